# AArch64 Linux, tests run in user-mode QEMU.
# cmake -S . -B build-aarch64 --toolchain toolchains/aarch64-linux.cmake \
#       -DARBOR_GEN_EXECUTABLE=<host arbor-gen> [-DARBOR_AARCH64_COMPILER=clang]
# The compiler: GCC's cross compiler (g++-aarch64-linux-gnu, the default) or, with
# ARBOR_AARCH64_COMPILER=clang, Clang for the same triple with the same Debian sysroot, libstdc++
# and binutils (the suite's choice, scripts/test.sh: half of GCC's compile time and memory on
# this build's units, e.g. tests/qp/qp_matrix_test.cpp 125 -> 64 s and 3.1 -> 1.8 GB).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(ARBOR_TARGET aarch64-linux CACHE STRING "target name" FORCE)
set(ARBOR_AARCH64_COMPILER "gcc" CACHE STRING "gcc (aarch64-linux-gnu-g++) or clang")
# try_compile projects read this file again: they get the same choice
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES ARBOR_AARCH64_COMPILER)
if(ARBOR_AARCH64_COMPILER STREQUAL "clang")
  set(CMAKE_C_COMPILER clang)
  set(CMAKE_CXX_COMPILER clang++)
  set(CMAKE_C_COMPILER_TARGET aarch64-linux-gnu)
  set(CMAKE_CXX_COMPILER_TARGET aarch64-linux-gnu)
elseif(ARBOR_AARCH64_COMPILER STREQUAL "gcc")
  set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
  set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
else()
  message(FATAL_ERROR "ARBOR_AARCH64_COMPILER: gcc or clang, not '${ARBOR_AARCH64_COMPILER}'")
endif()
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64;-L;/usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
