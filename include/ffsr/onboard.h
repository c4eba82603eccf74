/* ffsr/onboard.h -- the C interface of ffsr's onboard controllers, for flight frameworks (F Prime
 * components, cFS apps) that call C: opaque handles, fixed-size structs, status codes.
 *
 * A controller is built once at start-up from an onboard blob (an array of doubles that the host
 * writes from a scenario: ffsr-onboard-export, or capture_blob / detumble_blob in C++); building
 * allocates. Then each tick calls its step, which does not allocate, does not throw, and reports a bad
 * input as a status. The implementation (src/onboard/ffsr_onboard.cpp) is C++17 built without
 * exceptions or RTTI (docs/onboard.md).
 *
 * Conventions: SI units; quaternions w, x, y, z; vectors in the inertial frame unless said; joint
 * arrays hold the robot's joints in its coordinate order (the first ffsr_*_joints() entries are used).
 */
#ifndef FFSR_ONBOARD_H
#define FFSR_ONBOARD_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The most joints a fixed-size struct below holds. */
#define FFSR_ONBOARD_MAX_JOINTS 16

typedef enum ffsr_status {
  FFSR_OK = 0,
  FFSR_ERR_ARGUMENT = 1,        /* a null pointer, or a count of joints above FFSR_ONBOARD_MAX_JOINTS */
  FFSR_ERR_BLOB_SHORT = 2,      /* the blob is shorter than its header */
  FFSR_ERR_BLOB_MAGIC = 3,      /* not an ffsr blob */
  FFSR_ERR_BLOB_VERSION = 4,    /* another version of the blob */
  FFSR_ERR_BLOB_KIND = 5,       /* a blob of the other controller */
  FFSR_ERR_BLOB_COUNT = 6,      /* its count of entries is not the length given */
  FFSR_ERR_BLOB_CHECKSUM = 7,   /* altered or truncated */
  FFSR_ERR_BLOB_LAYOUT = 8,     /* a count or an index out of range */
  FFSR_ERR_BLOB_NOT_FINITE = 9, /* a value that is not finite */
  FFSR_ERR_NO_MEMORY = 10,      /* the allocation at start-up failed */
  FFSR_ERR_FAULT = 11           /* a step's input was refused: the command's fault names the field */
} ffsr_status;

/* A short English name of a status ("ok", "blob checksum", ...). */
const char* ffsr_status_name(ffsr_status s);

/* Sets the function called, in place of a throw, where a check of the library fails (a defect: the
 * checks of a blob and of every step's inputs come first and report a status); std::abort() follows
 * when it returns. NULL: std::abort() alone. For a flight framework's fault reporting. */
void ffsr_set_failure_handler(void (*handler)(const char* file, int line));

/* ---- the capture controller: the approach to the target along the planned line ---------------- */

typedef struct ffsr_capture ffsr_capture;

typedef struct ffsr_capture_state {
  double base_position[3];
  double base_orientation[4]; /* w x y z, unit */
  double theta[FFSR_ONBOARD_MAX_JOINTS];
} ffsr_capture_state;

typedef struct ffsr_target_estimate {
  double position[3];         /* centre of mass */
  double attitude[4];         /* w x y z, unit */
  double velocity[3];
  double angular_velocity[3]; /* target frame, rad/s */
} ffsr_target_estimate;

/* status: 0 ok, 1 damped (near a singularity), 2 rate-limited, 3 fault.
 * fault: 0 none, 1 time, 2 base position, 3 base orientation, 4 base quaternion norm, 5 joint count,
 * 6 joint angle, 7 joint limit, 8 target position, 9 target attitude, 10 target attitude norm,
 * 11 target velocity, 12 target angular velocity, 13 numerical; fault_index the joint or component. */
typedef struct ffsr_capture_command {
  double theta_dot[FFSR_ONBOARD_MAX_JOINTS]; /* joint-rate command, rad/s (zero on a fault) */
  double base_velocity[6];                   /* linear then angular: what zero momentum gives */
  double reference[3];                       /* the line's point at t */
  double end_effector[3];                    /* of the measured state */
  double sigma_min;                          /* smallest task singular value */
  double null_scale;                         /* factor on the null-space rates (1: none) */
  int status;
  int fault;
  int fault_index;
} ffsr_capture_command;

