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
source "$root/bench/dynamics/user_tu_common.sh"
user_tu_parse_args "$@"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "| robot | algorithm | instructions/call |"
echo "|---|---|---:|"
for r in "${robots[@]}"; do
  for a in "${algos[@]}"; do
    exe="$tmp/${r}_$a"
    user_tu_compile "$root" "$r" "$a" "$exe" \
      /usr/bin/time -a -o "$tmp/compile.log" -f "compile $r $a: %U s user, %M KB" \
      2>>"$tmp/compile.log" || { cat "$tmp/compile.log" >&2; exit 1; }
    i1=$(valgrind --tool=callgrind --callgrind-out-file="$tmp/cg1" "$exe" 200 2>&1 >/dev/null |
      sed -n 's/.*Collected : //p')
    i2=$(valgrind --tool=callgrind --callgrind-out-file="$tmp/cg2" "$exe" 1200 2>&1 >/dev/null |
      sed -n 's/.*Collected : //p')
    echo "| $r | $a | $(((i2 - i1) / 1000)) |"
  done
done
grep '^compile' "$tmp/compile.log" >&2
