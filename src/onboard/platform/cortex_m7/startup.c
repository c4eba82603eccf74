/* Startup code for the Cortex-M7 on QEMU's mps2-an500 (linker script: mps2_an500.ld).
 *
 * Replaces rdimon's crt0 (the program is linked with -nostartfiles): the vector table, a reset handler
 * that enables the FPU before any floating-point instruction, paints the stack (ffsr_stack_high_water),
 * copies .data, zeroes .bss, starts the instruction counter, opens the semihosting console, runs the
 * static constructors and main with the emulator's arguments, and exits through semihosting with main's
 * status. Also the system-call pieces that newlib's librdimon gets wrong or too loose for us: _sbrk
 * bounded by the linker script's heap, _exit with the status, abort with a message.
 */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "ffsr_platform.h"
#include "platform_m7.h"
#include "semihost.h"

/* Symbols of the linker script. */
extern uint32_t __stack_bottom[], __stack_top[];
extern uint32_t __data_start[], __data_end[], __data_load[];
extern uint32_t __bss_start__[], __bss_end__[];
extern char __heap_start[], __heap_end[];

/* newlib and libgloss. */
extern void __libc_init_array(void);
extern void initialise_monitor_handles(void);
extern int main(int argc, char **argv);

void ffsr_reset_handler(void) __attribute__((naked, noreturn));
void ffsr_start(void) __attribute__((noreturn, used));
void ffsr_hard_fault_handler(void) __attribute__((naked, noreturn));
void ffsr_fault_report(const uint32_t *frame, uint32_t exc_return) __attribute__((noreturn, used));
void ffsr_unexpected_handler(void) __attribute__((noreturn));

/* The vector table: the initial stack pointer, then the handlers, at address 0 (VTOR's reset value).
 * Only the 16 system exceptions: the program enables no external interrupt. MemManage, BusFault and
 * UsageFault are disabled at reset and escalate to HardFault; they get the same handler anyway. */
typedef void (*ffsr_vector)(void);
__attribute__((section(".vectors"), used)) static const ffsr_vector ffsr_vectors[16] = {
    (ffsr_vector)(uintptr_t)__stack_top, /* initial SP */
    ffsr_reset_handler,
    ffsr_unexpected_handler,  /* NMI */
    ffsr_hard_fault_handler,  /* HardFault */
    ffsr_hard_fault_handler,  /* MemManage */
    ffsr_hard_fault_handler,  /* BusFault */
    ffsr_hard_fault_handler,  /* UsageFault */
    0, 0, 0, 0,               /* reserved */
    ffsr_unexpected_handler,  /* SVCall */
    ffsr_unexpected_handler,  /* DebugMonitor */
    0,                        /* reserved */
    ffsr_unexpected_handler,  /* PendSV */
    ffsr_m7_systick_handler,  /* SysTick: the instruction counter's wrap count (platform_m7.c) */
};

/* Naked, in assembly: the compiler may use floating-point registers anywhere in C code (with
 * -mfloat-abi=hard even a struct copy can), and an FP instruction with CP10/CP11 disabled is a
 * UsageFault. CPACR (0xE000ED88) bits 20-23 give full access to CP10 and CP11; DSB/ISB make the change
 * visible before the next instruction. */
void ffsr_reset_handler(void) {
  __asm__ volatile(
      "ldr r0, =0xE000ED88\n"
      "ldr r1, [r0]\n"
      "orr r1, r1, #(0xF << 20)\n"
      "str r1, [r0]\n"
      "dsb\n"
      "isb\n"
      "b ffsr_start\n"
      ".ltorg\n");
}

/* Splits the semihosting command line at spaces (QEMU joins the arg= values with single spaces, so
 * arguments cannot contain spaces). argv[0] is the program's name as the runner gave it. */
#define FFSR_MAX_ARGS 8
static char command_line[256];
static char *arguments[FFSR_MAX_ARGS + 1];

static int split_command_line(void) {
  int count = 0;
  char *cursor = command_line;
  if (ffsr_semihost_cmdline(command_line, sizeof command_line) != 0) return 0;
  while (*cursor != '\0' && count < FFSR_MAX_ARGS) {
    while (*cursor == ' ') *cursor++ = '\0';
    if (*cursor == '\0') break;
    arguments[count++] = cursor;
    while (*cursor != '\0' && *cursor != ' ') ++cursor;
  }
  arguments[count] = NULL;
  return count;
}

