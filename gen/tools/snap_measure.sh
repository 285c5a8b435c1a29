#!/usr/bin/env bash
# Measures what `arbor-gen --snap TOL` does to a robot with rounded angles (default: the Kinova
# Gen3, rpy = 1.5708 / 3.1416, TOL = 1e-5): the model change (max relative difference of M and
# tau = rnea on the reference samples, and of both models against the reference values), and the
# instructions per call of rnea, aba and crba with and without (callgrind, N2 - N1 calls, as
# bench/callgrind_counts.sh counts; built -O3 -march=native -mno-avx512f like its _cg target).
#
#   gen/tools/snap_measure.sh [BUILD_DIR] [URDF] [REFERENCE] [TOL]
#
# BUILD_DIR must hold a built arbor-gen (default build-gen). Needs valgrind (scripts/setup.sh).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build-gen}"
urdf="${2:-$root/examples/robots/kinova_gen3.urdf}"
ref="${3:-$root/tests/data/reference/kinova_gen3.txt}"
tol="${4:-1e-5}"
gen="$build/gen/arbor-gen"
[[ -x "$gen" ]] || { echo "missing $gen (cmake --build $build --target arbor-gen)" >&2; exit 1; }
command -v valgrind >/dev/null || { echo "valgrind missing (bash scripts/setup.sh)" >&2; exit 1; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$gen" "$urdf" -o "$tmp/robots/plain.hpp" --name Plain --quiet
"$gen" "$urdf" -o "$tmp/robots/snapped.hpp" --name Snapped --snap "$tol" --quiet
"$gen" "$urdf" --summary --snap "$tol" | grep -E "snap|not axis-aligned"
${CXX:-g++} -std=c++20 -O3 -DNDEBUG -march=native -mno-avx512f -I"$root/include" -I"$tmp" \
  -I/usr/include/eigen3 "$root/gen/tools/snap_measure.cpp" -o "$tmp/snap_measure"
"$tmp/snap_measure" diff "$ref"

N1=${N1:-100}
N2=${N2:-1100}
count() {  # algo model calls -> total instructions
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "$tmp/snap_measure" run "$@" \
    >/dev/null 2>"$tmp/log" || { cat "$tmp/log" >&2; exit 1; }
  awk '/^summary:/ {print $2}' "$tmp/cg.out"
}
echo "| algorithm | without --snap | --snap $tol | ratio |"
echo "|---|---|---|---|"
for algo in rnea aba crba; do
  p=$(( ($(count "$algo" plain "$N2") - $(count "$algo" plain "$N1")) / (N2 - N1) ))
  s=$(( ($(count "$algo" snapped "$N2") - $(count "$algo" snapped "$N1")) / (N2 - N1) ))
  echo "| $algo | $p | $s | $(awk -v p="$p" -v s="$s" 'BEGIN {printf "%.3f", s / p}') |"
done
