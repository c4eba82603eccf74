/* Semihosting calls (semihost.h). */
#include "semihost.h"

/* Operation numbers of the Arm semihosting specification. */
enum {
  SYS_WRITE0 = 0x04,
  SYS_GET_CMDLINE = 0x15,
  SYS_EXIT = 0x18,
  SYS_EXIT_EXTENDED = 0x20,
  ADP_STOPPED_APPLICATION_EXIT = 0x20026
};

/* r0 = operation, r1 = parameter; the result comes back in r0. The "memory" clobber: the host reads
 * and writes the blocks that r1 points to. */
static uintptr_t semihost_call(uintptr_t operation, const void *parameter) {
  register uintptr_t r0 __asm__("r0") = operation;
  register const void *r1 __asm__("r1") = parameter;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

void ffsr_semihost_write0(const char *text) { (void)semihost_call(SYS_WRITE0, text); }

void ffsr_semihost_write_hex(const char *prefix, uint32_t value) {
  static const char digits[] = "0123456789abcdef";
  char text[12];
  int i;
  text[0] = '0';
  text[1] = 'x';
  for (i = 0; i < 8; ++i) text[2 + i] = digits[(value >> (28 - 4 * i)) & 0xFu];
  text[10] = '\n';
  text[11] = '\0';
  ffsr_semihost_write0(prefix);
  ffsr_semihost_write0(text);
}

void ffsr_semihost_exit(int status) {
  /* On 32-bit Arm, plain SYS_EXIT carries only a reason (QEMU exits 0 for ApplicationExit, 1 for any
   * other); SYS_EXIT_EXTENDED takes a block {reason, subcode} and QEMU exits with the subcode. */
  const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, (uint32_t)status};
  (void)semihost_call(SYS_EXIT_EXTENDED, block);
  /* An emulator without the extension returns here: fall back to the reason-only exit. */
  (void)semihost_call(SYS_EXIT, (const void *)(uintptr_t)(status == 0 ? ADP_STOPPED_APPLICATION_EXIT
                                                                      : 0x20023 /* RunTimeErrorUnknown */));
  for (;;) {
  }
}

int ffsr_semihost_cmdline(char *buffer, size_t size) {
  uintptr_t block[2];
  if (size == 0) return -1;
  block[0] = (uintptr_t)buffer;
  block[1] = (uintptr_t)(size - 1);
  buffer[0] = '\0';
  if (semihost_call(SYS_GET_CMDLINE, block) != 0) return -1;
  buffer[block[1] < size ? block[1] : size - 1] = '\0';
  return 0;
}
