#!/usr/bin/env bash
# Installs ctlio's build and test dependencies from Debian 12 packages (clang and its runtime
# libclang-rt-14-dev build the libFuzzer targets of scripts/fuzz.sh).
# Safe to re-run: when everything is present it only checks and returns.
set -euo pipefail

packages=(
  build-essential cmake
  libceres-dev libeigen3-dev libsuitesparse-dev libpcl-dev
  libgflags-dev libgoogle-glog-dev libgtest-dev libgmock-dev libbenchmark-dev
  libyaml-cpp-dev python3-matplotlib python3-numpy
  librosbag-dev libsensor-msgs-dev libtf2-msgs-dev libnav-msgs-dev
  libzstd-dev liblz4-dev libsqlite3-dev
  clang libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
