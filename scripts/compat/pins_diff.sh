#!/usr/bin/env bash
# Compares the pin, parameter and function names (types, directions) of every component we
# ship with LinuxCNC's component of the same name. Needs LinuxCNC installed and root.
# Usage: scripts/compat/pins_diff.sh [BUILD_DIR]   (default: build)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
lcnc_halrun=${LINUXCNC_HALRUN:-/usr/bin/halrun}
if [ ! -x "$lcnc_halrun" ] || ! grep -q linuxcnc "$lcnc_halrun"; then
    echo "pins_diff: LinuxCNC's halrun not found ($lcnc_halrun)" >&2
    exit 3
fi
# LinuxCNC's uspace realtime: a uid to drop to, and the path of its socket file in a directory
# that uid may write.
rtdir=$(mktemp -d /tmp/hal-pins-rtapi-XXXXXX)
trap 'rm -rf "$rtdir"' EXIT
chmod 1777 "$rtdir"
export RTAPI_UID=${RTAPI_UID:-65534} RTAPI_FIFO_PATH=${RTAPI_FIFO_PATH:-$rtdir/rtapi_fifo}
python3 "$here/pins_diff.py" --components "$build/lib/cnc/components" --halrun "$build/bin/halrun" \
    --linuxcnc-halrun "$lcnc_halrun"
