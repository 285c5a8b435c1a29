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
#
# BENCH=nmpc counts the NMPC phases (arbor_bench_nmpc_cg, bench/nmpc): the "robots" are problems
# (default: pendulum cartpole), the "algos" phases (default: the SQP iteration's linearize,
# solve_qp, line_search, solve, and the real-time iteration's prepare and feedback). callgrind
# collects only inside the phase (--collect-atstart=no); a run of n solves (SQP phases, N1/N2
# default 1/3) or n closed-loop samples (RTI phases, default 80/180) prints its number of phase
# calls, so the table has two columns: instructions per call over the first N1 runs (the RTI:
# the closed loop from its start, including the QP's first setup), and over runs N1..N2 (the RTI:
# the samples after the first N1, the system upright; the SQP: both equal, a repeatability check).
set -euo pipefail

build=${1:?usage: callgrind_counts.sh <build-dir> [robots...] [-- algos...]}
shift
bench=${BENCH:-dynamics}
exe="$build/bench/$bench/arbor_bench_${bench}_cg"
[[ -x "$exe" ]] || { echo "missing $exe (build arbor_bench_${bench}_cg)" >&2; exit 1; }

robots=()
algos=()
while [[ $# -gt 0 && "$1" != "--" ]]; do robots+=("$1"); shift; done
if [[ $# -gt 0 ]]; then shift; algos=("$@"); fi
if [[ ${#robots[@]} -eq 0 && $bench != nmpc ]]; then
  # the benchmark robots (examples/robots, the one list), as configured in this build
  list=$(sed -n 's/^ARBOR_BENCHMARK_ROBOTS:[A-Z]*=//p' "$build/CMakeCache.txt")
  IFS=';' read -r -a robots <<<"$list"
  [[ ${#robots[@]} -gt 0 ]] || { echo "no ARBOR_BENCHMARK_ROBOTS in $build/CMakeCache.txt" >&2; exit 1; }
fi
if [[ ${#algos[@]} -eq 0 ]]; then
  if [[ $bench == derivatives ]]; then
    algos=(rnea_derivatives aba_derivatives)
  elif [[ $bench == nmpc ]]; then
    algos=(linearize solve_qp line_search solve prepare feedback)
  else
    algos=(fk rnea gravity nle crba aba minverse jacobian cholesky)
  fi
fi
scalars=(${SCALARS:-double float})
if [[ $bench != nmpc ]]; then
  N1=${N1:-100}
  N2=${N2:-1100}
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

if [[ $bench == nmpc ]]; then
  [[ ${#robots[@]} -gt 0 && -n "${robots[0]}" ]] || robots=(pendulum cartpole)
  count_nmpc() {  # problem phase scalar n -> "instructions calls"
    local out="$tmp/cg.out" calls
    if ! calls=$(valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$out" \
      "$exe" --run "$1" "$2" "$3" "$4" 2>"$tmp/log" | awk '/^calls/ {print $2}'); then
      cat "$tmp/log" >&2
      echo "FAILED"
      return
    fi
    echo "$(awk '/^summary:/ {print $2}' "$out") $calls"
  }
  echo "| problem | scalar | phase | instructions/call, first N1 runs | instructions/call, runs N1..N2 |"
  echo "|---|---|---|---:|---:|"
  for r in "${robots[@]}"; do
    for s in "${scalars[@]}"; do
      for a in "${algos[@]}"; do
        if [[ $a == prepare || $a == feedback ]]; then n1=${N1:-80} n2=${N2:-180}; else n1=${N1:-1} n2=${N2:-3}; fi
        read -r i1 c1 <<<"$(count_nmpc "$r" "$a" "$s" "$n1")"
        read -r i2 c2 <<<"$(count_nmpc "$r" "$a" "$s" "$n2")"
        if ! [[ "$i1" =~ ^[0-9]+$ && "$i2" =~ ^[0-9]+$ && "$c1" =~ ^[0-9]+$ && "$c2" -gt "$c1" ]]; then
          echo "callgrind failed for $r $a $s" >&2
          exit 1
        fi
        echo "| $r | $s | $a | $((i1 / c1)) ($c1 calls) | $(((i2 - i1) / (c2 - c1))) ($((c2 - c1)) calls) |"
      done
    done
  done
  exit 0
fi

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
