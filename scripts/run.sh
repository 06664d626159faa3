#!/usr/bin/env bash
# Installs dependencies, builds, and runs the main job: the sample part examples/pocket.ngc on
# the simulated 3-axis mill configs/sim/mill.ini, in real time, with a progress bar, a summary
# and a picture of the path followed in build/pocket-preview.svg (docs/cnc-run.md). Extra
# arguments go to `cnc run` (e.g. --sim-clock, --trace t.csv).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
exec build/bin/cnc run configs/sim/mill.ini examples/pocket.ngc --preview build/pocket-preview.svg "$@"
