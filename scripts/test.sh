#!/usr/bin/env bash
# Set-up, build and run the whole test suite (from any folder). Build folder: build/ (override:
# BUILD_DIR). Exit status is non-zero when anything fails.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_TESTS=ON >/dev/null
cmake --build "$build" -j2
cd "$build"
ctest -j2 --output-on-failure --timeout 900
