// src/onboard/ffsr_onboard.cpp -- the C interface of the onboard controllers (include/ffsr/onboard.h):
// handles over the library's CaptureController and DetumbleController, built from an onboard blob
// (control/onboard_blob.hpp). Compiled without exceptions and RTTI on every target (docs/onboard.md).
#include "ffsr/onboard.h"

#include "ffsr/control/capture_controller.hpp"
#include "ffsr/control/detumble_controller.hpp"
#include "ffsr/control/detumble_dynamics.hpp"
#include "ffsr/control/onboard_blob.hpp"

#include <new>
#include <optional>

namespace {

using namespace ffsr;

// The C enumerations are the C++ ones' values (the header documents them as numbers).
static_assert(static_cast<int>(ControlStatus::Fault) == 3 && static_cast<int>(ControlFault::Numerical) == 13,
              "ffsr_capture_command's status and fault codes");
static_assert(static_cast<int>(DetumbleStatus::Fault) == 3 && static_cast<int>(DetumbleFault::Numerical) == 7,
              "ffsr_detumble_command's status and fault codes");

ffsr_status blob_status(BlobStatus s) {
  switch (s) {
    case BlobStatus::Ok:
      return FFSR_OK;
    case BlobStatus::TooShort:
      return FFSR_ERR_BLOB_SHORT;
    case BlobStatus::Magic:
      return FFSR_ERR_BLOB_MAGIC;
    case BlobStatus::Version:
      return FFSR_ERR_BLOB_VERSION;
    case BlobStatus::Kind:
      return FFSR_ERR_BLOB_KIND;
    case BlobStatus::Count:
      return FFSR_ERR_BLOB_COUNT;
    case BlobStatus::Checksum:
      return FFSR_ERR_BLOB_CHECKSUM;
    case BlobStatus::Layout:
      return FFSR_ERR_BLOB_LAYOUT;
    case BlobStatus::NotFinite:
      return FFSR_ERR_BLOB_NOT_FINITE;
  }
  return FFSR_ERR_BLOB_LAYOUT;
}

void put_pose(const BasePose& b, double* position, double* orientation) {
  for (int i = 0; i < 3; ++i) position[i] = b.position(i);
  orientation[0] = b.orientation.w();
  orientation[1] = b.orientation.x();
  orientation[2] = b.orientation.y();
  orientation[3] = b.orientation.z();
}

void get_pose(const double* position, const double* orientation, BasePose& b) {
  b.position = Vector3(position[0], position[1], position[2]);
  b.orientation = Quaternion(orientation[0], orientation[1], orientation[2], orientation[3]);
}

void put3(const Vector3& v, double* out) {
  for (int i = 0; i < 3; ++i) out[i] = v(i);
}

}  // namespace

struct ffsr_capture {
  CaptureBlob blob;
  std::optional<CaptureController<GradientPolicy>> gradient;
  std::optional<CaptureController<ServoPolicy>> servo;
  ControllerState state;
  TargetEstimate estimate;
  ControlCommand command;
};

struct ffsr_detumble {
  DetumbleBlob blob;
  std::optional<DetumbleController> controller;
  std::optional<detail::DetumbleSystem> system;
  std::optional<detail::StackRk4> rk4;
  DetumbleState state;
  DetumbleCommand command, held;
  Eigen::VectorXd y;
};

