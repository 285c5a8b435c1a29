#!/usr/bin/env bash
# Instructions per call of each rigid-body algorithm, measured with callgrind as the difference
# of two run lengths (N2 - N1 calls), so that start-up, data set-up and exit cancel out.
#
#   bench/callgrind_counts.sh <build-dir> [robots...] [-- algos...]
#
# Needs valgrind and a build with -DARBOR_BUILD_BENCH=ON (target arbor_bench_dynamics_cg:
# the same code as arbor_bench_dynamics, without AVX-512, which valgrind cannot run).
# BENCH=derivatives counts the derivative benchmarks instead (arbor_bench_derivatives_cg).
# Prints a Markdown table: robot, scalar, algorithm, instructions per call.
set -euo pipefail

build=${1:?usage: callgrind_counts.sh <build-dir> [robots...] [-- algos...]}
shift
bench=${BENCH:-dynamics}
exe="$build/bench/$bench/arbor_bench_${bench}_cg"
[[ -x "$exe" ]] || { echo "missing $exe (build arbor_bench_dynamics_cg)" >&2; exit 1; }

robots=()
algos=()
while [[ $# -gt 0 && "$1" != "--" ]]; do robots+=("$1"); shift; done
if [[ $# -gt 0 ]]; then shift; algos=("$@"); fi
if [[ ${#robots[@]} -eq 0 ]]; then
  # the benchmark robots (examples/robots, the one list), as configured in this build
  list=$(sed -n 's/^ARBOR_BENCHMARK_ROBOTS:[A-Z]*=//p' "$build/CMakeCache.txt")
  IFS=';' read -r -a robots <<<"$list"
  [[ ${#robots[@]} -gt 0 ]] || { echo "no ARBOR_BENCHMARK_ROBOTS in $build/CMakeCache.txt" >&2; exit 1; }
fi
if [[ ${#algos[@]} -eq 0 ]]; then
  if [[ $bench == derivatives ]]; then
    algos=(rnea_derivatives aba_derivatives)
  else
    algos=(fk rnea gravity nle crba aba minverse jacobian cholesky)
  fi
fi
scalars=(${SCALARS:-double float})
N1=${N1:-100}
N2=${N2:-1100}

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

count() {  # robot algo scalar n -> total instructions
  local out="$tmp/cg.out"
  if ! valgrind --tool=callgrind --callgrind-out-file="$out" "$exe" --run "$1" "$2" "$3" "$4" \
    >/dev/null 2>"$tmp/log"; then
    cat "$tmp/log" >&2
    echo "FAILED"
    return
  fi
  awk '/^summary:/ {print $2}' "$out"
}

echo "| robot | scalar | algorithm | instructions/call |"
echo "|---|---|---|---|"
for r in "${robots[@]}"; do
  for s in "${scalars[@]}"; do
    for a in "${algos[@]}"; do
      i1=$(count "$r" "$a" "$s" "$N1")
      i2=$(count "$r" "$a" "$s" "$N2")
      if ! [[ "$i1" =~ ^[0-9]+$ && "$i2" =~ ^[0-9]+$ ]]; then
        echo "callgrind failed for $r $a $s" >&2
        exit 1
      fi
      echo "| $r | $s | $a | $(( (i2 - i1) / (N2 - N1) )) |"
    done
  done
done
