#!/usr/bin/env bash
# Set-up, build and run the whole test suite (from any folder): the host, then the emulated
# targets (Cortex-M7 and Cortex-M4F bare metal in qemu-system-arm, AArch64 Linux in qemu-aarch64).
# Build folders: build/ and build-<target>/ (override the root with BUILD_DIR). Exit status is
# non-zero when anything fails. ARBOR_TARGETS="" skips the targets. The wall time of each stage
# and the total are printed at the end, also after a failure.
#
# A failing set-up or host build stops the run (the targets need the host's generator and
# results); failing host tests or a failing target do not stop the remaining targets.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build}"
targets="${ARBOR_TARGETS-cortex-m7 cortex-m4f aarch64-linux}"

stage_names=()
stage_seconds=()
stage_results=()
failed=0
start=$SECONDS

summary() {
  local i total=$((SECONDS - start))
  echo
  echo "== wall time per stage"
  for i in "${!stage_names[@]}"; do
    printf '  %-36s %4d:%02d  %s\n' "${stage_names[$i]}" $((stage_seconds[i] / 60)) \
      $((stage_seconds[i] % 60)) "${stage_results[$i]}"
  done
  printf '  %-36s %4d:%02d  %s\n' "total" $((total / 60)) $((total % 60)) \
    "$([ "$failed" = 0 ] && echo passed || echo FAILED)"
  # CPU time of every process started by this script (compilers, tests, emulators). `times`
  # must run in this shell (in a pipeline it would report a subshell's children: zero).
  times > >(awk 'NR == 2 {print "  CPU time of the child processes: user " $1 ", system " $2}')
  wait
}
trap summary EXIT

stage() {  # name command... : runs the command, records its wall time and result
  local name="$1" t0=$SECONDS rc
  shift
  "$@"
  rc=$?
  stage_names+=("$name")
  stage_seconds+=($((SECONDS - t0)))
  if [ "$rc" = 0 ]; then
    stage_results+=("ok")
  else
    stage_results+=("FAILED (exit $rc)")
    failed=1
  fi
  return "$rc"
}

configure_and_build() {  # build-dir cmake-configure-args...
  local dir="$1"
  shift
  cmake -S "$root" -B "$dir" "$@" >/dev/null && cmake --build "$dir" -j2
}

run_tests() {  # build-dir
  (cd "$1" && ctest -j2 --output-on-failure --timeout 900)
}

stage "set-up (apt)" bash "$root/scripts/setup.sh" || exit 1

echo "== host"
stage "host: configure + build" configure_and_build "$build" -DCMAKE_BUILD_TYPE=Release \
  -DARBOR_BUILD_TESTS=ON || exit 1
stage "host: tests" run_tests "$build"

for t in $targets; do
  echo "== $t (emulated)"
  tb="$build-$t"
  # Targets run the portable suites (harness, heap and fault traps, model contract, the RBD core
  # against the reference values and against the host's own results); the host runs everything.
  stage "$t: configure + build" configure_and_build "$tb" \
    --toolchain "$root/toolchains/$t.cmake" -DCMAKE_BUILD_TYPE=Release \
    -DARBOR_GEN_EXECUTABLE="$build/gen/arbor-gen" -DARBOR_HOST_BUILD_DIR="$build" \
    -DARBOR_PORTABLE_TESTS_ONLY=ON &&
    stage "$t: tests" run_tests "$tb"
done

exit "$failed"
