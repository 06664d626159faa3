#!/usr/bin/env bash
# Installs dependencies, builds, and runs the whole test suite: every ctest test of the main
# build, then short libFuzzer runs in a clang build of their own.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
(cd build && ctest --output-on-failure -j"${JOBS:-2}" --timeout 300)
scripts/fuzz-short.sh
