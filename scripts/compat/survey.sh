#!/usr/bin/env bash
# LinuxCNC HAL-file compatibility survey: copies every HAL file LinuxCNC ships (with the INI
# files and everything else of its config, gunzipped) into a temporary tree, then runs
# survey.py, which loads each file that uses only our components with our halrun --sim-clock.
# Usage: scripts/compat/survey.sh [BUILD_DIR] [OUT_DIR]
#   BUILD_DIR  a configured and built tree (default: build); its lib/cnc/components/*.so are
#              "the components we ship" and bin/halrun is the halrun under test
#   OUT_DIR    where results.tsv and summary.md go (default: a new /tmp/hal-compat-XXXXXX)
# Source directories: $LINUXCNC_DIRS (default: /usr/share/doc/linuxcnc* /usr/share/linuxcnc).
# Reference: when LinuxCNC's halrun is installed and we run as root, every file we load is also
# loaded by LinuxCNC itself (standalone, same INI) unless NO_LINUXCNC=1. Its uspace realtime
# needs RTAPI_UID (a uid to drop to) and RTAPI_FIFO_PATH (the path of its socket file, in a
# directory that uid can write); both are set here when unset.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
out=${2:-$(mktemp -d /tmp/hal-compat-XXXXXX)}
halrun=$build/bin/halrun
components=$build/lib/cnc/components
[ -x "$halrun" ] || { echo "survey: no $halrun (build the tree first)" >&2; exit 2; }
[ -d "$components" ] || { echo "survey: no $components" >&2; exit 2; }

read -r -a dirs <<< "${LINUXCNC_DIRS:-$(echo /usr/share/doc/linuxcnc* /usr/share/linuxcnc)}"
present=()
for d in "${dirs[@]}"; do [ -d "$d" ] && present+=("$d"); done
if [ ${#present[@]} -eq 0 ]; then
    echo "survey: LinuxCNC is not installed (none of ${dirs[*]})" >&2
    exit 3
fi

tree=$(mktemp -d /tmp/hal-compat-tree-XXXXXX)
trap 'rm -rf "$tree"' EXIT
hallib=""
for d in "${present[@]}"; do
    dest="$tree/$(basename "$d")"
    mkdir -p "$dest"
    cp -r "$d/." "$dest/"
    [ -d "$d/hallib" ] && hallib="$dest/hallib"
done
find "$tree" -name '*.gz' -exec gunzip -f {} +
[ -n "$hallib" ] || hallib="$tree/hallib-missing"

reference=()
lcnc_halrun=${LINUXCNC_HALRUN:-/usr/bin/halrun}
if [ "${NO_LINUXCNC:-0}" != 1 ] && [ -x "$lcnc_halrun" ] && grep -q linuxcnc "$lcnc_halrun" \
    && [ "$(id -u)" = 0 ]; then
    rtdir=$(mktemp -d /tmp/hal-compat-rtapi-XXXXXX)
    chmod 1777 "$rtdir"
    export RTAPI_UID=${RTAPI_UID:-65534} RTAPI_FIFO_PATH=${RTAPI_FIFO_PATH:-$rtdir/rtapi_fifo}
    trap 'rm -rf "$tree" "$rtdir"' EXIT
    reference=(--linuxcnc-halrun "$lcnc_halrun")
fi

checker=()
[ -x "$build/bin/hal_syntax_check" ] && checker=(--syntax-check "$build/bin/hal_syntax_check")

mkdir -p "$out"
python3 "$here/survey.py" --tree "$tree" --hallib "$hallib" --components "$components" \
    --halrun "$halrun" --out "$out" "${checker[@]}" "${reference[@]}" 2> "$out/progress.log"
echo "survey: results in $out/results.tsv and $out/summary.md" >&2