/* Builds the controller from a capture blob of `count` doubles (allocates). On success *out is the
 * handle; otherwise *out is NULL and the status names the blob's first defect. */
ffsr_status ffsr_capture_init(const double* blob, size_t count, ffsr_capture** out);
void ffsr_capture_free(ffsr_capture* c);
int ffsr_capture_joints(const ffsr_capture* c);
double ffsr_capture_duration(const ffsr_capture* c); /* T, s: the capture's time */
/* The plan's initial state and the target's state at t = 0 (as the blob holds them). */
ffsr_status ffsr_capture_start(const ffsr_capture* c, ffsr_capture_state* state, ffsr_target_estimate* target);
/* One tick at time t in [0, T]: FFSR_OK, or FFSR_ERR_FAULT with the field in out->fault. */
ffsr_status ffsr_capture_step(ffsr_capture* c, double t, const ffsr_capture_state* state,
                              const ffsr_target_estimate* estimate, ffsr_capture_command* out);
/* Re-plans the capture point from an estimate measured at t (the line re-anchored); on a bad input
 * the plan stays and *fault (may be NULL) names the field. */
ffsr_status ffsr_capture_update_target(ffsr_capture* c, double t, const ffsr_target_estimate* estimate,
                                       int* fault);

/* ---- the detumbling controller: the stack (robot holding the target) brought to rest -------------- */

typedef struct ffsr_detumble ffsr_detumble;

typedef struct ffsr_detumble_state {
  double base_position[3];
  double base_orientation[4];                     /* w x y z, unit */
  double theta[FFSR_ONBOARD_MAX_JOINTS];
  double velocity[6 + FFSR_ONBOARD_MAX_JOINTS];   /* base linear, base angular (inertial), joint rates */
  double wheel_momentum[3];                       /* stored by the reaction wheels, inertial (zero without) */
} ffsr_detumble_state;

/* status: 0 braking, 1 saturated, 2 at rest, 3 fault. fault: 0 none, 1 size, 2 base position,
 * 3 base orientation, 4 joint angle, 5 velocity, 6 wheel momentum, 7 numerical. */
typedef struct ffsr_detumble_command {
  double tau[FFSR_ONBOARD_MAX_JOINTS]; /* joint torques, N m (zero on a fault) */
  double base_wrench[6];               /* force, moment on the base about its origin, inertial */
  double decay;                        /* lambda of the tick, 1/s */
  double base_decay;                   /* k of the tick, 1/s */
  double brake_scale;                  /* the passive law's scale into the limits (1: none cut) */
  double joint_rate;                   /* largest |joint rate| */
  double relative_rate;                /* |gripper's angular velocity relative to the base| */
  double stack_rate;                   /* |base's angular velocity| */
  int passive;                         /* the passive law acted */
  int status;
  int fault;
} ffsr_detumble_command;

/* Builds the controller from a detumble blob of `count` doubles (allocates); as ffsr_capture_init. */
ffsr_status ffsr_detumble_init(const double* blob, size_t count, ffsr_detumble** out);
void ffsr_detumble_free(ffsr_detumble* d);
int ffsr_detumble_joints(const ffsr_detumble* d);
double ffsr_detumble_tick(const ffsr_detumble* d); /* s: the period each command is held */
/* The stack's state at the start (as the blob holds it). */
ffsr_status ffsr_detumble_start(const ffsr_detumble* d, ffsr_detumble_state* state);
/* One tick: FFSR_OK, or FFSR_ERR_FAULT with the field in out->fault. */
ffsr_status ffsr_detumble_step(ffsr_detumble* d, const ffsr_detumble_state* state, ffsr_detumble_command* out);
/* The stack's state `dt` later with the command held (the stack's dynamics, ABA, by one classical
 * Runge-Kutta step; the wheels store the negative of the base moment): a model of the plant for a
 * simulation in the loop or a monitor. Does not allocate. */
ffsr_status ffsr_detumble_predict(ffsr_detumble* d, const ffsr_detumble_state* state,
                                  const ffsr_detumble_command* command, double dt, ffsr_detumble_state* next);

#ifdef __cplusplus
}
#endif

#endif /* FFSR_ONBOARD_H */
