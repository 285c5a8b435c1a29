#!/usr/bin/env bash
# Deterministic timing of the demo's controller (bench/nmpc/contour_icount.cpp): instructions per
# preparation and feedback phase of every sample of the contour closed loop (examples/contour,
# analytical, hard tunnel, RTI, double) to s > 0.99, by callgrind: median, p95, max and
# max / median per phase and for the whole sample (issue 14's "max <= 1.5 x median" without the
# machine's noise). OCP-FD and OCP-ID. Prints a Markdown table.
#
#   bash bench/nmpc/contour_icount.sh [build-dir]     (default: build-fig2, as fig2.sh)
#
# The example's default configuration (examples/contour/README.md, "Configurations") unless told:
# FEEDBACK_ITER=K bounds the feedback's QP to K active-set iterations
# (NmpcSettings::feedback_qp_iterations; default 2, the demo's; 0: no bound). FORMS="fd" runs one
# formulation.
# SCENARIO="--mismatch" and/or "--noise SIGMA": the example's plant scenarios (unknown 0.5 kg
# payload; measurement noise), "--no-presolve" the feedback without its prepared first step
# (NmpcSettings::presolve_feedback off). FROZEN=1 (default) / 0: OCP-FD's RK4 with frozen /
# exact sensitivities (ocp::Sensitivity; configures ARBOR_CONTOUR_FROZEN_SENSITIVITY).
# GENERATED=1 (default) / 0: the Gauss-Newton stages from generated code (ocp/generated_stage.hpp)
# / the expression layer (configures ARBOR_CONTOUR_GENERATED_STAGE). Compiled -O3 -march=native
# -mno-avx512f (bench/nmpc/CMakeLists.txt: valgrind runs no AVX-512). The build folder may be the
# demo's (scripts/demo.sh): the benchmarks are configured into it.
#
# Needs valgrind; about 2 min of compiler time and 1 min of callgrind per formulation.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-fig2}
frozen=ON
[[ ${FROZEN:-1} == 0 ]] && frozen=OFF
generated=ON
[[ ${GENERATED:-1} == 0 ]] && generated=OFF
feedback_iter=${FEEDBACK_ITER:-2}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_BENCH=ON \
  -DARBOR_CONTOUR_FROZEN_SENSITIVITY=$frozen -DARBOR_CONTOUR_GENERATED_STAGE=$generated \
  >/dev/null
targets=()
for form in ${FORMS:-fd id}; do
  if [[ $form == id ]]; then targets+=(arbor_bench_contour_icount_id); else targets+=(arbor_bench_contour_icount); fi
done
cmake --build "$build" -j"${JOBS:-1}" --target "${targets[@]}"
work=$build/contour_icount
rm -rf "$work" && mkdir -p "$work"
bound=$feedback_iter
[[ $bound == 0 ]] && bound=none
echo "| formulation | phase (feedback bound $bound${SCENARIO:+, $SCENARIO}, $([[ $frozen == ON ]] && echo frozen || echo exact) sensitivities, $([[ $generated == ON ]] && echo generated stages || echo expression layer)) | samples | median | p95 | p99 | max | max / median |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
for form in ${FORMS:-fd id}; do
  exe=$build/bench/nmpc/arbor_bench_contour_icount
  [[ $form == id ]] && exe=${exe}_id
  (cd "$work" && valgrind --tool=callgrind --instr-atstart=no --dump-instr=no \
    --callgrind-out-file="$work/cg.$form" "$exe" "$feedback_iter" ${SCENARIO:-} >"$work/$form.log" 2>"$work/$form.err") ||
    { tail "$work/$form.err" "$work/$form.log" >&2; exit 1; }
  # one file per dump, cg.<form>.<k>, k = 1, 2, ... in call order; its "totals:" line is the
  # instructions since the previous dump. Per sample: dump 3s+1 closes the gap before the
  # preparation, 3s+2 the preparation, 3s+3 the feedback.
  for f in "$work"/cg.$form.*; do
    k=${f##*.}
    [[ $k =~ ^[0-9]+$ ]] || continue
    echo "$k $(awk '/^totals:/ {print $2}' "$f")"
  done | sort -n | awk -v form="$form" '
    function stats(name, a, n,   i, j, t, med, p95, p99) {
      for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (a[j] < a[i]) {t = a[i]; a[i] = a[j]; a[j] = t}
      med = a[int((n + 1) / 2)]; p95 = a[int(0.95 * n + 0.999)]; p99 = a[int(0.99 * n + 0.999)]
      printf "| %s | %s | %d | %d | %d | %d | %d | %.2f |\n", (form == "fd" ? "OCP-FD" : "OCP-ID"), name, n, med, p95, p99, a[n], a[n] / med
    }
    { s = int(($1 - 1) / 3); p = ($1 - 1) % 3
      if (p == 1) prep[s + 1] = $2; else if (p == 2) {fb[s + 1] = $2; both[s + 1] = prep[s + 1] + $2; n = s + 1} }
    END { stats("preparation", prep, n); stats("feedback", fb, n); stats("sample", both, n) }'
  grep "^samples" "$work/$form.log" | sed 's/^/  /' >&2
done
