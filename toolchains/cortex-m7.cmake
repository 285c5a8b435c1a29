# Cortex-M7 with double-precision FPU, bare metal, run in QEMU's MPS2 AN500 board.
# cmake -S . -B build-m7 --toolchain toolchains/cortex-m7.cmake -DARBOR_GEN_EXECUTABLE=<host arbor-gen>
set(ARBOR_TARGET cortex-m7)
set(ARBOR_QEMU_MACHINE mps2-an500)
set(ARBOR_CPU_FLAGS "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb")
include(${CMAKE_CURRENT_LIST_DIR}/arm-none-eabi-common.cmake)
