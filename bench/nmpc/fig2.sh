#!/usr/bin/env bash
# The paper's Fig. 2 reproduced: solve time per sample of the Kinova Gen3 contour NMPC
# (examples/contour; OCP-FD and OCP-ID, analytical vs AD RBD derivatives, AD as dual numbers and
# as code-generated straight-line code) along its closed loop,
# in the paper's mode (full SQP, at most 5 iterations per sample, CONTOUR.md's tolerances) and in
# real-time iteration; instructions per sample by callgrind. Writes bench/nmpc/FIG2.md and
# bench/nmpc/fig2.png.
#
#   bash bench/nmpc/fig2.sh [build-dir]          (default: build-fig2 in the repository root)
#
# Environment: SAMPLES (closed-loop samples per variant and mode, default 250), CG_FROM and
# CG_COUNT (the samples callgrind counts, default 50 and 10), CG=0 (skip callgrind), TIMING=0
# (reuse the timing run of the last call, <build-dir>/fig2/fig2.csv), JOBS (build parallelism,
# default 1: each variant's translation unit takes ~2 GB of compiler memory). Intermediate files
# (per-sample CSV, callgrind outputs) stay in <build-dir>/fig2/.
# Needs: a C++20 compiler, CMake, Eigen, Google Benchmark, urdfdom (arbor-gen), valgrind,
# python3-matplotlib. Takes ~15 min to build (12 translation units of ~75 s) and ~15 min to run.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-fig2}
samples=${SAMPLES:-250}
cg_from=${CG_FROM:-50}
cg_count=${CG_COUNT:-10}
out=$root/bench/nmpc
# Debian's python3 (python3-matplotlib), not a python3 of a virtual environment first in PATH
py=${PYTHON:-$( [[ -x /usr/bin/python3 ]] && echo /usr/bin/python3 || echo python3 )}

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_BENCH=ON >/dev/null
targets=(arbor_bench_fig2)
[[ ${CG:-1} == 0 ]] || targets+=(arbor_bench_fig2_cg)
cmake --build "$build" -j"${JOBS:-1}" --target "${targets[@]}"

work=$build/fig2
mkdir -p "$work"

if [[ ${TIMING:-1} != 0 ]]; then
  echo "== closed loops: 6 variants x 3 modes, $samples samples each"
  "$build/bench/nmpc/arbor_bench_fig2" --samples "$samples" --csv "$work/fig2.csv" \
    --md "$work/tables.md"
  # the machine's load when the timing ended (fig2.py states it; a later rerun of fig2.py alone
  # must not report its own moment's load)
  echo "$(date -u '+%Y-%m-%d %H:%M UTC') $(cut -d' ' -f1-3 /proc/loadavg)" >"$work/timing_load.txt"
else
  samples=$(awk -F, 'NR > 1 && $5 + 1 > n {n = $5 + 1} END {print n}' "$work/fig2.csv")
fi

: >"$work/cg.tsv"
if [[ ${CG:-1} != 0 ]]; then
  echo "== callgrind: samples $cg_from..$((cg_from + cg_count - 1)) of each variant and mode"
  exe="$build/bench/nmpc/arbor_bench_fig2_cg"
  for v in fd_analytical fd_autodiff fd_generated id_analytical id_autodiff id_generated; do
    for m in sqp sqp_c rti; do
      f="$work/cg.$v.$m"
      valgrind --tool=callgrind --instr-atstart=no --collect-atstart=no \
        --callgrind-out-file="$f" "$exe" --cg "$v" "$m" "$cg_from" "$cg_count" \
        >"$f.log" 2>"$f.err" || { cat "$f.err" >&2; exit 1; }
      calls=$(awk '/^calls/ {print $2}' "$f.log")
      failed=$(awk '/^failed/ {print $2}' "$f.log")
      total=$(awk '/^totals:/ {print $2}' "$f")  # (summary: is 0 with --collect-atstart=no)
      # inclusive instructions of the RBD Jacobian routines (where the compiler kept them as
      # functions): callgrind_annotate's inclusive view, the largest entry per pattern
      rbd=$(callgrind_annotate --inclusive=yes --threshold=100 "$f" 2>/dev/null |
        "$py" "$out/fig2.py" --rbd-from-annotate "$v")
      printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$v" "$m" "$total" "$calls" "$failed" "$rbd" >>"$work/cg.tsv"
      echo "  $v $m: $((total / calls)) instructions per sample ($calls samples)"
    done
  done
fi

"$py" "$out/fig2.py" --csv "$work/fig2.csv" --tables "$work/tables.md" --cg "$work/cg.tsv" \
  --cg-from "$cg_from" --samples "$samples" --build "$build" \
  --md "$out/FIG2.md" --png "$out/fig2.png"
echo "wrote $out/FIG2.md and $out/fig2.png"
