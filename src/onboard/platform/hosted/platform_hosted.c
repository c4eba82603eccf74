/* The platform layer (ffsr_platform.h) on Linux: the host and aarch64 under qemu-aarch64. */
#define _POSIX_C_SOURCE 200809L

#include "ffsr_platform.h"

#include <string.h>
#include <time.h>
#include <unistd.h>

void ffsr_platform_fatal(const char *message, int status) {
  /* write(2) and _exit: no stdio (its buffers may allocate), no atexit handlers. */
  static const char prefix[] = "ffsr: ";
  ssize_t ignored = write(STDERR_FILENO, prefix, sizeof prefix - 1);
  ignored = write(STDERR_FILENO, message, strlen(message));
  ignored = write(STDERR_FILENO, "\n", 1);
  (void)ignored;
  _exit(status);
}

/* Not measured on Linux: the main thread's stack is mapped on demand by the kernel. */
size_t ffsr_stack_high_water(void) { return 0; }
size_t ffsr_stack_size(void) { return 0; }
void ffsr_stack_paint(void) {}

uint64_t ffsr_cycles(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (uint64_t)now.tv_sec * 1000000000u + (uint64_t)now.tv_nsec;
}

const char *ffsr_cycles_unit(void) { return "ns (CLOCK_MONOTONIC)"; }
