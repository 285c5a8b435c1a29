# Cortex-M4F with single-precision FPU only, bare metal, run in QEMU's MPS2 AN386 board. double is
# emulated in software here, so the library's target tests run with Scalar = float.
# cmake -S . -B build-m4f --toolchain toolchains/cortex-m4f.cmake -DARBOR_GEN_EXECUTABLE=<host arbor-gen>
set(ARBOR_TARGET cortex-m4f)
set(ARBOR_QEMU_MACHINE mps2-an386)
set(ARBOR_CPU_FLAGS "-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard -mthumb")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
