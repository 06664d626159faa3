#!/usr/bin/env bash
# One LinuxCNC-compatibility reproducer: repro/<case>/test.hal (+ test.ini when present) must
# print the value lines in repro/<case>/expected and exit 0.
#   run_repro.sh ours     OUR_HALRUN       CASE_DIR   our halrun --sim-clock
#   run_repro.sh linuxcnc LINUXCNC_HALRUN  CASE_DIR   LinuxCNC's halrun: proves `expected` is
#                                                     what LinuxCNC does (exit 77 = skipped
#                                                     when LinuxCNC or root is missing)
# Only value lines (TRUE, FALSE, numbers) are compared: they come from getp/gets, while
# notices and help texts differ between the two implementations.
set -euo pipefail
who=$1 halrun=$2 dir=$3
cd "$dir"
ini_args=()
[ -f test.ini ] && ini_args=(-i test.ini)
if [ "$who" = linuxcnc ]; then
    if [ ! -x "$halrun" ] || ! grep -q linuxcnc "$halrun" 2>/dev/null || [ "$(id -u)" != 0 ]; then
        echo "SKIP: needs LinuxCNC's halrun ($halrun) and root"
        exit 77
    fi
    rtdir=$(mktemp -d /tmp/hal-repro-rtapi-XXXXXX)
    trap 'rm -rf "$rtdir"' EXIT
    chmod 1777 "$rtdir"
    export RTAPI_UID=${RTAPI_UID:-65534} RTAPI_FIFO_PATH=$rtdir/rtapi_fifo
    cmd=("$halrun" "${ini_args[@]}" -f test.hal)
else
    cmd=("$halrun" --sim-clock --instance "repro-$$" "${ini_args[@]}" -f test.hal)
fi
status=0
out=$("${cmd[@]}" 2>&1) || status=$?
if [ "$who" = linuxcnc ] && grep -q "Realtime already running" <<< "$out"; then
    echo "SKIP: another LinuxCNC realtime session is running on this machine"
    exit 77
fi
values=$(grep -E '^(TRUE|FALSE|-?[0-9][0-9.eE+-]*)$' <<< "$out" || true)
if [ "$status" != 0 ] || [ "$values" != "$(cat expected)" ]; then
    echo "$out"
    echo "FAIL: exit $status; value lines:"
    echo "$values"
    echo "expected:"
    cat expected
    exit 1
fi
echo "ok: $(tr '\n' ' ' < expected)"
