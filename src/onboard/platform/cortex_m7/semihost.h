/* Arm semihosting on the Cortex-M7: requests to the debugger or emulator (here QEMU with
 * -semihosting-config enable=on,target=native) through BKPT 0xAB. Used directly only where newlib's
 * stdio cannot be: at reset, in fault handlers, in the allocator's fatal path. */
#ifndef FFSR_ONBOARD_SEMIHOST_H
#define FFSR_ONBOARD_SEMIHOST_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Writes a NUL-terminated string to the host's console (SYS_WRITE0). */
void ffsr_semihost_write0(const char *text);

/* Writes "<prefix>0x<8 hex digits>\n" (for fault reports, without printf). */
void ffsr_semihost_write_hex(const char *prefix, uint32_t value);

/* Ends the emulation with `status` as QEMU's exit status (SYS_EXIT_EXTENDED, reason
 * ADP_Stopped_ApplicationExit, subcode = status). */
void ffsr_semihost_exit(int status) __attribute__((__noreturn__));

/* The command line given to the emulator (SYS_GET_CMDLINE: QEMU joins -semihosting-config arg=...
 * values with spaces), NUL-terminated into `buffer`; returns 0 on success. */
int ffsr_semihost_cmdline(char *buffer, size_t size);

#ifdef __cplusplus
}
#endif

#endif
