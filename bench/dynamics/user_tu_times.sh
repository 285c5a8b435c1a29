#!/usr/bin/env bash
# CPU time per call of the RBD kernels in a user's translation unit, this tree against another
# version of the library (e.g. a `git archive` of an older commit), as ratios measured in one run.
# The unit is bench/dynamics/user_tu.cpp of this tree, compiled twice with the flags of
# user_tu_counts.sh (-O3 -march=native -mno-avx512f), once per include root; both programs get
# the same generated robot header, the same inputs and the same call count.
#
#   bench/dynamics/user_tu_times.sh <host-build-dir> <other-source-root> [robots...] [-- algos...]
#
# The two programs run alternately, ROUNDS times (default 7), each for about SECONDS (default 0.3)
# of CPU; per program the minimum CPU time per call over the rounds is kept (the least disturbed
# run on a shared machine), and the ratio other / this is printed (> 1: this tree is faster).
# Prints a Markdown table.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build=${1:?usage: user_tu_times.sh <host-build-dir> <other-source-root> [robots...] [-- algos...]}
other=${2:?usage: user_tu_times.sh <host-build-dir> <other-source-root> [robots...] [-- algos...]}
shift 2
rounds=${ROUNDS:-7}
seconds=${SECONDS_PER_RUN:-0.3}
source "$root/bench/dynamics/user_tu_common.sh"
user_tu_parse_args "$@"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ns_per_call() { "$1" "$2" time 2>&1 >/dev/null; }  # exe calls

echo "| robot | algorithm | other ns/call | this ns/call | other / this |"
echo "|---|---|---:|---:|---:|"
for r in "${robots[@]}"; do
  for a in "${algos[@]}"; do
    user_tu_compile "$other" "$r" "$a" "$tmp/old"
    user_tu_compile "$root" "$r" "$a" "$tmp/new"
    # Calls for about $seconds of CPU, from a short calibration run of this tree's program.
    calls=$(awk -v t="$(ns_per_call "$tmp/new" 20000)" -v s="$seconds" \
      'BEGIN {n = int(s * 1e9 / t); print (n < 1000 ? 1000 : n)}')
    best_old=""
    best_new=""
    for ((k = 0; k < rounds; ++k)); do
      o=$(ns_per_call "$tmp/old" "$calls")
      n=$(ns_per_call "$tmp/new" "$calls")
      best_old=$(awk -v a="$best_old" -v b="$o" 'BEGIN {print (a == "" || b < a) ? b : a}')
      best_new=$(awk -v a="$best_new" -v b="$n" 'BEGIN {print (a == "" || b < a) ? b : a}')
    done
    awk -v r="$r" -v a="$a" -v o="$best_old" -v n="$best_new" \
      'BEGIN {printf "| %s | %s | %.1f | %.1f | %.2f |\n", r, a, o, n, o / n}'
  done
done
