# The pendulum's real-time-iteration closed loop (double and float) on every target: host,
# AArch64, Cortex-M7 and Cortex-M4F (float only there: its FPU is single precision). No files, no
# reference solver: the plant is plain RK4 code in the test.
arbor_add_test(nmpc_portable_test SOURCES portable_test.cpp LABELS nmpc PORTABLE)
