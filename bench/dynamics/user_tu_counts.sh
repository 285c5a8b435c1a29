#!/usr/bin/env bash
# Instructions per call of the RBD kernels in a user's translation unit (bench/dynamics/user_tu.cpp:
# one program per robot and algorithm, nothing else in it), the method of
# ../shared/reference/pinocchio_counts.md: g++ -std=c++20 -O3 -march=native -mno-avx512f -DNDEBUG,
# callgrind totals of 200 and 1200 calls on a cycle of 16 random inputs, (I(1200) - I(200)) / 1000.
#
#   bench/dynamics/user_tu_counts.sh <host-build-dir> [robots...] [-- algos...]
#
# The build folder gives the generated robot headers (built here: arbor_robot_<robot>_generate).
# Prints a Markdown table (robot, algorithm, instructions per call) and, with CPU time, the
# compile cost of each unit on stderr. JOBS: compile parallelism (default 1).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build=${1:?usage: user_tu_counts.sh <host-build-dir> [robots...] [-- algos...]}
shift
robots=()
algos=()
while [[ $# -gt 0 && "$1" != "--" ]]; do robots+=("$1"); shift; done
if [[ $# -gt 0 ]]; then shift; algos=("$@"); fi
if [[ ${#robots[@]} -eq 0 ]]; then
  list=$(sed -n 's/^ARBOR_BENCHMARK_ROBOTS:[A-Z]*=//p' "$build/CMakeCache.txt")
  IFS=';' read -r -a robots <<<"$list"
fi
[[ ${#algos[@]} -gt 0 ]] || algos=(rnea crba aba minverse rnea_derivatives aba_derivatives)
declare -A id=([rnea]=1 [crba]=2 [aba]=3 [minverse]=4 [rnea_derivatives]=5 [aba_derivatives]=6)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

for r in "${robots[@]}"; do
  cmake --build "$build" --target "arbor_robot_${r}_generate" >/dev/null 2>&1
done
struct_of() { sed -n "s/^ARBOR_ROBOT_$1_STRUCT:INTERNAL=//p" "$build/CMakeCache.txt"; }

echo "| robot | algorithm | instructions/call |"
echo "|---|---|---:|"
for r in "${robots[@]}"; do
  st=$(struct_of "$r")
  inc="$build/examples/robots/arbor_robot_${r}_gen"
  for a in "${algos[@]}"; do
    exe="$tmp/${r}_$a"
    /usr/bin/time -f "compile $r $a: %U s user, %M KB" \
      g++ -std=c++20 -O3 -march=native -mno-avx512f -DNDEBUG -I "$root/include" -I "$inc" \
      -isystem /usr/include/eigen3 "-DARBOR_UT_ROBOT_HEADER=<robots/$r.hpp>" \
      -DARBOR_UT_STRUCT="$st" -DARBOR_UT_ALGO_ID="${id[$a]}" "$root/bench/dynamics/user_tu.cpp" \
      -o "$exe" 2>>"$tmp/compile.log" || { cat "$tmp/compile.log" >&2; exit 1; }
    i1=$(valgrind --tool=callgrind --callgrind-out-file="$tmp/cg1" "$exe" 200 2>&1 >/dev/null |
      sed -n 's/.*Collected : //p')
    i2=$(valgrind --tool=callgrind --callgrind-out-file="$tmp/cg2" "$exe" 1200 2>&1 >/dev/null |
      sed -n 's/.*Collected : //p')
    echo "| $r | $a | $(((i2 - i1) / 1000)) |"
  done
done
grep '^compile' "$tmp/compile.log" >&2
