#!/usr/bin/env bash
# The numerical floor (bench/floor/floor.py) on tp_default's sections where LinuxCNC leaves the
# path (docs/benchmarks.md, "A numerical floor for sections"). Installs python3-scipy if it is
# missing, like scripts/deps.sh. Extra arguments go to every floor.py call (e.g. --step-ms 1).
#   bench/floor/run.sh                 # all sections, 2 ms grid
#   bench/floor/run.sh --step-ms 1     # 1 ms grid (slower, tighter)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if ! dpkg-query -W -f='${Status}' python3-scipy 2>/dev/null | grep -q "install ok installed"; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  echo "floor: installing python3-scipy"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends python3-scipy
fi
program="$root/bench/tp_default.ngc"
# Sections: the three row ends, the rapids between the rows and the half circles, the last
# four moves. The row ends take the rows' 0.5 mm chains as hulls (--group-deg 10).
sections=(
  "201-209 --group-deg 10"
  "401-410 --group-deg 10"
  "603-611 --group-deg 10"
  "807-810"
  "831-834"
)
for s in "${sections[@]}"; do
  # shellcheck disable=SC2086
  /usr/bin/python3 "$here/floor.py" "$program" --lines $s --step-ms 2 "$@"
done
