/* The platform layer (ffsr_platform.h) on the Cortex-M7 (QEMU mps2-an500). */
#include "ffsr_platform.h"

#include "platform_m7.h"
#include "semihost.h"

extern uint32_t __stack_bottom[], __stack_top[];

void ffsr_platform_fatal(const char *message, int status) {
  ffsr_semihost_write0("ffsr: ");
  ffsr_semihost_write0(message);
  ffsr_semihost_write0("\n");
  ffsr_semihost_exit(status);
}

/* The linker script's symbols are distinct objects to C: comparing or subtracting pointers to them is
 * undefined, so the bounds are compared as integers. */
size_t ffsr_stack_high_water(void) {
  const uintptr_t top = (uintptr_t)__stack_top;
  const uint32_t *word = __stack_bottom;
  while ((uintptr_t)word < top && *word == FFSR_M7_STACK_PAINT) ++word;
  return (size_t)(top - (uintptr_t)word);
}

/* A leaf with no frame of its own at -O2: the painting stops at the caller's stack pointer. */
void ffsr_stack_paint(void) {
  uint32_t *word;
  uint32_t *stack_pointer;
  __asm__ volatile("mov %0, sp" : "=r"(stack_pointer));
  for (word = __stack_bottom; (uintptr_t)word < (uintptr_t)stack_pointer; ++word) *word = FFSR_M7_STACK_PAINT;
}

size_t ffsr_stack_size(void) { return (size_t)((uintptr_t)__stack_top - (uintptr_t)__stack_bottom); }

/* SysTick (ARMv7-M system timer) and the SCB's interrupt control register. */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SCB_ICSR (*(volatile uint32_t *)0xE000ED04u)
#define ICSR_PENDSTSET (1u << 26)

/* The full 24-bit range: one wrap every 2^24 ticks (0.67 s of virtual time, 671 million instructions
 * under -icount shift=0), so the wrap interrupt costs nothing measurable. */
#define SYSTICK_RELOAD 0x00FFFFFFu
/* mps2-an500's SYSCLK is 25 MHz: 40 ns of virtual time per SysTick tick. */
#define NANOSECONDS_PER_TICK 40u

static volatile uint32_t systick_wraps;

void ffsr_m7_counter_start(void) {
  SYST_RVR = SYSTICK_RELOAD;
  SYST_CVR = 0u;       /* any write clears the counter; it reloads on the next tick */
  SYST_CSR = 0x7u;     /* ENABLE | TICKINT | CLKSOURCE = processor clock */
}

void ffsr_m7_systick_handler(void) { ++systick_wraps; }

uint64_t ffsr_cycles(void) {
  uint32_t primask;
  uint32_t wraps;
  uint32_t value;
  /* With interrupts masked a wrap cannot be counted behind our back, but one may have happened and be
   * pending: then the value read may be from after the reload while the wrap count is not, so count the
   * pending wrap and read the value again (it cannot wrap twice within a few instructions). */
  __asm__ volatile("mrs %0, primask\n cpsid i" : "=r"(primask)::"memory");
  wraps = systick_wraps;
  value = SYST_CVR;
  if ((SCB_ICSR & ICSR_PENDSTSET) != 0u) {
    ++wraps;
    value = SYST_CVR;
  }
  __asm__ volatile("msr primask, %0" ::"r"(primask) : "memory");
  return ((uint64_t)wraps * (SYSTICK_RELOAD + 1u) + (SYSTICK_RELOAD - value)) * NANOSECONDS_PER_TICK;
}

const char *ffsr_cycles_unit(void) {
  return "instructions (QEMU -icount shift=0 virtual ns from SysTick, resolution 40)";
}
