#!/usr/bin/env bash
# The contour NMPC (examples/contour, Kinova Gen3, analytical RBD derivatives, hard tunnel,
# real-time iteration) on the emulated microcontrollers: the 50-sample closed loop of
# tests/contour/target_test.cpp for OCP-FD and OCP-ID on the host and the Cortex-M7 (double) and for
# OCP-FD and OCP-ID on the host and the Cortex-M4F (float), each target's trajectory checked
# against the host's; QP iterations per sample;
# instructions per preparation and feedback phase (SysTick under QEMU's -icount shift=0); flash,
# static RAM and stack of firmware-sized images with only the controller
# (bench/targets/contour_firmware.cpp). Writes bench/nmpc/RESULTS-targets.md (or $1).
# Build folders: $BUILD_DIR (host, default build-contour-bench) and <it>-cortex-m7/-cortex-m4f.
# About 20 minutes of compiler time on 2 cores (twelve controller translation units, ~2 GB each).
# The example's default configuration (examples/contour/README.md, "Configurations") unless told:
# FEEDBACK_ITER=K: the closed loops' feedback bounded to K QP iterations (issue 38;
# ARBOR_CONTOUR_FEEDBACK_ITER, host and targets alike; default 2, the demo's; 0: no bound).
# FROZEN=1 (default) / 0: OCP-FD's RK4 with frozen / exact sensitivities
# (ARBOR_CONTOUR_FROZEN_SENSITIVITY, host and targets alike). GENERATED=1 (default) / 0: the
# Gauss-Newton stages from generated code / the expression layer (ARBOR_CONTOUR_GENERATED_STAGE; the
# host build generates the header the targets compile). PRESOLVE=0: the feedback computes its
# first QP step itself (ARBOR_CONTOUR_PRESOLVE OFF; NmpcSettings::presolve_feedback, on by
# default as here). TARGETS="cortex-m7" and FORMS="fd" run a subset (defaults: both targets, both
# formulations).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="${1:-$root/bench/nmpc/RESULTS-targets.md}"
host="${BUILD_DIR:-$root/build-contour-bench}"
tmp="$(mktemp -d)"
frozen=OFF
[[ ${FROZEN:-1} == 1 ]] && frozen=ON
generated=OFF
[[ ${GENERATED:-1} == 1 ]] && generated=ON
presolve=ON
[[ ${PRESOLVE:-1} == 0 ]] && presolve=OFF
forms="${FORMS:-fd id}"
trap 'rm -rf "$tmp"' EXIT

targets="${TARGETS:-cortex-m7 cortex-m4f}"
tests=""  # the host's loops in the scalars of the targets (Cortex-M7: double, Cortex-M4F: float)
for form in $forms; do
  [[ " $targets " == *" cortex-m7 "* ]] && tests="$tests contour_target_${form}_double_test"
  [[ " $targets " == *" cortex-m4f "* ]] && tests="$tests contour_target_${form}_float_test"
done
echo "== host"
# -O3 like the targets (hosted tests default to -O1 for compile time: ARBOR_TEST_OPTIMIZATION).
cmake -S "$root" -B "$host" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_TESTS=ON \
  -DARBOR_CONTOUR_TARGET_ID=ON -DARBOR_TEST_OPTIMIZATION= \
  -DARBOR_CONTOUR_FEEDBACK_ITER="${FEEDBACK_ITER:-2}" -DARBOR_CONTOUR_PRESOLVE="$presolve" \
  -DARBOR_CONTOUR_FROZEN_SENSITIVITY="$frozen" -DARBOR_CONTOUR_GENERATED_STAGE="$generated" \
  >/dev/null
# shellcheck disable=SC2086
cmake --build "$host" -j2 --target $tests
for t in $tests; do
  (cd "$host/tests/contour" && "./$t") | tee "$tmp/host_$t.log" | grep -E "CONTOUR|OK|FAILED"
  grep "^CONTOUR" "$tmp/host_$t.log" | sed "s/^/host /" >>"$tmp/runs.txt"
done

