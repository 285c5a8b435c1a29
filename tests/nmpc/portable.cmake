# The pendulum's real-time-iteration closed loop (double and float) on every target: host,
# AArch64, Cortex-M7 (double only) and Cortex-M4F (float only: each FPU's precision). No files, no
# reference solver: the plant is plain RK4 code in the test.
arbor_add_test(nmpc_portable_test SOURCES portable_test.cpp LABELS nmpc PORTABLE UNOPTIMIZED)
target_compile_definitions(nmpc_portable_test PRIVATE ARBOR_TEST_DOUBLE=${arbor_test_double}
                                                      ARBOR_TEST_FLOAT=${arbor_test_float})
# The size matrix's float part (random_matrix_test.cpp, ARBOR_MATRIX_PART 2: a random 7-DoF robot,
# nx = 14, nu = 7, N = 20: Gauss-Newton vs exact Hessian (host only), the hard tunnel after a
# state jump, the RTI closed loop after a jump): SSE2 on the host, NEON on AArch64, no SIMD on
# the Cortex-M4F. Parts 1 and 3 (double, host): CMakeLists.txt.
# Not on the Cortex-M7: the M4F, whose FPU is single precision, runs the same float code without
# SIMD (the M7's float differs only in its FPU's instruction set); the M7's NMPC checks are the
# Kinova's closed loop in double (tests/contour) and the pendulum's (portable_test.cpp). It saves
# the M7 chain, the suite's longest, ~2.5 min of compiler CPU.
if(ARBOR_TARGET STREQUAL "cortex-m7")
  return()
endif()
arbor_add_isa_tests(nmpc_random_matrix2 SOURCES random_matrix_test.cpp LABELS nmpc VARIANTS none
                    PORTABLE UNOPTIMIZED)
target_include_directories(nmpc_random_matrix2_test PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/../dynamics)
target_compile_definitions(nmpc_random_matrix2_test PRIVATE ARBOR_MATRIX_PART=2)
if(CMAKE_CROSSCOMPILING)
  # the suite's time: the targets skip GN vs exact (random_matrix_test.cpp says why)
  target_compile_definitions(nmpc_random_matrix2_test PRIVATE ARBOR_MATRIX_NO_EXACT=1)
endif()
if(ARBOR_BARE_METAL)
  # and the Cortex-M4F the hard tunnel's QP after a jump (its second controller type: 113 -> 80 s
  # of compiler CPU); the host (SSE2) and AArch64 (NEON) keep it
  target_compile_definitions(nmpc_random_matrix2_test PRIVATE ARBOR_MATRIX_NO_HARD_TUNNEL=1)
endif()
