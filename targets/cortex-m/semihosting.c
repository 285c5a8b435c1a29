/* Arm semihosting (BKPT 0xAB) for output and exit. QEMU is started with
 * -semihosting-config enable=on,target=native,chardev=c -chardev stdio,id=c so that output goes
 * to standard output and the exit code of SYS_EXIT_EXTENDED becomes QEMU's exit status. */
#include <stdint.h>

#include "arbor_target.h"

#define SYS_WRITE0 0x04
#define SYS_EXIT_EXTENDED 0x20
#define ADP_Stopped_ApplicationExit 0x20026

static inline int semihost(int op, const void* arg) {
  register int r0 __asm("r0") = op;
  register const void* r1 __asm("r1") = arg;
  __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

void arbor_puts(const char* s) {
  semihost(SYS_WRITE0, s);
}

void arbor_exit(int code) {
  const uint32_t block[2] = {ADP_Stopped_ApplicationExit, (uint32_t)code};
  for (;;)
    semihost(SYS_EXIT_EXTENDED, block);
}
