#!/usr/bin/env bash
# Runs one G-code program on LinuxCNC 2.9's sim stack (bench.ini: the bench settings) headless
# and prints its result as key=value lines (motion_s, runs, wall_s; see display.py).
#   bench/linuxcnc/run.sh [--trace FILE] [--tolerance-scale F] PROGRAM
# --trace FILE  also record the commanded X Y Z of every moving servo cycle into FILE
#               (trace.hal + halsampler), for bench_motion --trace-check.
# --tolerance-scale F  multiply every G64 P (the INI's default and the program's own) by F:
#               LinuxCNC 2.9's corners deviate from the path by far more than P (see
#               docs/benchmarks.md), so a fair time is taken at the P that keeps its deviation.
# Exit 0 on success, 1 if LinuxCNC reported an error, 2 if LinuxCNC is not installed.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
usage="usage: $0 [--trace FILE] [--tolerance-scale F] PROGRAM"
trace= tolerance_scale=
while [[ $# -gt 1 ]]; do
    case $1 in
        --trace) trace=$(realpath "$2"); shift 2 ;;
        --tolerance-scale) tolerance_scale=$2; shift 2 ;;
        *) echo "$usage" >&2; exit 64 ;;
    esac
done
[[ $# -eq 1 ]] || { echo "$usage" >&2; exit 64; }
program=$(realpath "$1")
[[ -r $program ]] || { echo "$0: cannot read $1" >&2; exit 66; }
if ! command -v linuxcnc >/dev/null || [[ ! -x /usr/bin/python3 ]] ||
    ! /usr/bin/python3 -c 'import linuxcnc' 2>/dev/null; then
    echo "$0: LinuxCNC (linuxcnc-uspace and its python3 module) is not installed" >&2
    exit 2
fi

# LinuxCNC writes its position and parameter files beside the INI: run from a scratch copy.
scratch=$(mktemp -d /tmp/lcncbench.XXXXXX)
# rtapi_app drops to RTAPI_UID and must reach the socket folder inside.
chmod 755 "$scratch"
trap '[[ -n ${LCNC_BENCH_KEEP:-} ]] || rm -rf "$scratch"' EXIT
cp "$here"/bench.ini "$here"/bench.hal "$here"/bench.tbl "$here"/display.py "$scratch"/
if [[ -n $tolerance_scale ]]; then
    scale_p() { perl -pe 's/(G64\s*P)([0-9.]+)/$1 . sprintf("%.6g", $2 * '"$tolerance_scale"')/gie' "$@"; }
    scale_p "$program" >"$scratch"/program.ngc
    program=$scratch/program.ngc
    scale_p -i "$scratch"/bench.ini
fi
if [[ -n $trace ]]; then
    cp "$here"/trace.hal "$scratch"/
    sed -i 's/^HALFILE = bench.hal$/&\nHALFILE = trace.hal/' "$scratch"/bench.ini
    : >"$trace"
    export LCNC_BENCH_TRACE=$trace
fi
: >"$scratch"/bench.var
# Run as root, uspace rtapi_app needs a uid to drop to and the path of its master socket
# (a socket file in a mode-1777 folder; docs/benchmarks.md, HAL section).
export RTAPI_UID=${RTAPI_UID:-65534}
if [[ -z ${RTAPI_FIFO_PATH:-} ]]; then
    mkdir -m 1777 "$scratch"/fifo
    export RTAPI_FIFO_PATH=$scratch/fifo/rtapi_fifo
fi
export LCNC_BENCH_PROGRAM=$program LCNC_BENCH_OUT=$scratch/result

status=0
# HOME: linuxcnc copies its debug and print logs there when not on a terminal.
(cd "$scratch" && HOME=$scratch linuxcnc bench.ini) >"$scratch"/log 2>&1 </dev/null || status=$?
if [[ ! -s $scratch/result ]] || grep -q '^error=' "$scratch"/result; then
    sed "s/^error=/LinuxCNC: /" "$scratch"/result >&2 2>/dev/null || true
    echo "$0: LinuxCNC run failed (exit $status); its log:" >&2
    tail -n 30 "$scratch"/linuxcnc_print.txt "$scratch"/log >&2 2>/dev/null || true
    exit 1
fi
cat "$scratch"/result
