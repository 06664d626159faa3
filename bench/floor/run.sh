#!/usr/bin/env bash
# The numerical floor (bench/floor/floor.py) on tp_default's sections where LinuxCNC leaves the
# path (docs/benchmarks.md, "A numerical floor for sections"). Installs what is missing
# (python3-scipy with the project's packages, and coinor-cbc) through scripts/deps.sh. Extra
# arguments go to every floor.py call (the last of a repeated option counts, e.g.
# --time-limit 600).
#   bench/floor/run.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
# coinor-cbc: the second solver, which the docs use to check the proofs and which proves the
# opening's and the 1 ms figures (`floor.py --solver cbc`).
"$root/scripts/deps.sh" coinor-cbc
program="$root/bench/tp_default.ngc"
# Sections: the three row ends, the rapids between the rows and the half circles, and the last
# four moves split at their corners (floors of sections disjoint in time add up). The row ends
# take the rows' 0.5 mm chains as hulls (--group-deg 10). The horizons are a little above our
# planner's times, so the bisection starts close. These are the commands of the table in
# docs/benchmarks.md; on this 2-vCPU VM they take about two hours together.
sections=(
  "201-209 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --horizon-ms 264 --time-limit 150"
  "401-410 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --horizon-ms 280 --time-limit 200"
  "603-611 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --horizon-ms 262 --time-limit 150"
  "807-810 --step-ms 2 --lead-in 15 --lead-out 15 --horizon-ms 904 --time-limit 200"
  "831-831 --step-ms 1 --lead-in 25 --lead-out 25 --horizon-ms 486 --time-limit 200"
  "832-832 --step-ms 2 --lead-in 15 --lead-out 15 --horizon-ms 1560 --time-limit 200"
  "833-834 --step-ms 1 --lead-in 25 --lead-out 25 --horizon-ms 828 --time-limit 200"
)
# Where a bisection step hit its time limit, the table's follow-up proofs with longer limits.
sections+=(
  "401-410 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --prove-ms 258 --time-limit 1200"
  "401-410 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --prove-ms 260 --time-limit 1000"
  "401-410 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --prove-ms 262 --time-limit 2100"
  "603-611 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --prove-ms 246 --time-limit 900"
  "603-611 --group-deg 10 --step-ms 2 --lead-in 15 --lead-out 15 --prove-ms 248 --time-limit 1500"
)
# The opening under the stricter contract (--reach-vertices), split at the end of G1 Z0, with
# CBC (HiGHS did not prove the hop within its limits).
sections+=(
  "2-3 --step-ms 4 --lead-in 10 --lead-out 10 --reach-vertices --prove-ms 156 --time-limit 300 --solver cbc"
  "4-5 --step-ms 2 --lead-in 15 --lead-out 15 --horizon-ms 60 --time-limit 100 --reach-vertices --solver cbc"
)
# The row ends and the rapids at a 1 ms grid, with CBC (the second table).
ms1="--step-ms 1 --lead-in 25 --lead-out 25 --time-limit 300 --solver cbc"
sections+=(
  "201-209 --group-deg 10 $ms1 --prove-ms 249"
  "201-209 --group-deg 10 $ms1 --prove-ms 250"
  "603-611 --group-deg 10 $ms1 --prove-ms 249"
  "603-611 --group-deg 10 $ms1 --prove-ms 250"
  "807-810 $ms1 --prove-ms 887"
)
for s in "${sections[@]}"; do
  # shellcheck disable=SC2086
  /usr/bin/python3 "$here/floor.py" "$program" --lines $s "$@"
done
