#!/usr/bin/env bash
# Short libFuzzer runs of the HAL-file and interpreter fuzz targets, in a clang build of its
# own (build-fuzz/). Part of the test suite; long runs: docs/fuzzing-hal.md, docs/fuzzing-interp.md.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ -DCNC_BUILD_FUZZ=ON \
      -DCNC_BUILD_BENCH=OFF >/dev/null
# The HAL fuzzer loads components; a representative set is enough to exercise loadrt paths.
cmake --build build-fuzz -j"${JOBS:-2}" --target fuzz_halfile interp_fuzz_expr interp_fuzz_program interp_fuzz_canon \
      comp_and2 comp_or2 comp_not comp_sum2 comp_pid comp_siggen comp_sampler comp_streamer \
      comp_limit3 comp_mux2 comp_conv_float_s32 comp_weighted_sum comp_debounce comp_encoder
cd build-fuzz
ctest -R "fuzz.*short" --output-on-failure