extern "C" {

const char* ffsr_status_name(ffsr_status s) {
  switch (s) {
    case FFSR_OK:
      return "ok";
    case FFSR_ERR_ARGUMENT:
      return "argument";
    case FFSR_ERR_BLOB_SHORT:
      return "blob shorter than its header";
    case FFSR_ERR_BLOB_MAGIC:
      return "not an ffsr blob";
    case FFSR_ERR_BLOB_VERSION:
      return "blob of another version";
    case FFSR_ERR_BLOB_KIND:
      return "blob of the other controller";
    case FFSR_ERR_BLOB_COUNT:
      return "blob count is not its length";
    case FFSR_ERR_BLOB_CHECKSUM:
      return "blob checksum";
    case FFSR_ERR_BLOB_LAYOUT:
      return "blob count or index out of range";
    case FFSR_ERR_BLOB_NOT_FINITE:
      return "blob value not finite";
    case FFSR_ERR_NO_MEMORY:
      return "no memory";
    case FFSR_ERR_FAULT:
      return "input fault";
  }
  return "?";
}

void ffsr_set_failure_handler(void (*handler)(const char* file, int line)) { set_failure_handler(handler); }

// ---- capture --------------------------------------------------------------------------------------

ffsr_status ffsr_capture_init(const double* blob, size_t count, ffsr_capture** out) {
  if (out == nullptr) return FFSR_ERR_ARGUMENT;
  *out = nullptr;
  auto* c = new (std::nothrow) ffsr_capture;
  if (c == nullptr) return FFSR_ERR_NO_MEMORY;
  const BlobStatus s = read_capture_blob(blob, count, c->blob);
  if (s != BlobStatus::Ok || c->blob.model.n() > FFSR_ONBOARD_MAX_JOINTS) {
    delete c;
    return s != BlobStatus::Ok ? blob_status(s) : FFSR_ERR_ARGUMENT;
  }
  CaptureBlob& b = c->blob;
  if (b.servo)
    c->servo.emplace(b.problem, b.task, b.options, b.servo_policy, b.controller);
  else
    c->gradient.emplace(make_gradient_controller(b.problem, b.task, b.options, b.controller));
  c->state = {b.problem.base, b.problem.theta};
  c->command = c->gradient ? c->gradient->make_command() : c->servo->make_command();
  *out = c;
  return FFSR_OK;
}

void ffsr_capture_free(ffsr_capture* c) { delete c; }

int ffsr_capture_joints(const ffsr_capture* c) { return c != nullptr ? c->blob.model.n() : 0; }

double ffsr_capture_duration(const ffsr_capture* c) { return c != nullptr ? c->blob.options.duration : 0.0; }

ffsr_status ffsr_capture_start(const ffsr_capture* c, ffsr_capture_state* state, ffsr_target_estimate* target) {
  if (c == nullptr || state == nullptr || target == nullptr) return FFSR_ERR_ARGUMENT;
  const CaptureProblem& pb = c->blob.problem;
  put_pose(pb.base, state->base_position, state->base_orientation);
  for (int k = 0; k < FFSR_ONBOARD_MAX_JOINTS; ++k) state->theta[k] = k < pb.theta.size() ? pb.theta(k) : 0.0;
  const Target& t = pb.target;
  put_pose(BasePose{t.position, t.attitude}, target->position, target->attitude);
  put3(t.velocity, target->velocity);
  put3(t.angular_velocity, target->angular_velocity);
  return FFSR_OK;
}

static void get_estimate(const ffsr_target_estimate& e, TargetEstimate& out) {
  BasePose p;
  get_pose(e.position, e.attitude, p);
  out.position = p.position;
  out.attitude = p.orientation;
  out.velocity = Vector3(e.velocity[0], e.velocity[1], e.velocity[2]);
  out.angular_velocity = Vector3(e.angular_velocity[0], e.angular_velocity[1], e.angular_velocity[2]);
}

ffsr_status ffsr_capture_step(ffsr_capture* c, double t, const ffsr_capture_state* state,
                              const ffsr_target_estimate* estimate, ffsr_capture_command* out) {
  if (c == nullptr || state == nullptr || estimate == nullptr || out == nullptr) return FFSR_ERR_ARGUMENT;
  get_pose(state->base_position, state->base_orientation, c->state.base);
  const int n = c->blob.model.n();
  for (int k = 0; k < n; ++k) c->state.theta(k) = state->theta[k];
  get_estimate(*estimate, c->estimate);
  ControlCommand& cmd = c->command;
  if (c->gradient)
    c->gradient->step(t, c->state, c->estimate, cmd);
  else
    c->servo->step(t, c->state, c->estimate, cmd);
  for (int k = 0; k < FFSR_ONBOARD_MAX_JOINTS; ++k) out->theta_dot[k] = k < n ? cmd.theta_dot(k) : 0.0;
  for (int i = 0; i < 6; ++i) out->base_velocity[i] = cmd.base_velocity(i);
  put3(cmd.reference, out->reference);
  put3(cmd.end_effector, out->end_effector);
  out->sigma_min = cmd.sigma_min;
  out->null_scale = cmd.null_scale;
  out->status = static_cast<int>(cmd.status);
  out->fault = static_cast<int>(cmd.fault);
  out->fault_index = cmd.fault_index;
  return cmd.status == ControlStatus::Fault ? FFSR_ERR_FAULT : FFSR_OK;
}

ffsr_status ffsr_capture_update_target(ffsr_capture* c, double t, const ffsr_target_estimate* estimate,
                                       int* fault) {
  if (c == nullptr || estimate == nullptr) return FFSR_ERR_ARGUMENT;
  get_estimate(*estimate, c->estimate);
  const ControlFault f =
      c->gradient ? c->gradient->update_target(t, c->estimate) : c->servo->update_target(t, c->estimate);
  if (fault != nullptr) *fault = static_cast<int>(f);
  return f == ControlFault::None ? FFSR_OK : FFSR_ERR_FAULT;
}

// ---- detumble -------------------------------------------------------------------------------------

ffsr_status ffsr_detumble_init(const double* blob, size_t count, ffsr_detumble** out) {
  if (out == nullptr) return FFSR_ERR_ARGUMENT;
  *out = nullptr;
  auto* d = new (std::nothrow) ffsr_detumble;
  if (d == nullptr) return FFSR_ERR_NO_MEMORY;
  const BlobStatus s = read_detumble_blob(blob, count, d->blob);
  if (s != BlobStatus::Ok || d->blob.stack.n() > FFSR_ONBOARD_MAX_JOINTS) {
    delete d;
    return s != BlobStatus::Ok ? blob_status(s) : FFSR_ERR_ARGUMENT;
  }
  DetumbleBlob& b = d->blob;
  d->controller.emplace(b.stack, b.gripper, b.body, b.limits, b.options, b.tick);
  d->system.emplace(b.stack);
  d->rk4.emplace(d->system->size());
  d->y.resize(d->system->size());
  d->state = b.start;
  d->command = d->controller->make_command();
  d->held = d->controller->make_command();
  *out = d;
  return FFSR_OK;
}

void ffsr_detumble_free(ffsr_detumble* d) { delete d; }

int ffsr_detumble_joints(const ffsr_detumble* d) { return d != nullptr ? d->blob.stack.n() : 0; }

double ffsr_detumble_tick(const ffsr_detumble* d) { return d != nullptr ? d->blob.tick : 0.0; }

static void put_state(const DetumbleState& s, ffsr_detumble_state& out) {
  put_pose(s.base, out.base_position, out.base_orientation);
  const Eigen::Index n = s.theta.size();
  for (Eigen::Index k = 0; k < FFSR_ONBOARD_MAX_JOINTS; ++k) out.theta[k] = k < n ? s.theta(k) : 0.0;
  for (Eigen::Index k = 0; k < 6 + FFSR_ONBOARD_MAX_JOINTS; ++k) out.velocity[k] = k < 6 + n ? s.v(k) : 0.0;
  put3(s.wheel_momentum, out.wheel_momentum);
}

static void get_state(const ffsr_detumble_state& in, DetumbleState& s) {
  get_pose(in.base_position, in.base_orientation, s.base);
  const Eigen::Index n = s.theta.size();
  for (Eigen::Index k = 0; k < n; ++k) s.theta(k) = in.theta[k];
  for (Eigen::Index k = 0; k < 6 + n; ++k) s.v(k) = in.velocity[k];
  s.wheel_momentum = Vector3(in.wheel_momentum[0], in.wheel_momentum[1], in.wheel_momentum[2]);
}

ffsr_status ffsr_detumble_start(const ffsr_detumble* d, ffsr_detumble_state* state) {
  if (d == nullptr || state == nullptr) return FFSR_ERR_ARGUMENT;
  put_state(d->blob.start, *state);
  return FFSR_OK;
}

ffsr_status ffsr_detumble_step(ffsr_detumble* d, const ffsr_detumble_state* state, ffsr_detumble_command* out) {
  if (d == nullptr || state == nullptr || out == nullptr) return FFSR_ERR_ARGUMENT;
  get_state(*state, d->state);
  DetumbleCommand& c = d->command;
  d->controller->step(d->state, c);
  const Eigen::Index n = c.tau.size();
  for (Eigen::Index k = 0; k < FFSR_ONBOARD_MAX_JOINTS; ++k) out->tau[k] = k < n ? c.tau(k) : 0.0;
  for (int i = 0; i < 6; ++i) out->base_wrench[i] = c.base_wrench(i);
  out->decay = c.decay;
  out->base_decay = c.base_decay;
  out->brake_scale = c.brake_scale;
  out->joint_rate = c.joint_rate;
  out->relative_rate = c.relative_rate;
  out->stack_rate = c.stack_rate;
  out->passive = c.passive ? 1 : 0;
  out->status = static_cast<int>(c.status);
  out->fault = static_cast<int>(c.fault);
  return c.status == DetumbleStatus::Fault ? FFSR_ERR_FAULT : FFSR_OK;
}

ffsr_status ffsr_detumble_predict(ffsr_detumble* d, const ffsr_detumble_state* state,
                                  const ffsr_detumble_command* command, double dt, ffsr_detumble_state* next) {
  if (d == nullptr || state == nullptr || command == nullptr || next == nullptr) return FFSR_ERR_ARGUMENT;
  if (!std::isfinite(dt) || dt < 0) return FFSR_ERR_ARGUMENT;
  get_state(*state, d->state);
  const Eigen::Index n = d->held.tau.size();
  for (Eigen::Index k = 0; k < n; ++k) d->held.tau(k) = command->tau[k];
  for (int i = 0; i < 6; ++i) d->held.base_wrench(i) = command->base_wrench[i];
  const DetumbleState& s = d->state;
  const Quaternion q = s.base.orientation.normalized();
  d->y << s.base.position, q.x(), q.y(), q.z(), q.w(), s.theta, s.v, s.wheel_momentum;
  const bool wheels = d->blob.limits.actuator == BaseActuator::ReactionWheels;
  detail::rk4_stack_step(*d->system, *d->rk4, d->y, d->held, wheels, dt);
  if (!d->y.allFinite()) return FFSR_ERR_FAULT;
  d->state.base = d->system->base(d->y);
  d->state.theta = d->y.segment(7, n);
  d->state.v = d->y.segment(7 + n, 6 + n);
  d->state.wheel_momentum = d->y.tail<3>();
  put_state(d->state, *next);
  return FFSR_OK;
}

}  // extern "C"
