#!/usr/bin/env bash
# Regenerates the AD layer's reports, the paper's Table 1, Fig. 1 and Table 2 reproduced:
#
#   bash bench/ad/report.sh [build-dir]        (default build-dir: build-bench)
#   JOBS=1 bash bench/ad/report.sh ...          (parallel compile jobs, default 2)
#
# Installs what is missing (scripts/setup.sh), builds arbor_ad_op_counts and arbor_bench_ad in a
# Release build with benchmarks, runs them, and writes bench/ad/RESULTS.md (tables) and
# bench/ad/fig1.png (bar chart, log scale) with Debian's python3-matplotlib (/usr/bin/python3:
# a python3 earlier in PATH, e.g. pyenv's, would not see it). Takes about 10 minutes on 2 cores,
# mostly compiling.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$root/build-bench}
bash "$root/scripts/setup.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_BENCH=ON \
  -DARBOR_BUILD_TESTS=OFF -DARBOR_BUILD_EXAMPLES=OFF >/dev/null
cmake --build "$build" -j"${JOBS:-2}" --target arbor_ad_op_counts arbor_bench_ad arbor_ad_fn_counts
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "report.sh: operation counts" >&2
"$build/bench/ad/arbor_ad_op_counts" >"$tmp/counts.md"
echo "report.sh: Jacobian and Hessian times (5 repetitions)" >&2
"$build/bench/ad/arbor_bench_ad" --benchmark_format=json --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true --benchmark_min_time=0.05 >"$tmp/times.json"
# a user function's derivatives (bench/ad/fn_counts.cpp): the counts table, then times as JSON
echo "report.sh: user function (fn_counts)" >&2
"$build/bench/ad/arbor_ad_fn_counts" --benchmark_filter=^$ >"$tmp/fn_counts.md"
"$build/bench/ad/arbor_ad_fn_counts" --benchmark_format=json --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true | sed -n '/^{/,$p' >"$tmp/fn_times.json"
/usr/bin/python3 "$root/bench/ad/report.py" "$tmp/counts.md" "$tmp/times.json" "$root/bench/ad" \
  "$tmp/fn_counts.md" "$tmp/fn_times.json"
echo "wrote $root/bench/ad/RESULTS.md and $root/bench/ad/fig1.png"
