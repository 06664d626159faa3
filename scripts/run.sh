#!/usr/bin/env bash
# Installs dependencies, builds, and runs the main job on the simulated machine.
# Until the motion stack lands this is the HAL demo: a PID loop on a simulated axis.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
exec build/bin/halrun configs/demo/pid-demo.hal
