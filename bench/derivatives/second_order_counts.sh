#!/usr/bin/env bash
# Instructions per call of the second-order derivative benchmarks (arbor_bench_second_order_cg,
# bench/derivatives), measured with callgrind as the difference of two run lengths (N2 - N1
# calls), so that start-up, data set-up and exit cancel out (the method of bench/callgrind_counts.sh).
#
#   bench/derivatives/second_order_counts.sh <build-dir> <robot>:<algo>...
#
# e.g. kinova_gen3:id_hessian kinova_gen3:fd_hessian. Prints a Markdown table.
set -euo pipefail
build=${1:?usage: second_order_counts.sh <build-dir> <robot>:<algo>...}
shift
exe="$build/bench/derivatives/arbor_bench_second_order_cg"
[[ -x "$exe" ]] || { echo "missing $exe (build arbor_bench_second_order_cg)" >&2; exit 1; }
N1=${N1:-20}
N2=${N2:-120}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
count() {  # robot algo n -> total instructions
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "$exe" --run "$1" "$2" "$3" \
    >/dev/null 2>"$tmp/log" || { cat "$tmp/log" >&2; exit 1; }
  awk '/^summary:/ {print $2}' "$tmp/cg.out"
}
echo "| robot | algorithm | instructions/call |"
echo "|---|---|---|"
for ra in "$@"; do
  r=${ra%%:*} a=${ra#*:}
  i1=$(count "$r" "$a" "$N1")
  i2=$(count "$r" "$a" "$N2")
  echo "| $r | $a | $(((i2 - i1) / (N2 - N1))) |"
done
