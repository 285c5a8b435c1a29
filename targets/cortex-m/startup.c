/* Start-up code for Cortex-M on the QEMU MPS2 boards: vector table, reset handler (FPU first),
 * .data copy, .bss zeroing, stack painting for high-water measurement, static constructors, and
 * fault handlers that print the fault registers and exit non-zero. */
#include <stdint.h>

#include "arbor_target.h"

extern uint32_t __data_load[], __data_start[], __data_end[], __bss_start[], __bss_end[];
extern uint32_t __stack_limit[], __stack_top[];
extern void __libc_init_array(void);
extern int main(void);

void Reset_Handler(void);
void arbor_reset_c(void);
void HardFault_Handler(void);
void MemManage_Handler(void);
void BusFault_Handler(void);
void UsageFault_Handler(void);
void Default_Handler(void);
void SysTick_Handler(void);

/* Newlib's __libc_init_array calls _init; there is no crti.o with -nostartfiles. */
void _init(void) {}
void _fini(void) {}

/* The reset handler enables the FPU (CPACR CP10/CP11 full access) before any C code can use a
 * floating-point register, then continues in C. Written in assembly so that no compiler-generated
 * prologue can touch the FPU first. */
__attribute__((naked, noreturn)) void Reset_Handler(void) {
  __asm volatile(
      "ldr r0, =0xE000ED88      \n" /* CPACR */
      "ldr r1, [r0]             \n"
      "orr r1, r1, #(0xF << 20) \n"
      "str r1, [r0]             \n"
      "dsb                      \n"
      "isb                      \n"
      "b arbor_reset_c          \n");
}

__attribute__((noreturn)) void arbor_reset_c(void) {
  for (uint32_t *src = __data_load, *dst = __data_start; dst < __data_end;)
    *dst++ = *src++;
  for (uint32_t* p = __bss_start; p < __bss_end;)
    *p++ = 0;
  arbor_paint_stack();
  __libc_init_array();
  const int rc = main();
  arbor_exit(rc);
}

/* ---- stack painting -------------------------------------------------------------------------- */
#define ARBOR_STACK_PAINT 0xC5AC5AC5u

static inline uint32_t* current_sp(void) {
  uint32_t* sp;
  __asm volatile("mov %0, sp" : "=r"(sp));
  return sp;
}

void arbor_paint_stack(void) {
  uint32_t* const sp = current_sp() - 16; /* keep clear of our own frame */
  for (uint32_t* p = __stack_limit; p < sp; ++p)
    *p = ARBOR_STACK_PAINT;
}

uint32_t arbor_stack_high_water(void) {
  const uint32_t* p = __stack_limit;
  while (p < __stack_top && *p == ARBOR_STACK_PAINT)
    ++p;
  return (uint32_t)((const char*)__stack_top - (const char*)p);
}

uint32_t arbor_stack_size(void) {
  return (uint32_t)((char*)__stack_top - (char*)__stack_limit);
}

/* ---- faults -------------------------------------------------------------------------------- */
static void hex(char* out, uint32_t v) {
  static const char digits[] = "0123456789abcdef";
  out[0] = '0';
  out[1] = 'x';
  for (int i = 0; i < 8; ++i)
    out[2 + i] = digits[(v >> (28 - 4 * i)) & 0xf];
  out[10] = 0;
}

static void print_reg(const char* name, uint32_t v) {
  char buf[12];
  hex(buf, v);
  arbor_puts(name);
  arbor_puts(buf);
  arbor_puts("\n");
}

__attribute__((used)) void arbor_fault_report(const char* what, uint32_t* frame) {
  arbor_puts("\n*** ");
  arbor_puts(what);
  arbor_puts(" ***\n");
  print_reg("  CFSR  = ", *(volatile uint32_t*)0xE000ED28);
  print_reg("  HFSR  = ", *(volatile uint32_t*)0xE000ED2C);
  print_reg("  MMFAR = ", *(volatile uint32_t*)0xE000ED34);
  print_reg("  BFAR  = ", *(volatile uint32_t*)0xE000ED38);
  print_reg("  PC    = ", frame[6]);
  print_reg("  LR    = ", frame[5]);
  print_reg("  SP    = ", (uint32_t)frame);
  arbor_exit(ARBOR_EXIT_FAULT);
}

/* Each handler finds the stacked exception frame (MSP or PSP by EXC_RETURN bit 2). */
#define ARBOR_FAULT_HANDLER(fn, label)   \
  __attribute__((naked)) void fn(void) { \
    __asm volatile(                      \
        "tst lr, #4            \n"       \
        "ite eq                \n"       \
        "mrseq r1, msp         \n"       \
        "mrsne r1, psp         \n"       \
        "ldr r0, =" #fn                  \
        "_name \n"                       \
        "b arbor_fault_report  \n");     \
  }                                      \
  const char fn##_name[] __attribute__((used)) = label;

ARBOR_FAULT_HANDLER(HardFault_Handler, "HardFault")
ARBOR_FAULT_HANDLER(MemManage_Handler, "MemManage fault")
ARBOR_FAULT_HANDLER(BusFault_Handler, "BusFault")
ARBOR_FAULT_HANDLER(UsageFault_Handler, "UsageFault")
ARBOR_FAULT_HANDLER(Default_Handler, "unexpected interrupt")

/* ---- SysTick: 24-bit down-counter extended in software, for cycle/instruction counts ------- */
static volatile uint32_t systick_wraps;
void SysTick_Handler(void) {
  ++systick_wraps;
}

#define SYST_CSR (*(volatile uint32_t*)0xE000E010)
#define SYST_RVR (*(volatile uint32_t*)0xE000E014)
#define SYST_CVR (*(volatile uint32_t*)0xE000E018)

void arbor_ticks_start(void) {
  SYST_CSR = 0;
  SYST_RVR = 0x00FFFFFF;
  SYST_CVR = 0; /* clears the counter; it reloads from RVR on the next tick */
  SYST_CSR = 0x7; /* enable, interrupt on wrap, processor clock */
  while (SYST_CVR == 0) {
  }
  systick_wraps = 0;
}

uint64_t arbor_ticks(void) {
  uint32_t wraps, cvr;
  do {
    wraps = systick_wraps;
    cvr = SYST_CVR;
  } while (wraps != systick_wraps);
  return (uint64_t)wraps * 0x01000000u + (0x00FFFFFFu - cvr);
}

/* ---- the vector table ------------------------------------------------------------------------ */
__attribute__((section(".vectors"), used)) void (*const arbor_vectors[16 + 32])(void) = {
    (void (*)(void))__stack_top,
    Reset_Handler,
    Default_Handler, /* NMI */
    HardFault_Handler,
    MemManage_Handler,
    BusFault_Handler,
    UsageFault_Handler,
    0,
    0,
    0,
    0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMon */
    0,
    Default_Handler, /* PendSV */
    SysTick_Handler,
    [16 ... 16 + 31] = Default_Handler,
};
