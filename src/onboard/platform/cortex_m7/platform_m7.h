/* Internals of the Cortex-M7 platform layer shared by startup.c and platform_m7.c. */
#ifndef FFSR_ONBOARD_PLATFORM_M7_H
#define FFSR_ONBOARD_PLATFORM_M7_H

#include <stdint.h>

/* The word the reset handler paints the free stack with. */
#define FFSR_M7_STACK_PAINT 0xC5A5C5A5u

/* Starts SysTick on the processor clock (called once at reset, before main). */
void ffsr_m7_counter_start(void);

/* SysTick's exception handler: counts the 24-bit counter's wraps. */
void ffsr_m7_systick_handler(void);

#endif
