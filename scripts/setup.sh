#!/usr/bin/env bash
# Installs what arbor needs from Debian 12 packages, only when something is missing (idempotent).
# Run as root (or with sudo available). Used by scripts/demo.sh and scripts/test.sh.
set -euo pipefail

packages=(
  cmake make g++ pkg-config          # build
  python3                            # header dependency-order check (tests/headers)
  libeigen3-dev                      # Eigen 3.4
  liburdfdom-dev liburdfdom-tools    # URDF parsing for arbor-gen (+ check_urdf)
  libtinyxml-dev libconsole-bridge-dev
  googletest libgtest-dev            # unit tests
  coinor-libipopt-dev                # IPOPT, test-only NLP reference (tests/support/ipopt_reference)
  libmujoco-dev                      # MuJoCo 2.2.2: the contour demo's plant, tests/plant
  libbenchmark-dev                   # benchmarks
  clang libclang-rt-14-dev           # libFuzzer target of the generator
  clang-format                       # formatting check of generated headers
  valgrind                           # callgrind instruction counts
  python3-matplotlib                 # AD report plot (bench/ad/report.sh)
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib  # Cortex-M7/M4F
  g++-aarch64-linux-gnu              # AArch64 Linux
  qemu-system-arm qemu-user          # emulators for the targets' tests
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "setup: all packages present"
fi
