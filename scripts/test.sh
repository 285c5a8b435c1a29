#!/usr/bin/env bash
# Set-up, build and run the whole test suite (from any folder): the host, then the emulated
# targets (Cortex-M7 and Cortex-M4F bare metal in qemu-system-arm, AArch64 Linux in qemu-aarch64).
# Build folders: build/ and build-<target>/ (override the root with BUILD_DIR). Exit status is
# non-zero when anything fails. ARBOR_TARGETS="" skips the targets. The wall time of each stage
# and the total are printed at the end, also after a failure. After the host build, the host tests
# and the targets run concurrently (below), so their stage times overlap.
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

build_parallel=(-j2)  # the host build runs alone; the concurrent builds share a jobserver (below)
configure_and_build() {  # build-dir cmake-configure-args...
  local dir="$1"
  shift
  cmake -S "$root" -B "$dir" "$@" >/dev/null && cmake --build "$dir" "${build_parallel[@]}"
}

run_tests() {  # build-dir [ctest-args...]
  local dir="$1"
  shift
  (cd "$dir" && ctest -j2 --output-on-failure --timeout 900 "$@")
}

stage "set-up (apt)" bash "$root/scripts/setup.sh" || exit 1

# Two host compilers. The host suite builds with Clang (ARBOR_HOST_CXX): it compiles the
# template-heavy units in 1/1.7 of GCC 12's time and 1/1.8 of its memory (medians per unit, README,
# Tests), and checks the library with a second front end. GCC, the compiler a Debian user builds
# with, builds the ISA variants (-O3 -march=..., AVX2/AVX-512, the fast paths a user builds) and
# the examples beside it (ARBOR_GCC_CXX, build-gcc/; they are not built twice), and the Cortex-M7
# (arm-none-eabi-gcc); the Cortex-M4F and AArch64 build with Clang (target_chain, below).
host_cxx="${ARBOR_HOST_CXX:-clang++}"
gcc_cxx="${ARBOR_GCC_CXX:-g++}"

# With the GCC job, the host build leaves the ISA variants and the examples to it (each built by
# one compiler; ~6 min of compiler CPU); without it (ARBOR_GCC_CXX=""), the host builds them.
host_only=()
[ -n "$gcc_cxx" ] && host_only=(-DARBOR_ISA_VARIANTS=OFF -DARBOR_BUILD_EXAMPLES=OFF)

echo "== host ($host_cxx)"
stage "host: configure + build" configure_and_build "$build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER="$host_cxx" -DARBOR_BUILD_TESTS=ON "${host_only[@]}" || exit 1
# After the host build, the host tests and each target's chain (configure + build, then tests)
# run as concurrent jobs: one build alone leaves a core idle in its serial tail (the last large
# translation unit, linking, the emulator runs) and the host's longest test (IPOPT) runs alone
# for about a minute; together they keep both cores busy (the builds share a jobserver, below).
# Each job writes its output to a log, printed when the job ends; a status line every minute says
# what is still running.
mkdir -p "$build"
records="$build/suite-stages.txt"
: >"$records"

# The concurrent builds share one GNU make jobserver (make 4.3's protocol: a pipe of tokens; each
# make runs one job without a token and takes a token for each further one): with one token, at
# most five compilers at once (four while every build runs, two for the last one) instead of the
# eight of four `-j2` builds. Compilers sharing the two cores slow each other beyond their share
# (four units at once took 13 % longer than the same units two at a time) and peak memory follows
# their number. `cmake --build` without -j lets make join it through MAKEFLAGS.
jobserver="$build/suite-jobserver"
rm -f "$jobserver"
if mkfifo "$jobserver" && exec {jobserver_fd}<>"$jobserver"; then
  rm -f "$jobserver"  # (the open descriptor keeps the pipe)
  printf 'x' >&"$jobserver_fd"
  export MAKEFLAGS="-j --jobserver-auth=$jobserver_fd,$jobserver_fd"
  build_parallel=()
fi

job_stage() {  # name command... : stage() for a job (a subshell): the record goes to a file
  local name="$1" t0=$SECONDS rc
  shift
  "$@"
  rc=$?
  printf '%s\t%s\t%s\n' "$name" $((SECONDS - t0)) \
    "$([ "$rc" = 0 ] && echo ok || echo "FAILED (exit $rc)")" >>"$records"
  return "$rc"
}

