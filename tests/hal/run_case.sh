#!/usr/bin/env bash
# Runs one tests/hal case: `halrun --sim-clock -f test.hal` inside the case folder, in a HAL
# instance of its own (so cases run in parallel). stdout and stderr, then "exit N", must
# equal the file `expected` byte for byte. An optional file `args` adds halrun options.
set -u
halrun=$1
case_dir=$2
name=$(basename "$case_dir")
export HAL_INSTANCE="t-${name}-$$"
cd "$case_dir" || exit 2
extra=()
[ -f args ] && read -r -a extra < args
actual=$("$halrun" --sim-clock "${extra[@]}" -f test.hal 2>&1; echo "exit $?")
"$halrun" -U >/dev/null 2>&1
if [ "$actual" != "$(cat expected)" ]; then
  echo "case $name: output differs from expected (< actual, > expected):"
  diff <(printf '%s\n' "$actual") expected
  exit 1
fi
