#!/usr/bin/env bash
# The paper's Fig. 2 reproduced: solve time per sample of the Kinova Gen3 contour NMPC
# (examples/contour; OCP-FD and OCP-ID, analytical vs AD RBD derivatives) along its closed loop,
# in the paper's mode (full SQP, at most 5 iterations per sample, CONTOUR.md's tolerances) and in
# real-time iteration; instructions per sample by callgrind. Writes bench/nmpc/FIG2.md and
# bench/nmpc/fig2.png.
#
#   bash bench/nmpc/fig2.sh [build-dir]          (default: build-fig2 in the repository root)
#
# Environment: SAMPLES (closed-loop samples per variant and mode, default 250), CG_FROM and
# CG_COUNT (the samples callgrind counts, default 50 and 10), CG=0 (skip callgrind), JOBS (build
# parallelism, default 1: each variant's translation unit takes ~2 GB of compiler memory).
# Needs: a C++20 compiler, CMake, Eigen, Google Benchmark, urdfdom (arbor-gen), valgrind,
# python3-matplotlib. Takes ~10 min to build (8 translation units of ~75 s) and ~10 min to run.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-fig2}
samples=${SAMPLES:-250}
cg_from=${CG_FROM:-50}
cg_count=${CG_COUNT:-10}
out=$root/bench/nmpc

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_BENCH=ON >/dev/null
targets=(arbor_bench_fig2)
[[ ${CG:-1} == 0 ]] || targets+=(arbor_bench_fig2_cg)
cmake --build "$build" -j"${JOBS:-1}" --target "${targets[@]}"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "== closed loops: 4 variants x 2 modes, $samples samples each"
"$build/bench/nmpc/arbor_bench_fig2" --samples "$samples" --csv "$tmp/fig2.csv" \
  --md "$tmp/tables.md"

: >"$tmp/cg.tsv"
if [[ ${CG:-1} != 0 ]]; then
  echo "== callgrind: samples $cg_from..$((cg_from + cg_count - 1)) of each variant and mode"
  exe="$build/bench/nmpc/arbor_bench_fig2_cg"
  for v in fd_analytical fd_autodiff id_analytical id_autodiff; do
    for m in sqp sqp_c rti; do
      f="$tmp/cg.$v.$m"
      valgrind --tool=callgrind --instr-atstart=no --collect-atstart=no \
        --callgrind-out-file="$f" "$exe" --cg "$v" "$m" "$cg_from" "$cg_count" \
        >"$f.log" 2>"$f.err" || { cat "$f.err" >&2; exit 1; }
      calls=$(awk '/^calls/ {print $2}' "$f.log")
      failed=$(awk '/^failed/ {print $2}' "$f.log")
      total=$(awk '/^summary:/ {print $2}' "$f")
      # inclusive instructions of the RBD Jacobian routines (where the compiler kept them as
      # functions): callgrind_annotate's inclusive view, the largest entry per pattern
      rbd=$(callgrind_annotate --inclusive=yes --threshold=100 "$f" 2>/dev/null |
        python3 "$out/fig2.py" --rbd-from-annotate "$v")
      printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$v" "$m" "$total" "$calls" "$failed" "$rbd" >>"$tmp/cg.tsv"
      echo "  $v $m: $((total / calls)) instructions per sample ($calls samples)"
    done
  done
fi

python3 "$out/fig2.py" --csv "$tmp/fig2.csv" --tables "$tmp/tables.md" --cg "$tmp/cg.tsv" \
  --cg-from "$cg_from" --samples "$samples" --build "$build" \
  --md "$out/FIG2.md" --png "$out/fig2.png"
echo "wrote $out/FIG2.md and $out/fig2.png"
