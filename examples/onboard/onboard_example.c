/* The onboard example (C99): the capture and the detumbling controllers of ffsr through their C interface
 * (ffsr/onboard.h), each on both paper robots, 10^4 ticks each in a closed loop; every command written to
 * a binary file, the deepest stack use of a step and the instructions (or time) per step reported.
 *
 *   onboard_example <output file>
 *
 * It runs unchanged on the host, on aarch64 Linux (qemu-aarch64) and on the Cortex-M7 (qemu-system-arm,
 * where the arguments and the file go through semihosting); scripts/onboard.sh builds and runs it on all
 * three and compares the files. The four blobs are compiled in (ffsr-onboard-export writes them from the
 * scenario files: robots/paper_3dof.toml, robots/paper_7dof_position.toml, robots/paper_7dof_detumble.toml
 * and examples/onboard/paper_3dof_detumble.toml).
 *
 * The loops: the capture controller's joint rates integrated exactly over the tick (a kinematic stand-in
 * for the arm and its rate loops; the base moves as zero momentum says, as the command reports), the
 * target estimate the plan's; the detumbling controller's torques held over the tick through the stack's
 * dynamics (ffsr_detumble_predict). Only the controllers' steps are timed.
 *
 * Output file: a 16-byte header, then one record per tick, all little-endian (every target is):
 *   bytes 0-7   magic "FFSRONB1"
 *   bytes 8-11  uint32 number of doubles in a record (RECORD)
 *   bytes 12-15 uint32 number of records (RUNS * TICKS)
 *   records     IEEE-754 binary64: run, tick, then the command (capture: theta_dot[16], base velocity
 *               [6], reference [3], end-effector [3], sigma_min, null_scale; detumble: tau[16], base
 *               wrench [6], decay, base decay, brake scale, joint rate, relative rate, stack rate), zero
 *               padded. scripts/onboard-compare.py reads it.
 *
 * Exit status: 0 on success, 1 on a failure of its own (arguments, file, a refused blob or step); the
 * platform's fatal paths have their own statuses (ffsr_platform.h), FFSR_EXIT_HEAP_AFTER_INIT for an
 * allocation after the heap lock.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "ffsr/onboard.h"
#include "ffsr_platform.h"
#include "heap_guard.h"

#define TICKS 10000u
#define RUNS 4
#define RECORD 32
#define STACK_PROBES 20 /* steps on the start state measured alone for their stack */

extern const double ffsr_blob_capture_3dof[];
extern const size_t ffsr_blob_capture_3dof_count;
extern const double ffsr_blob_capture_7dof[];
extern const size_t ffsr_blob_capture_7dof_count;
extern const double ffsr_blob_detumble_3dof[];
extern const size_t ffsr_blob_detumble_3dof_count;
extern const double ffsr_blob_detumble_7dof[];
extern const size_t ffsr_blob_detumble_7dof_count;

/* Buffers of our own for every stream used after the heap lock: stdio would otherwise allocate them on
 * first use (newlib and glibc both do). */
static char stdout_buffer[256];
static char output_buffer[4096];

typedef struct run {
  const char *name;
  int detumble;
  const double *blob;
  const size_t *count;
  ffsr_capture *capture;
  ffsr_detumble *stack;
} run;

typedef struct timing {
  uint64_t total, least, most;
} timing;

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

static void note(timing *t, uint64_t spent) {
  t->total += spent;
  if (spent < t->least) t->least = spent;
  if (spent > t->most) t->most = spent;
}

/* A unit quaternion (w x y z) turned by the angular velocity w over dt (first order, renormalized). */
static void turn(double *q, const double *w, double dt) {
  const double a = q[0], b = q[1], c = q[2], d = q[3];
  double norm = 0;
  int i;
  q[0] = a + 0.5 * dt * (-w[0] * b - w[1] * c - w[2] * d);
  q[1] = b + 0.5 * dt * (w[0] * a + w[1] * d - w[2] * c);
  q[2] = c + 0.5 * dt * (w[1] * a + w[2] * b - w[0] * d);
  q[3] = d + 0.5 * dt * (w[2] * a + w[0] * c - w[1] * b);
  for (i = 0; i < 4; ++i) norm += q[i] * q[i];
  norm = 1.0 / sqrt(norm);
  for (i = 0; i < 4; ++i) q[i] *= norm;
}

