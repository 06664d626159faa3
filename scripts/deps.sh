#!/usr/bin/env bash
# Installs the Debian 12 packages the project needs, and any packages named as arguments (what
# a bench script needs besides). Idempotent: installs only what is missing.
set -euo pipefail
packages=(
  build-essential
  cmake
  pkg-config
  libfmt-dev
  libeigen3-dev
  nlohmann-json3-dev
  libcli11-dev
  libedit-dev
  libgtest-dev
  libgmock-dev
  libbenchmark-dev
  clang
  libclang-rt-14-dev
  python3
  time
  procps
  libcairo2-dev
  libexpat1-dev
  python3-scipy
)
packages+=("$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  echo "deps: installing ${missing[*]}"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
