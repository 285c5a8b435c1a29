# Shared part of the bare-metal Cortex-M toolchains (included by cortex-m7.cmake, cortex-m4f.cmake).
# Expects ARBOR_CPU_FLAGS, ARBOR_QEMU_MACHINE and ARBOR_TARGET to be set by the includer.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(ARBOR_BARE_METAL ON CACHE BOOL "bare-metal target (no OS, no heap)" FORCE)
set(ARBOR_TARGET ${ARBOR_TARGET} CACHE STRING "target name" FORCE)

# The compiler: arm-none-eabi-gcc (the default) or, with ARBOR_CORTEX_M_COMPILER=clang, Clang for
# the arm-none-eabi triple (the compiler of Arm's LLVM-based toolchains) on arm-none-eabi-gcc's
# newlib and libstdc++ headers, with GCC's ABI choices (short enums) and GCC's driver as the
# linker (its multilib newlib, libgcc and linker script handling). The suite builds the Cortex-M7
# with GCC and the Cortex-M4F with Clang (scripts/test.sh): both compilers are checked on bare
# metal, and Clang compiles this build's units in about half of GCC's time.
set(ARBOR_CORTEX_M_COMPILER "gcc" CACHE STRING "gcc (arm-none-eabi-gcc) or clang")
# try_compile projects read this file again: they get the same choice
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES ARBOR_CORTEX_M_COMPILER)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(_arbor_targets_dir "${CMAKE_CURRENT_LIST_DIR}/../targets")
set(_arbor_cxx_flags "-ffunction-sections -fdata-sections -fno-exceptions -fno-rtti \
-fno-threadsafe-statics -fno-use-cxa-atexit -include ${_arbor_targets_dir}/cortex-m/target_config.hpp")

if(ARBOR_CORTEX_M_COMPILER STREQUAL "gcc")
  set(CMAKE_C_COMPILER arm-none-eabi-gcc)
  set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
  set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)
  set(_arbor_clang_flags "")
  set(_arbor_clang_c_flags "")
  set(_arbor_clang_link_flags "")
elseif(ARBOR_CORTEX_M_COMPILER STREQUAL "clang")
  set(CMAKE_C_COMPILER clang)
  set(CMAKE_CXX_COMPILER clang++)
  set(CMAKE_ASM_COMPILER clang)
  set(CMAKE_C_COMPILER_TARGET arm-none-eabi)
  set(CMAKE_CXX_COMPILER_TARGET arm-none-eabi)
  set(CMAKE_ASM_COMPILER_TARGET arm-none-eabi)
  # The system headers GCC uses for these CPU flags (newlib; libstdc++ with its multilib
  # directory), without GCC's own compiler headers (Clang has its own).
  separate_arguments(_arbor_cpu_list UNIX_COMMAND "${ARBOR_CPU_FLAGS}")
  execute_process(COMMAND ${CMAKE_COMMAND} -E env LC_ALL=C arm-none-eabi-g++ ${_arbor_cpu_list}
                          -xc++ -E -v /dev/null
                  OUTPUT_QUIET ERROR_VARIABLE _arbor_gcc_v RESULT_VARIABLE _arbor_rc)
  execute_process(COMMAND arm-none-eabi-gcc -print-libgcc-file-name
                  OUTPUT_VARIABLE _arbor_libgcc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT _arbor_rc EQUAL 0 OR NOT _arbor_libgcc)
    message(FATAL_ERROR "ARBOR_CORTEX_M_COMPILER=clang needs arm-none-eabi-gcc (its headers, "
                        "libraries and driver): not found")
  endif()
  get_filename_component(_arbor_gcc_dir "${_arbor_libgcc}" DIRECTORY)
  if(NOT _arbor_gcc_v MATCHES "search starts here:\n.*\nEnd of search list")
    message(FATAL_ERROR "ARBOR_CORTEX_M_COMPILER=clang: no include search list in the output of "
                        "arm-none-eabi-g++ -v:\n${_arbor_gcc_v}")
  endif()
  string(REGEX REPLACE ".*#include <...> search starts here:\n(.*)\nEnd of search list.*" "\\1"
                       _arbor_dirs "${_arbor_gcc_v}")
  string(REPLACE "\n" ";" _arbor_dirs "${_arbor_dirs}")
  set(_arbor_clang_c_flags "-nostdlibinc -fshort-enums")
  set(_arbor_clang_flags "${_arbor_clang_c_flags}")
  foreach(_arbor_dir IN LISTS _arbor_dirs)
    string(STRIP "${_arbor_dir}" _arbor_dir)
    get_filename_component(_arbor_dir "${_arbor_dir}" REALPATH)
    string(FIND "${_arbor_dir}" "${_arbor_gcc_dir}" _arbor_at)
    if(NOT _arbor_at EQUAL 0)
      string(APPEND _arbor_clang_flags " -isystem ${_arbor_dir}")
      if(NOT _arbor_dir MATCHES "/c\\+\\+/")
        string(APPEND _arbor_clang_c_flags " -isystem ${_arbor_dir}")
      endif()
    endif()
  endforeach()
  # Clang marks its objects' stacks non-executable, newlib's objects say nothing (ld warns): no
  # stack is executable on this MPU-less bare metal, say so
  set(_arbor_clang_link_flags "-Wl,-z,noexecstack")
  # GCC's driver links: Clang's objects with newlib, libstdc++ and libgcc of the CPU's multilib
  set(CMAKE_C_LINK_EXECUTABLE
      "arm-none-eabi-gcc <CMAKE_C_LINK_FLAGS> <LINK_FLAGS> <OBJECTS> -o <TARGET> <LINK_LIBRARIES>")
  set(CMAKE_CXX_LINK_EXECUTABLE "arm-none-eabi-g++ <CMAKE_CXX_LINK_FLAGS> <LINK_FLAGS> <OBJECTS> \
-o <TARGET> <LINK_LIBRARIES>")
else()
  message(FATAL_ERROR "ARBOR_CORTEX_M_COMPILER: gcc or clang, not '${ARBOR_CORTEX_M_COMPILER}'")
endif()

set(CMAKE_C_FLAGS_INIT
    "${ARBOR_CPU_FLAGS} ${_arbor_clang_c_flags} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${ARBOR_CPU_FLAGS} ${_arbor_clang_flags} ${_arbor_cxx_flags}")
set(CMAKE_EXE_LINKER_FLAGS_INIT
    "${ARBOR_CPU_FLAGS} ${_arbor_clang_link_flags} --specs=nano.specs -nostartfiles \
-Wl,--gc-sections \
-Wl,--wrap=malloc,--wrap=free,--wrap=calloc,--wrap=realloc,--wrap=_malloc_r \
-T ${_arbor_targets_dir}/cortex-m/mps2.ld")

# QEMU: semihosting output to standard output, exit status from SYS_EXIT_EXTENDED; -icount
# shift=0 makes the virtual clock advance 1 ns per instruction (deterministic tick counts).
set(CMAKE_CROSSCOMPILING_EMULATOR
    qemu-system-arm;-M;${ARBOR_QEMU_MACHINE};-display;none;-monitor;none;-serial;none;-icount;shift=0
    -chardev;stdio,id=c;-semihosting-config;enable=on,target=native,chardev=c;-kernel)

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