static int capture_loop(run *r, int index, FILE *out, timing *t, size_t *stack) {
  ffsr_capture_state s;
  ffsr_target_estimate e;
  ffsr_capture_command c;
  double record[RECORD];
  const int n = ffsr_capture_joints(r->capture);
  const double dt = ffsr_capture_duration(r->capture) / TICKS;
  unsigned tick;
  int k;
  ffsr_capture_start(r->capture, &s, &e);
  ffsr_stack_paint();
  for (tick = 0; tick < STACK_PROBES; ++tick) ffsr_capture_step(r->capture, 0.0, &s, &e, &c);
  *stack = ffsr_stack_high_water();
  for (tick = 0; tick < TICKS; ++tick) {
    const uint64_t start = ffsr_cycles();
    const ffsr_status status = ffsr_capture_step(r->capture, tick * dt, &s, &e, &c);
    note(t, ffsr_cycles() - start);
    if (status != FFSR_OK) {
      fprintf(stderr, "onboard_example: %s: tick %u refused (fault %d)\n", r->name, tick, c.fault);
      return -1;
    }
    memset(record, 0, sizeof record);
    record[0] = index;
    record[1] = tick;
    memcpy(record + 2, c.theta_dot, sizeof c.theta_dot);
    memcpy(record + 18, c.base_velocity, sizeof c.base_velocity);
    memcpy(record + 24, c.reference, sizeof c.reference);
    memcpy(record + 27, c.end_effector, sizeof c.end_effector);
    record[30] = c.sigma_min;
    record[31] = c.null_scale;
    if (fwrite(record, sizeof record, 1, out) != 1) return -1;
    for (k = 0; k < n; ++k) s.theta[k] += dt * c.theta_dot[k];
    for (k = 0; k < 3; ++k) s.base_position[k] += dt * c.base_velocity[k];
    turn(s.base_orientation, c.base_velocity + 3, dt);
  }
  return 0;
}

static int detumble_loop(run *r, int index, FILE *out, timing *t, size_t *stack) {
  ffsr_detumble_state s, next;
  ffsr_detumble_command c;
  double record[RECORD];
  const double dt = ffsr_detumble_tick(r->stack);
  unsigned tick;
  ffsr_detumble_start(r->stack, &s);
  ffsr_stack_paint();
  for (tick = 0; tick < STACK_PROBES; ++tick) ffsr_detumble_step(r->stack, &s, &c);
  *stack = ffsr_stack_high_water();
  for (tick = 0; tick < TICKS; ++tick) {
    const uint64_t start = ffsr_cycles();
    const ffsr_status status = ffsr_detumble_step(r->stack, &s, &c);
    note(t, ffsr_cycles() - start);
    if (status != FFSR_OK) {
      fprintf(stderr, "onboard_example: %s: tick %u refused (fault %d)\n", r->name, tick, c.fault);
      return -1;
    }
    memset(record, 0, sizeof record);
    record[0] = index;
    record[1] = tick;
    memcpy(record + 2, c.tau, sizeof c.tau);
    memcpy(record + 18, c.base_wrench, sizeof c.base_wrench);
    record[24] = c.decay;
    record[25] = c.base_decay;
    record[26] = c.brake_scale;
    record[27] = c.joint_rate;
    record[28] = c.relative_rate;
    record[29] = c.stack_rate;
    if (fwrite(record, sizeof record, 1, out) != 1) return -1;
    if (ffsr_detumble_predict(r->stack, &s, &c, dt, &next) != FFSR_OK) {
      fprintf(stderr, "onboard_example: %s: the plant model failed at tick %u\n", r->name, tick);
      return -1;
    }
    s = next;
  }
  return 0;
}

