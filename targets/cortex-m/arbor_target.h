/* Services of the bare-metal Cortex-M runtime (targets/cortex-m), callable from C and C++. */
#ifndef ARBOR_TARGET_H
#define ARBOR_TARGET_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Exit codes used by the runtime itself (tests exit with their failure count, 1..120). */
#define ARBOR_EXIT_FAULT 121 /**< a CPU fault handler ran */
#define ARBOR_EXIT_HEAP 122  /**< something tried to allocate from a heap */
#define ARBOR_EXIT_ABORT 123 /**< abort(), a failed eigen_assert/ARBOR_ASSERT, a trap */

/** Writes a NUL-terminated string to the host's standard output (semihosting). */
void arbor_puts(const char* s);
/** Ends the program; `code` becomes QEMU's exit status (SYS_EXIT_EXTENDED). */
__attribute__((noreturn)) void arbor_exit(int code);

/** Fills the free stack with a pattern (done at reset; call again before a measurement). */
void arbor_paint_stack(void);
/** Bytes of stack ever used since the last painting (high-water mark). */
uint32_t arbor_stack_high_water(void);
/** Size of the stack region [bytes]. */
uint32_t arbor_stack_size(void);

/** Starts the SysTick counter from zero (processor clock). */
void arbor_ticks_start(void);
/** SysTick ticks since arbor_ticks_start(), extended to 64 bits by the wrap interrupt. */
uint64_t arbor_ticks(void);

#ifdef __cplusplus
}
#endif

#endif
