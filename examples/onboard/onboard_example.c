/* The onboard example (C99): initialise, lock the heap, run 10^4 ticks, write every tick's outputs to a
 * binary file, report the deepest stack use and the instruction (or time) count per tick.
 *
 *   onboard_example <output file>
 *
 * It runs unchanged on the host, on aarch64 Linux (qemu-aarch64) and on the Cortex-M7 (qemu-system-arm,
 * where the arguments and the file go through semihosting); scripts/onboard.sh builds and runs it on all
 * three and compares the files.
 *
 * For now it drives the STAND-IN workload (src/onboard/standin.h), which the onboard core's C interface
 * will replace.
 *
 * Output file: a 16-byte header, then one record per tick, all little-endian (every target is):
 *   bytes 0-7   magic "FFSRONB1"
 *   bytes 8-11  uint32 number of doubles in a record
 *   bytes 12-15 uint32 number of records (ticks)
 *   records     IEEE-754 binary64 values, each record `doubles` values
 * scripts/onboard-compare.py reads it.
 *
 * Exit status: 0 on success, 1 on a failure of its own (arguments, file, step); the platform's fatal
 * paths have their own statuses (ffsr_platform.h), FFSR_EXIT_HEAP_AFTER_INIT for an allocation after
 * the heap lock.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "ffsr_platform.h"
#include "heap_guard.h"
#include "standin.h"

#define TICKS 10000u

/* Buffers of our own for every stream used after the heap lock: stdio would otherwise allocate them on
 * first use (newlib and glibc both do). Static, not on the stack: they outlive main's frame until
 * exit() flushes and closes the streams. */
static char stdout_buffer[256];
static char output_buffer[4096];

static void put_u32(unsigned char *bytes, uint32_t value) {
  bytes[0] = (unsigned char)(value & 0xFFu);
  bytes[1] = (unsigned char)((value >> 8) & 0xFFu);
  bytes[2] = (unsigned char)((value >> 16) & 0xFFu);
  bytes[3] = (unsigned char)((value >> 24) & 0xFFu);
}

static int write_header(FILE *file, uint32_t doubles, uint32_t records) {
  unsigned char header[16];
  memcpy(header, "FFSRONB1", 8);
  put_u32(header + 8, doubles);
  put_u32(header + 12, records);
  return fwrite(header, 1, sizeof header, file) == sizeof header ? 0 : -1;
}

int main(int argc, char **argv) {
  const char *path;
  FILE *output;
  ffsr_standin *workload;
  ffsr_standin_output values;
  uint64_t total = 0, least = UINT64_MAX, most = 0;
  size_t stack_initialisation, stack_steps;
  unsigned long allocations;
  unsigned tick;

  /* Before any output: stdout's buffer is ours (line-buffered, as on a terminal). */
  setvbuf(stdout, stdout_buffer, _IOLBF, sizeof stdout_buffer);
  if (argc < 2) {
    fprintf(stderr, "usage: %s <output file>\n", argc > 0 ? argv[0] : "onboard_example");
    return 1;
  }
  path = argv[1];

  /* --- Initialisation: everything that allocates. --- */
  output = fopen(path, "wb"); /* newlib's fopen may allocate its table of FILEs */
  if (output == NULL) {
    fprintf(stderr, "onboard_example: cannot open %s\n", path);
    return 1;
  }
  setvbuf(output, output_buffer, _IOFBF, sizeof output_buffer);
  /* The header's record count is known in advance: a partial file (a run that died) is detectable. */
  if (write_header(output, FFSR_STANDIN_OUTPUTS, TICKS) != 0) {
    fprintf(stderr, "onboard_example: cannot write %s\n", path);
    return 1;
  }
  workload = ffsr_standin_init();
  if (workload == NULL) {
    fprintf(stderr, "onboard_example: initialisation failed\n");
    return 1;
  }
  /* stderr is unbuffered on both C libraries: its writes do not allocate. */
  allocations = ffsr_heap_allocations();
  printf("initialised: %lu allocations, %lu bytes\n", allocations, (unsigned long)ffsr_heap_bytes_requested());
  /* The deepest stack use so far (startup, fopen, printf, init), then the stack is painted again so
   * that the next reading is the steps' own (plus this frame and the loop's calls into the file). */
  stack_initialisation = ffsr_stack_high_water();
  ffsr_stack_paint();

  /* --- Steady state: from here every allocation is fatal. --- */
  ffsr_heap_lock();
  for (tick = 0; tick < TICKS; ++tick) {
    const uint64_t start = ffsr_cycles();
    const int status = ffsr_standin_step(workload, &values);
    const uint64_t spent = ffsr_cycles() - start;
    total += spent;
    if (spent < least) least = spent;
    if (spent > most) most = spent;
    if (status != 0) {
      fprintf(stderr, "onboard_example: step %u failed (%d)\n", tick, status);
      return 1;
    }
    if (fwrite(values.values, sizeof values.values, 1, output) != 1) {
      fprintf(stderr, "onboard_example: cannot write %s\n", path);
      return 1;
    }
  }
  stack_steps = ffsr_stack_high_water();
  if (fclose(output) != 0) {
    fprintf(stderr, "onboard_example: cannot write %s\n", path);
    return 1;
  }

  /* Integers only: newlib's printf of a double allocates (its dtoa's big numbers). */
  printf("ticks: %u\n", TICKS);
  printf("allocations after initialisation: %lu\n", ffsr_heap_allocations() - allocations);
  if (ffsr_stack_size() != 0) {
    printf("stack high water: steps %lu bytes, initialisation %lu bytes, of %lu\n", (unsigned long)stack_steps,
           (unsigned long)stack_initialisation, (unsigned long)ffsr_stack_size());
  } else {
    printf("stack high water: not measured on this target\n");
  }
  printf("per step, %s: min %lu mean %lu max %lu\n", ffsr_cycles_unit(), (unsigned long)least,
         (unsigned long)(total / TICKS), (unsigned long)most);
  ffsr_standin_free(workload);
  return 0;
}