int main(int argc, char **argv) {
  run runs[RUNS] = {
      {"capture 3-DOF", 0, ffsr_blob_capture_3dof, &ffsr_blob_capture_3dof_count, NULL, NULL},
      {"capture 7-DOF", 0, ffsr_blob_capture_7dof, &ffsr_blob_capture_7dof_count, NULL, NULL},
      {"detumble 3-DOF", 1, ffsr_blob_detumble_3dof, &ffsr_blob_detumble_3dof_count, NULL, NULL},
      {"detumble 7-DOF", 1, ffsr_blob_detumble_7dof, &ffsr_blob_detumble_7dof_count, NULL, NULL}};
  const char *path;
  FILE *output;
  unsigned long allocations;
  size_t stack_initialisation;
  int i;

  setvbuf(stdout, stdout_buffer, _IOLBF, sizeof stdout_buffer);
  if (argc < 2) {
    fprintf(stderr, "usage: %s <output file>\n", argc > 0 ? argv[0] : "onboard_example");
    return 1;
  }
  path = argv[1];

  /* --- Initialisation: everything that allocates. --- */
  output = fopen(path, "wb");
  if (output == NULL) {
    fprintf(stderr, "onboard_example: cannot open %s\n", path);
    return 1;
  }
  setvbuf(output, output_buffer, _IOFBF, sizeof output_buffer);
  if (write_header(output, RECORD, RUNS * TICKS) != 0) {
    fprintf(stderr, "onboard_example: cannot write %s\n", path);
    return 1;
  }
  for (i = 0; i < RUNS; ++i) {
    run *r = &runs[i];
    const ffsr_status s = r->detumble ? ffsr_detumble_init(r->blob, *r->count, &r->stack)
                                      : ffsr_capture_init(r->blob, *r->count, &r->capture);
    if (s != FFSR_OK) {
      fprintf(stderr, "onboard_example: %s: the blob was refused: %s\n", r->name, ffsr_status_name(s));
      return 1;
    }
  }
  allocations = ffsr_heap_allocations();
  printf("initialised: %lu allocations, %lu bytes\n", allocations, (unsigned long)ffsr_heap_bytes_requested());
  stack_initialisation = ffsr_stack_high_water();

  /* --- Steady state: from here every allocation is fatal. --- */
  ffsr_heap_lock();
  for (i = 0; i < RUNS; ++i) {
    run *r = &runs[i];
    timing t = {0, UINT64_MAX, 0};
    size_t stack = 0;
    const int failed = r->detumble ? detumble_loop(r, i, output, &t, &stack) : capture_loop(r, i, output, &t, &stack);
    if (failed) {
      fprintf(stderr, "onboard_example: %s failed\n", r->name);
      return 1;
    }
    /* Integers only: newlib's printf of a double allocates (its dtoa's big numbers). */
    printf("%s: %u ticks, per step %s min %lu mean %lu max %lu", r->name, TICKS, ffsr_cycles_unit(),
           (unsigned long)t.least, (unsigned long)(t.total / TICKS), (unsigned long)t.most);
    if (ffsr_stack_size() != 0) printf(", stack of a step %lu bytes", (unsigned long)stack);
    printf("\n");
  }
  if (fclose(output) != 0) {
    fprintf(stderr, "onboard_example: cannot write %s\n", path);
    return 1;
  }
  printf("allocations after initialisation: %lu\n", ffsr_heap_allocations() - allocations);
  if (ffsr_stack_size() != 0)
    printf("stack high water: initialisation %lu bytes, of %lu\n", (unsigned long)stack_initialisation,
           (unsigned long)ffsr_stack_size());
  else
    printf("stack high water: not measured on this target\n");
  for (i = 0; i < RUNS; ++i) {
    ffsr_capture_free(runs[i].capture);
    ffsr_detumble_free(runs[i].stack);
  }
  return 0;
}