for t in $targets; do
  echo "== $t"
  machine=mps2-an500 scalar=double
  [ "$t" = cortex-m4f ] && machine=mps2-an386 scalar=float
  b="$host-$t"
  cmake -S "$root" -B "$b" --toolchain "$root/toolchains/$t.cmake" -DCMAKE_BUILD_TYPE=Release \
    -DARBOR_GEN_EXECUTABLE="$host/gen/arbor-gen" -DARBOR_HOST_BUILD_DIR="$host" \
    -DARBOR_PORTABLE_TESTS_ONLY=ON -DARBOR_CONTOUR_TARGET_ID=ON -DARBOR_BUILD_BENCH=ON \
    -DARBOR_CONTOUR_FEEDBACK_ITER="${FEEDBACK_ITER:-2}" -DARBOR_CONTOUR_PRESOLVE="$presolve" \
    -DARBOR_CONTOUR_FROZEN_SENSITIVITY="$frozen" -DARBOR_CONTOUR_GENERATED_STAGE="$generated" \
    >/dev/null
  loop_forms="$forms"  # closed loops run on this target
  loops=""
  for form in $loop_forms; do loops="$loops contour_target_${form}_${scalar}_test"; done
  # shellcheck disable=SC2086
  firmware=""
  for form in $forms; do firmware="$firmware contour_firmware_$form"; done
  # shellcheck disable=SC2086
  cmake --build "$b" -j2 --target $loops $firmware
  for form in $forms; do
    if [[ " $loop_forms " == *" $form "* ]]; then
      (cd "$b" && ctest -R "contour_target_${form}_${scalar}_test" --output-on-failure -V) |
        tee "$tmp/$t-$form.log" | grep -E "CONTOUR|Passed|Failed|high water"
      grep -o "CONTOUR.*" "$tmp/$t-$form.log" | sed "s/^/$t /" >>"$tmp/runs.txt" || true
      grep -o "stack high water [0-9]*" "$tmp/$t-$form.log" | sed "s/^/$t $form /" >>"$tmp/stack.txt" || true
    fi
    elf="$b/bench/targets/contour_firmware_$form"
    stack=$(qemu-system-arm -M "$machine" -display none -monitor none -serial none \
      -icount shift=0 -chardev stdio,id=c -semihosting-config enable=on,target=native,chardev=c \
      -kernel "$elf" | awk '/FIRMWARE stack/ {print $3}')
    arm-none-eabi-size -A "$elf" |
      awk -v t="$t" -v f="$form" -v sc="$scalar" -v s="$stack" '
        $1 == ".vectors" || $1 == ".text" || $1 == ".ARM.exidx" || $1 == ".ARM.extab" {flash += $2}
        $1 == ".data" {flash += $2; ram += $2}
        $1 == ".bss" {ram += $2}
        END {print t, f, sc, flash, ram, s}' >>"$tmp/firmware.txt"
  done
done

{
  echo "# The contour NMPC on the emulated targets"
  echo
  echo "Generated by \`bash bench/nmpc/contour_targets.sh\` on $(date -u +%Y-%m-%d) at $(git -C "$root" \
    rev-parse --short HEAD). QEMU $(qemu-system-arm --version | head -1 | awk '{print $4}'),"
  echo "$(arm-none-eabi-gcc --version | head -1), Release (-O3) for the closed loop, -O2 for the"
  echo "firmware images; Cortex-M7 = MPS2 AN500 (double FPU), Cortex-M4F = MPS2 AN386 (single FPU)."
  echo "Closed loop: tests/contour/target_test.cpp, 50 samples of 0.02 s from CONTOUR.md's q0,"
  echo "real-time iteration (preparation = shift + prepare before the measurement, feedback = one QP"
  echo "after it), analytical RBD derivatives, hard tunnel; each target's plant trajectory is"
  echo "checked against the host's, relative to 1 + |x_i| (double 1e-6; float 2e-5 on q, s and"
  echo "2e-3 on qd, sd: target_test.cpp derives them)."
  echo "Instructions = SysTick ticks x instructions per tick (calibrated on a loop of known length"
  echo "under -icount shift=0); host rows are microseconds of this machine (shared, noisy)."
  echo "Options: FEEDBACK_ITER=${FEEDBACK_ITER:-2}, FROZEN=${FROZEN:-1}," \
    "GENERATED=${GENERATED:-1}, PRESOLVE=${PRESOLVE:-1}."
  echo
  echo "| where | OCP | scalar | phase | median | p95 | max | unit |"
  echo "|---|---|---|---|---:|---:|---:|---|"
  awk '$2 == "CONTOUR" && $6 == "median" && $8 == "p95" {
    printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $3, $4, $5, $7, $9, $11, $12}' \
    "$tmp/runs.txt"
  echo
  echo "Largest |tau| / limit and final s over the 50 samples; the targets' largest deviation from"
  echo "the host's trajectory:"
  echo
  awk '$2 == "CONTOUR" && ($5 == "max-tau/limit" || $5 == "deviation") {print "    " $0}' "$tmp/runs.txt"
  echo
  echo "QP iterations per sample (one warm-started QP per real-time iteration):"
  echo
  awk '$2 == "CONTOUR" && $5 == "QP" {print "    " $0}' "$tmp/runs.txt"
  echo
  echo "Stack high-water mark of the whole closed-loop test (controller, plant, harness):"
  echo
  awk '{print "    " $0}' "$tmp/stack.txt"
  echo
  echo "## Firmware-sized images (only the controller: workspace, problem, NMPC; one sample)"
  echo
  echo "Flash = .vectors + .text + .ARM.exidx + .ARM.extab + .data; static RAM = .data + .bss"
  echo "(the whole controller: RBD workspace, problem, QP data and solver, plan); stack = high-water"
  echo "mark of one prepare + feedback."
  echo
  echo "| target | OCP | scalar | flash [B] | static RAM [B] | stack [B] |"
  echo "|---|---|---|---:|---:|---:|"
  awk '{printf "| %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6}' "$tmp/firmware.txt"
} >"$tmp/record.md"
# the new record becomes the newest section of $out; its Current figures table and older record stay
python3 "$root/scripts/results_file.py" "$out" "$tmp/record.md" --command "bash bench/nmpc/contour_targets.sh"