target_chain() {  # target
  local t="$1" tb="$build-$1" extra=()
  # AArch64 Linux builds with Clang for the same triple (ARBOR_AARCH64_COMPILER, gcc or clang;
  # toolchains/aarch64-linux.cmake): half of GCC's compile time and memory there. The Cortex-M7
  # builds with arm-none-eabi-gcc, the Cortex-M4F with Clang for arm-none-eabi on GCC's newlib
  # (ARBOR_CORTEX_M4F_COMPILER, gcc or clang; toolchains/arm-none-eabi-common.cmake): each
  # firmware compiler family checked on bare metal, the M4F's units in ~0.55 of GCC's time.
  [ "$t" = aarch64-linux ] && extra=(-DARBOR_AARCH64_COMPILER="${ARBOR_AARCH64_COMPILER:-clang}")
  [ "$t" = cortex-m4f ] && extra=(-DARBOR_CORTEX_M_COMPILER="${ARBOR_CORTEX_M4F_COMPILER:-clang}")
  # Targets run the portable suites (harness, heap and fault traps, model contract, the RBD core
  # against the reference values and against the host's own results); the host runs everything.
  job_stage "$t: configure + build" configure_and_build "$tb" \
    --toolchain "$root/toolchains/$t.cmake" -DCMAKE_BUILD_TYPE=Release \
    -DARBOR_GEN_EXECUTABLE="$build/gen/arbor-gen" -DARBOR_HOST_BUILD_DIR="$build" \
    -DARBOR_PORTABLE_TESTS_ONLY=ON "${extra[@]}" &&
    job_stage "$t: tests" run_tests "$tb"
}

gcc_build() {  # build-dir: the ISA variants and the examples with the second host compiler
  cmake -S "$root" -B "$1" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$gcc_cxx" \
    -DARBOR_BUILD_TESTS=ON -DARBOR_ISA_VARIANTS=ON -DARBOR_BUILD_EXAMPLES=ON \
    -DARBOR_GEN_EXECUTABLE="$build/gen/arbor-gen" >/dev/null &&
    cmake --build "$1" "${build_parallel[@]}" --target arbor_isa_variant_tests robot_table contour
}

gcc_chain() {
  job_stage "host GCC: configure + build" gcc_build "$build-gcc" &&
    job_stage "host GCC: tests" run_tests "$build-gcc" -L isa_variant
}

job_names=()
job_pids=()
job_logs=()
jobs_start=$SECONDS
start_job() {  # name log command...
  local name="$1" log="$2"
  shift 2
  ("$@") >"$log" 2>&1 &
  job_names+=("$name")
  job_pids+=($!)
  job_logs+=("$log")
  echo "== started: $name (output: $log)"
}

start_job "host tests" "$build/suite-host-tests.log" job_stage "host: tests" run_tests "$build"
if [ -n "$gcc_cxx" ]; then  # ARBOR_GCC_CXX="" skips it
  start_job "host GCC (ISA variants, examples)" "$build/suite-host-gcc.log" gcc_chain
fi
for t in $targets; do
  start_job "$t (emulated)" "$build/suite-$t.log" target_chain "$t"
done

pending=("${!job_pids[@]}")
last_status=$SECONDS
while [ "${#pending[@]}" -gt 0 ]; do
  still=()
  for i in "${pending[@]}"; do
    if kill -0 "${job_pids[$i]}" 2>/dev/null; then
      still+=("$i")
    else
      wait "${job_pids[$i]}"
      echo
      echo "== ${job_names[$i]}: finished after $(((SECONDS - jobs_start) / 60)) min (its output follows)"
      cat "${job_logs[$i]}"
    fi
  done
  pending=("${still[@]}")
  if [ "${#pending[@]}" -gt 0 ] && [ $((SECONDS - last_status)) -ge 60 ]; then
    last_status=$SECONDS
    names=""
    for i in "${pending[@]}"; do names+="${names:+, }${job_names[$i]}"; done
    echo "   ... $(((SECONDS - jobs_start) / 60)) min: still running: $names"
  fi
  [ "${#pending[@]}" -gt 0 ] && sleep 5
done

expected=("host: tests")
[ -n "$gcc_cxx" ] && expected+=("host GCC: configure + build" "host GCC: tests")
for t in $targets; do expected+=("$t: configure + build" "$t: tests"); done
for name in "${expected[@]}"; do  # in this order; a stage missing after a failed build is skipped
  line="$(grep -F "$name"$'\t' "$records" | head -1)"
  if [ -z "$line" ]; then
    case "$name" in
      *": tests") continue ;;  # its build failed (recorded) or the chain died (below)
    esac
    line="$name"$'\t0\tFAILED (no record)'
  fi
  IFS=$'\t' read -r _ seconds result <<<"$line"
  stage_names+=("$name")
  stage_seconds+=("$seconds")
  stage_results+=("$result")
  [ "$result" = ok ] || failed=1
done
stage_names+=("host tests + targets (concurrent)")
stage_seconds+=($((SECONDS - jobs_start)))
stage_results+=("$([ "$failed" = 0 ] && echo ok || echo FAILED)")

exit "$failed"
