#!/usr/bin/env bash
# The instruction-count rows of scripts/bench_targets.sh (rbd_bench on the Cortex-M7 and M4F under
# qemu-system-arm -icount shift=0, rbd_count on AArch64 Linux under qemu-aarch64's per-instruction
# log), measured the same way for any source tree into a build root of its own, so that two
# commits can be compared like for like (bench/RESULTS-regression.md):
#
#   scripts/bench_targets_rows.sh <source-root> <build-root> [robots...]
#
# Robots default to the source tree's benchmark robots; TARGETS (default "cortex-m7 cortex-m4f
# aarch64-linux") restricts the targets; JOBS (default 1) is the build parallelism. Prints one
# line per row: target robot scalar algorithm instructions/call stack/call (- on AArch64).
# The toolchain files and generator are the source tree's own (arbor-gen built in
# <build-root>/host).
set -euo pipefail
src="$(cd "${1:?usage: bench_targets_rows.sh <source-root> <build-root> [robots...]}" && pwd)"
broot="${2:?usage: bench_targets_rows.sh <source-root> <build-root> [robots...]}"
shift 2
robots=("$@")
targets=(${TARGETS:-cortex-m7 cortex-m4f aarch64-linux})
jobs="${JOBS:-1}"
mkdir -p "$broot"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

host="$broot/host"
cmake -S "$src" -B "$host" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_TESTS=OFF >/dev/null
cmake --build "$host" -j"$jobs" --target arbor-gen >/dev/null

configure() {  # target build-dir
  cmake -S "$src" -B "$2" --toolchain "$src/toolchains/$1.cmake" -DCMAKE_BUILD_TYPE=Release \
    -DARBOR_GEN_EXECUTABLE="$host/gen/arbor-gen" -DARBOR_BUILD_TESTS=OFF -DARBOR_BUILD_BENCH=ON \
    >/dev/null
  if [ ${#robots[@]} -eq 0 ]; then
    local r
    r="$(sed -n 's/^ARBOR_BENCHMARK_ROBOTS:INTERNAL=//p' "$2/CMakeCache.txt" | tr ';' ' ')"
    [ -n "$r" ] || r="double_pendulum iiwa7 kinova_gen3 yumi_no_grippers atlas"
    read -r -a robots <<<"$r"
  fi
}

count_insn() {  # exe algo scalar calls
  qemu-aarch64 -L /usr/aarch64-linux-gnu -singlestep -d exec,nochain -D "$tmp/trace.log" \
    "$1" "$2" "$3" "$4"
  grep -c '^Trace' "$tmp/trace.log"
  rm -f "$tmp/trace.log"
}

for t in "${targets[@]}"; do
  b="$broot/$t"
  configure "$t" "$b"
  if [ "$t" = aarch64-linux ]; then
    for r in "${robots[@]}"; do
      cmake --build "$b" -j"$jobs" --target "rbd_count_$r" >/dev/null
      for sc in double float; do
        for algo in rnea aba crba minverse fk; do
          n10=$(count_insn "$b/bench/targets/rbd_count_$r" $algo $sc 10)
          n20=$(count_insn "$b/bench/targets/rbd_count_$r" $algo $sc 20)
          n30=$(count_insn "$b/bench/targets/rbd_count_$r" $algo $sc 30)
          lin=""
          [ $((n30 - n20)) -eq $((n20 - n10)) ] || lin=" NOT-LINEAR"
          echo "$t $r $sc $algo $(((n20 - n10) / 10)) -$lin"
        done
      done
    done
  else
    machine=mps2-an500
    [ "$t" = cortex-m4f ] && machine=mps2-an386
    for r in "${robots[@]}"; do
      cmake --build "$b" -j"$jobs" --target "rbd_bench_$r" >/dev/null
      qemu-system-arm -M "$machine" -display none -monitor none -serial none -icount shift=0 \
        -chardev stdio,id=c -semihosting-config enable=on,target=native,chardev=c \
        -kernel "$b/bench/targets/rbd_bench_$r" |
        awk -v t="$t" '$1 == "BENCH" {$1 = t; print}'
    done
  fi
done
