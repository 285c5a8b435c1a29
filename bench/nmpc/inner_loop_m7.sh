#!/usr/bin/env bash
# The inner loop's and the QP feedback gain's instructions per call on the emulated Cortex-M7
# (bench/nmpc/inner_loop_m7.cpp): compiled directly with arm-none-eabi-g++ (-O2, the flags of
# toolchains/cortex-m7.cmake and the runtime of targets/cortex-m, as bench/targets builds its
# benchmarks) and run in QEMU's MPS2 AN500 with -icount shift=0. About 1 min of compiler time.
#   bash bench/nmpc/inner_loop_m7.sh [work-dir]      (default: build-inner-loop-m7)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
work=${1:-$root/build-inner-loop-m7}
mkdir -p "$work"
cpu="-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb"
rt=$root/targets/cortex-m
for c in startup semihosting syscalls; do
  arm-none-eabi-gcc $cpu -O2 -ffunction-sections -fdata-sections -I"$rt" -c "$rt/$c.c" \
    -o "$work/$c.o"
done
eigen=$(pkg-config --cflags eigen3 2>/dev/null || echo -I/usr/include/eigen3)
arm-none-eabi-g++ $cpu -O2 -std=c++20 -ffunction-sections -fdata-sections -fno-exceptions \
  -fno-rtti -fno-threadsafe-statics -fno-use-cxa-atexit -include "$rt/target_config.hpp" \
  -DNDEBUG -Wall -Wextra -Wno-psabi -I"$root/include" $eigen -I"$rt" -I"$root/bench/targets" \
  -I"$root/bench/qp" -c "$root/bench/nmpc/inner_loop_m7.cpp" -o "$work/inner_loop_m7.o"
arm-none-eabi-g++ $cpu --specs=nano.specs -nostartfiles -Wl,--gc-sections \
  -Wl,--wrap=malloc,--wrap=free,--wrap=calloc,--wrap=realloc,--wrap=_malloc_r \
  -T "$rt/mps2.ld" "$work"/*.o -o "$work/inner_loop_m7.elf"
qemu-system-arm -M mps2-an500 -display none -monitor none -serial none -icount shift=0 \
  -chardev stdio,id=c -semihosting-config enable=on,target=native,chardev=c \
  -kernel "$work/inner_loop_m7.elf"
