# Shared part of the bare-metal Cortex-M toolchains (included by cortex-m7.cmake, cortex-m4f.cmake).
# Expects ARBOR_CPU_FLAGS, ARBOR_QEMU_MACHINE and ARBOR_TARGET to be set by the includer.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(ARBOR_BARE_METAL ON CACHE BOOL "bare-metal target (no OS, no heap)" FORCE)
set(ARBOR_TARGET ${ARBOR_TARGET} CACHE STRING "target name" FORCE)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(_arbor_targets_dir "${CMAKE_CURRENT_LIST_DIR}/../targets")
set(CMAKE_C_FLAGS_INIT "${ARBOR_CPU_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT
    "${ARBOR_CPU_FLAGS} -ffunction-sections -fdata-sections -fno-exceptions -fno-rtti \
-fno-threadsafe-statics -fno-use-cxa-atexit -include ${_arbor_targets_dir}/cortex-m/target_config.hpp")
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "${ARBOR_CPU_FLAGS} --specs=nano.specs -nostartfiles -Wl,--gc-sections \
-Wl,--wrap=malloc,--wrap=free,--wrap=calloc,--wrap=realloc,--wrap=_malloc_r \
-T ${_arbor_targets_dir}/cortex-m/mps2.ld")

# QEMU: semihosting output to standard output, exit status from SYS_EXIT_EXTENDED; -icount
# shift=0 makes the virtual clock advance 1 ns per instruction (deterministic tick counts).
set(CMAKE_CROSSCOMPILING_EMULATOR
    qemu-system-arm;-M;${ARBOR_QEMU_MACHINE};-display;none;-monitor;none;-serial;none;-icount;shift=0
    -chardev;stdio,id=c;-semihosting-config;enable=on,target=native,chardev=c;-kernel)

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
