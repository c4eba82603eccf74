/* The onboard platform layer: what a program needs from the target beyond ISO C, in one small header
 * for every target (host and aarch64 Linux, Cortex-M7 bare metal). C99 and C++.
 *
 * Implementations: hosted/platform_hosted.c (POSIX), cortex_m7/platform_m7.c (mps2-an500 under QEMU).
 */
#ifndef FFSR_ONBOARD_PLATFORM_H
#define FFSR_ONBOARD_PLATFORM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Exit statuses of the platform's fatal paths, distinct from a program's own failures (1) so that a
 * runner can tell which check fired. */
#define FFSR_EXIT_HEAP_AFTER_INIT 90 /* an allocation after ffsr_heap_lock() (heap_guard.h) */
#define FFSR_EXIT_HARD_FAULT 91      /* Cortex-M7: HardFault or another unexpected exception */
#define FFSR_EXIT_CXX_ERROR 92       /* Cortex-M7: a libstdc++ error that would have thrown */
#define FFSR_EXIT_OUT_OF_MEMORY 93   /* Cortex-M7: operator new found the heap exhausted */
#define FFSR_EXIT_ABORT 94           /* Cortex-M7: abort() */

/* Writes "ffsr: <message>" and a newline to the error channel and ends the program with `status`.
 * Allocation-free and independent of stdio (it may be called from inside malloc or a fault handler):
 * write(2) and _exit on Linux, semihosting on the Cortex-M7. (A GNU attribute: C99 has no _Noreturn,
 * and every target's compiler is GCC.) */
void ffsr_platform_fatal(const char *message, int status) __attribute__((__noreturn__));

/* The deepest stack use since reset, in bytes: the Cortex-M7 startup code paints the whole stack with a
 * pattern and this scans for the lowest word that no longer holds it. 0 where it is not measured (host
 * and aarch64 Linux, whose stacks the kernel grows on demand). */
size_t ffsr_stack_high_water(void);

/* Paints the free stack (below the caller's frame) again, so that the next ffsr_stack_high_water()
 * measures what runs after this call, e.g. the steps without the initialisation. No-op where the stack
 * is not measured. */
void ffsr_stack_paint(void);

/* The stack's size in bytes (the linker script's), 0 where not fixed. */
size_t ffsr_stack_size(void);

/* A monotonic counter for timing a step; ffsr_cycles_unit() names what it counts:
 *  - Cortex-M7 on QEMU: virtual nanoseconds from SysTick (processor clock, 25 MHz SYSCLK: 40 ns a
 *    tick). With QEMU's -icount shift=0 every instruction advances virtual time by exactly 1 ns, so the
 *    counter is the number of instructions executed, to within one tick (40 instructions). It is not a
 *    cycle count: QEMU models no pipeline, caches or wait states.
 *  - host and aarch64 Linux: CLOCK_MONOTONIC nanoseconds (under qemu-aarch64, host time of the
 *    emulation, not a model of the target). */
uint64_t ffsr_cycles(void);
const char *ffsr_cycles_unit(void);

#ifdef __cplusplus
}
#endif

#endif /* FFSR_ONBOARD_PLATFORM_H */
