#!/usr/bin/env bash
# Builds bench_hal (Release, in its own build directory) and runs it. Arguments go to the
# bench: --seconds S, --chain N, --no-linuxcnc, --linuxcnc-cycles N, --help. See
# docs/benchmarks.md. Run as root for SCHED_FIFO threads and for LinuxCNC's realtime.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${BENCH_BUILD_DIR:-$root/build-bench}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" -j2 --target bench_hal comp_and2 > /dev/null
if [ "$(id -u)" != 0 ]; then
    echo "note: not root: threads run with normal scheduling and LinuxCNC's realtime may not start" >&2
fi
exec "$build/bin/bench_hal" "$@"
