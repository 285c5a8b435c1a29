#!/usr/bin/env bash
# Instructions of the feedback gain and of the torque-rate inner loop (bench/nmpc/
# inner_loop_icount.cpp), by callgrind: per sample of the demo's closed loop (OCP-FD, analytical,
# hard tunnel, double, the default configuration: FEEDBACK_ITER=2 as contour_icount.sh, whose
# build options it takes) the
# preparation + feedback ("sample"), the stage-0 gain (Nmpc::feedback_gain) and 20 inner-loop
# calls, as median / p99 / max and the gain's and one call's share of the sample's median; then
# instructions per InnerLoop::control call for four sizes. Prints Markdown tables.
#
#   bash bench/nmpc/inner_loop_icount.sh [build-dir]     (default: build-fig2, as contour_icount.sh)
#
# Needs valgrind; about 2 min of compiler time and 1 min of callgrind.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build-fig2}
mkdir -p "$build" && build=$(cd "$build" && pwd)
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_BENCH=ON \
  -DARBOR_CONTOUR_FROZEN_SENSITIVITY=${FROZEN:-ON} -DARBOR_CONTOUR_GENERATED_STAGE=${GENERATED:-ON} \
  >/dev/null
cmake --build "$build" -j"${JOBS:-1}" --target arbor_bench_inner_loop_icount
exe=$build/bench/nmpc/arbor_bench_inner_loop_icount
work=$build/inner_loop_icount
rm -rf "$work" && mkdir -p "$work"
(cd "$work" && valgrind --tool=callgrind --instr-atstart=no --dump-instr=no \
  --callgrind-out-file="$work/cg.demo" "$exe" "${FEEDBACK_ITER:-2}" >"$work/demo.log" 2>"$work/demo.err") ||
  { tail "$work/demo.err" "$work/demo.log" >&2; exit 1; }
# per sample six dumps: gap, preparation, feedback, tail, gain, 20 calls
for f in "$work"/cg.demo.*; do
  k=${f##*.}
  [[ $k =~ ^[0-9]+$ ]] || continue
  echo "$k $(awk '/^totals:/ {print $2}' "$f")"
done | sort -n | awk '
  function sort(a, n,   i, j, t) {
    for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (a[j] < a[i]) {t = a[i]; a[i] = a[j]; a[j] = t}
  }
  function row(name, a, n,   med) {
    sort(a, n); med = a[int((n + 1) / 2)]
    printf "| %s | %d | %d | %d | %d |\n", name, n, med, a[int(0.99 * n + 0.999)], a[n]
    return med
  }
  { s = int(($1 - 1) / 6); p = ($1 - 1) % 6
    if (p == 1) prep[s + 1] = $2
    else if (p == 2) {sample[s + 1] = prep[s + 1] + $2}
    else if (p == 4) gain[s + 1] = $2
    else if (p == 5) {calls[s + 1] = $2 / 20; n = s + 1} }
  END {
    print "| per sample (demo, OCP-FD, double) | samples | median | p99 | max |"
    print "|---|---:|---:|---:|---:|"
    ms = row("sample (preparation + feedback)", sample, n)
    mg = row("stage-0 gain (Nmpc::feedback_gain)", gain, n)
    mc = row("one inner-loop call (start + 20 calls, / 20)", calls, n)
    printf "\ngain / sample median: %.2f %%; one call / sample median: %.3f %%\n", 100 * mg / ms, 100 * mc / ms
  }'
grep "^samples" "$work/demo.log" >&2
(cd "$work" && valgrind --tool=callgrind --instr-atstart=no --dump-instr=no \
  --callgrind-out-file="$work/cg.calls" "$exe" calls >"$work/calls.log" 2>"$work/calls.err") ||
  { tail "$work/calls.err" "$work/calls.log" >&2; exit 1; }
echo
echo "| InnerLoop<Scalar, NX, NU, ND>::control | instructions per call (1000 calls) |"
echo "|---|---:|"
names=("double, 16, 8, 7 (Kinova)" "float, 16, 8, 7 (Kinova)" "double, 4, 2, 2 (2-DoF arm)" "double, 12, 6, 6")
for i in 0 1 2 3; do
  f="$work/cg.calls.$((2 * i + 2))"
  echo "| ${names[$i]} | $(awk '/^totals:/ {printf "%.0f", $2 / 1000}' "$f") |"
done