void ffsr_start(void) {
  uint32_t *word;
  const uint32_t *source;
  uint32_t *stack_pointer;

  /* Paint the unused stack, from its bottom up to the current stack pointer (what lies above it is
   * this function's frame). Memory is written only below the stack pointer by pushes and frames, so a
   * word that no longer holds the pattern has been used. */
  __asm__ volatile("mov %0, sp" : "=r"(stack_pointer));
  /* (The linker script's symbols are distinct objects to C: bounds are compared as integers.) */
  for (word = __stack_bottom; (uintptr_t)word < (uintptr_t)stack_pointer; ++word) *word = FFSR_M7_STACK_PAINT;

  for (word = __data_start, source = __data_load; (uintptr_t)word < (uintptr_t)__data_end; ++word, ++source)
    *word = *source;
  for (word = __bss_start__; (uintptr_t)word < (uintptr_t)__bss_end__; ++word) *word = 0u;

  ffsr_m7_counter_start();
  initialise_monitor_handles(); /* librdimon: stdin/stdout/stderr as semihosting handles */
  __libc_init_array();          /* static constructors */
  {
    const int argc = split_command_line();
    /* exit, not _exit: atexit handlers and static destructors run and stdio is flushed. */
    exit(main(argc, arguments));
  }
}

/* newlib's __libc_init_array and __libc_fini_array call _init and _fini (crti.o/crtn.o, left out with
 * -nostartfiles): nothing to do for them here. */
void _init(void) {}
void _fini(void) {}

/* The handle that C++ registers static destructors under (__cxa_atexit); crtbegin.o defines it and is
 * left out with -nostartfiles. One image, no shared objects: any unique address does. */
void *__dso_handle = &__dso_handle;

/* The end of every exit path: QEMU's exit status is `status`. */
void _exit(int status) { ffsr_semihost_exit(status); }

void abort(void) { ffsr_platform_fatal("abort() called", FFSR_EXIT_ABORT); }

/* The heap is the linker script's fixed region [__heap_start, __heap_end): malloc fails cleanly (NULL,
 * ENOMEM) when it is exhausted instead of growing into the stack or past the end of the RAM. */
void *_sbrk(ptrdiff_t increment) {
  static uintptr_t program_break;
  const uintptr_t start = (uintptr_t)__heap_start, end = (uintptr_t)__heap_end;
  uintptr_t previous;
  if (program_break == 0u) program_break = start;
  previous = program_break;
  if (increment < 0 ? previous - start < (uintptr_t)-increment : end - previous < (uintptr_t)increment) {
    errno = ENOMEM;
    return (void *)-1;
  }
  program_break = previous + (uintptr_t)increment;
  return (void *)previous;
}

/* Which stack the exception frame was pushed on (EXC_RETURN bit 2) tells where to read the faulting
 * PC; the report itself is C. */
void ffsr_hard_fault_handler(void) {
  __asm__ volatile(
      "tst lr, #4\n"
      "ite eq\n"
      "mrseq r0, msp\n"
      "mrsne r0, psp\n"
      "mov r1, lr\n"
      "b ffsr_fault_report\n");
}

void ffsr_fault_report(const uint32_t *frame, uint32_t exc_return) {
  volatile const uint32_t *const scb = (volatile const uint32_t *)0xE000ED00u;
  uint32_t ipsr;
  __asm__ volatile("mrs %0, ipsr" : "=r"(ipsr));
  ffsr_semihost_write0("ffsr: fault: exception ");
  ffsr_semihost_write_hex("", ipsr & 0x1FFu);
  ffsr_semihost_write_hex("  pc    ", frame[6]);
  ffsr_semihost_write_hex("  lr    ", frame[5]);
  ffsr_semihost_write_hex("  CFSR  ", scb[0x28 / 4]);
  ffsr_semihost_write_hex("  HFSR  ", scb[0x2C / 4]);
  ffsr_semihost_write_hex("  MMFAR ", scb[0x34 / 4]);
  ffsr_semihost_write_hex("  BFAR  ", scb[0x38 / 4]);
  ffsr_semihost_write_hex("  EXC_RETURN ", exc_return);
  ffsr_semihost_exit(FFSR_EXIT_HARD_FAULT);
}

void ffsr_unexpected_handler(void) {
  uint32_t ipsr;
  __asm__ volatile("mrs %0, ipsr" : "=r"(ipsr));
  ffsr_semihost_write_hex("ffsr: unexpected exception ", ipsr & 0x1FFu);
  ffsr_semihost_exit(FFSR_EXIT_HARD_FAULT);
}
