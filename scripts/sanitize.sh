#!/usr/bin/env bash
# The host tests that touch raw memory (qp, nmpc, dynamics, derivatives, ad) built with
# -fsanitize=address,undefined (alignment included; every finding ends the test) and run: an
# out-of-bounds access, a misaligned load or store, or undefined arithmetic fails the run. Build
# folder: build-sanitize/ (BUILD_DIR overrides). Separate from the suite (scripts/test.sh) for its
# cost: about twice the compile time and memory of the same tests in the suite. LABELS narrows it
# (a CTest label regex, default "qp|nmpc|dynamics|derivatives|ad").
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build-sanitize}"
# anchored: a bare "ad" would also match the label "headers"
labels="^(${LABELS:-qp|nmpc|dynamics|derivatives|ad})\$"
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_TESTS=ON \
  -DARBOR_BUILD_EXAMPLES=OFF -DARBOR_SANITIZE=ON >/dev/null
# the test executables of those labels (one target per test, named as the test)
# (of the size matrix's per-ISA builds: the default one and AVX-512 -march=native, where wide
# vectors meet odd sizes)
mapfile -t tests < <(cd "$build" && ctest -N -L "$labels" | sed -n 's/^ *Test *#[0-9]*: \(.*\)$/\1/p' |
  grep -Ev '_(o3|avx2|unaligned)_test$')
# only tests that are executables of this build (a test may run a script or another's binary)
mapfile -t targets < <(cd "$build" && cmake --build . --target help | sed -n 's/^\.\.\. \([^ ]*\).*/\1/p')
tests=($(printf '%s\n' "${tests[@]}" | grep -Fxf <(printf '%s\n' "${targets[@]}")))
echo "sanitize: ${#tests[@]} tests labelled $labels"
cmake --build "$build" -j2 --target "${tests[@]}"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd "$build" && ctest -j2 -L "$labels" -E '_(o3|avx2|unaligned)_test$' --output-on-failure \
  --timeout 1800
