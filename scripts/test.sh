#!/usr/bin/env bash
# Set-up, build and run the whole test suite (from any folder): the host, then the emulated
# targets (Cortex-M7 and Cortex-M4F bare metal in qemu-system-arm, AArch64 Linux in qemu-aarch64).
# Build folders: build/ and build-<target>/ (override the root with BUILD_DIR). Exit status is
# non-zero when anything fails. ARBOR_TARGETS="" skips the targets.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
targets="${ARBOR_TARGETS-cortex-m7 cortex-m4f aarch64-linux}"
bash "$root/scripts/setup.sh"

echo "== host"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_TESTS=ON >/dev/null
cmake --build "$build" -j2
(cd "$build" && ctest -j2 --output-on-failure --timeout 900)

for t in $targets; do
  echo "== $t (emulated)"
  tb="$build-$t"
  # Targets run the portable suites (harness, heap and fault traps, model contract, the RBD core
  # against the reference values and against the host's own results); the host runs everything.
  cmake -S "$root" -B "$tb" --toolchain "$root/toolchains/$t.cmake" -DCMAKE_BUILD_TYPE=Release \
    -DARBOR_GEN_EXECUTABLE="$build/gen/arbor-gen" -DARBOR_HOST_BUILD_DIR="$build" \
    -DARBOR_PORTABLE_TESTS_ONLY=ON >/dev/null
  cmake --build "$tb" -j2
  (cd "$tb" && ctest -j2 --output-on-failure --timeout 900)
done
