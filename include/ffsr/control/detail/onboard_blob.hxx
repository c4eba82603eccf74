// ffsr/control/detail/onboard_blob.hxx -- body of ffsr/control/onboard_blob.hpp.
#pragma once

#include <cstdio>

namespace ffsr {

namespace detail {

inline void write_target(BlobWriter& w, const Target& t) {
  w.put(t.mass);
  w.put(t.inertia);
  w.put(t.position);
  w.put(t.attitude);
  w.put(t.velocity);
  w.put(t.angular_velocity);
  w.put(t.contact_offset);
  w.put(t.normal);
}

inline void read_target(BlobReader& r, Target& t) noexcept {
  t.mass = r.real();
  r.get(t.inertia);
  r.get(t.position);
  r.get(t.attitude);
  r.get(t.velocity);
  r.get(t.angular_velocity);
  r.get(t.contact_offset);
  r.get(t.normal);
}

/// A vector of `size` values (size read first, at most `most`).
inline void read_vector(BlobReader& r, Eigen::VectorXd& x, int most) {
  x.resize(r.integer(0, most));
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = r.real();
}

inline void write_vector(BlobWriter& w, const Eigen::VectorXd& x) {
  w.put(static_cast<double>(x.size()));
  w.put(x);
}

inline void write_capture_options(BlobWriter& w, const CaptureTask& task, const CaptureOptions& o,
                                  const ControllerOptions& c) {
  w.put(task.kind == CaptureTask::Kind::Pose ? 1 : 0);
  for (bool a : task.axes) w.put(a ? 1 : 0);
  w.put(task.final_orientation ? 1 : 0);
  w.put(task.final_orientation.value_or(Matrix3::Identity()));
  for (double x : {o.duration, o.step, o.gain, o.feedback, o.tolerance, o.orientation_tolerance}) w.put(x);
  w.put(o.objective == CaptureObjective::ExactMaxForce ? 1 : 0);
  for (double x : {o.singular_value_threshold, o.max_damping, o.max_joint_rate}) w.put(x);
  w.put(o.hold_base_attitude ? 1 : 0);
  w.put(c.quaternion_tolerance);
  w.put(c.prediction_window);
}

inline void read_capture_options(BlobReader& r, CaptureTask& task, CaptureOptions& o, ControllerOptions& c) {
  task.kind = r.flag() ? CaptureTask::Kind::Pose : CaptureTask::Kind::Position;
  for (bool& a : task.axes) a = r.flag();
  const bool has_orientation = r.flag();
  Matrix3 R;
  r.get(R);
  if (has_orientation) task.final_orientation = R;
  for (double* x : {&o.duration, &o.step, &o.gain, &o.feedback, &o.tolerance, &o.orientation_tolerance})
    *x = r.real();
  o.objective = r.flag() ? CaptureObjective::ExactMaxForce : CaptureObjective::IntegratedEffectiveMass;
  for (double* x : {&o.singular_value_threshold, &o.max_damping, &o.max_joint_rate}) *x = r.real();
  o.hold_base_attitude = r.flag();
  c.quaternion_tolerance = r.real();
  c.prediction_window = r.integer(1, 100000);
}

inline int contact_law_index(const std::string& name) {
  const auto names = contact_law_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  FFSR_THROW(InputError(str("onboard blob: unknown contact law '", name, "'")));
}

}  // namespace detail

/// Reads a capture blob into `out` (which then holds the model the problem points at). Ok, or the
/// first defect (out is then not to be used). Allocates; never throws in a build without exceptions
/// but for memory.
inline BlobStatus read_capture_blob(const double* blob, std::size_t count, CaptureBlob& out) {
  const BlobStatus h = detail::check_blob_header(blob, count, BlobKind::Capture);
  if (h != BlobStatus::Ok) return h;
  detail::BlobReader r(blob, count);
  out.model = detail::read_model(r);
  const int n = r.ok() ? out.model.n() : 0;
  CaptureProblem& pb = out.problem;
  pb.model = &out.model;
  pb.frame = r.integer(0, r.ok() ? static_cast<int>(out.model.frames().size()) - 1 : 0);
  r.get(pb.base.position);
  r.get(pb.base.orientation);
  pb.theta.resize(n);
  r.get(pb.theta);
  detail::read_target(r, pb.target);
  pb.contact.K = r.real();
  pb.contact.alpha = r.real();
  pb.contact.c_r = r.real();
  pb.law = std::string(contact_law_names()[static_cast<std::size_t>(r.integer(0, num_contact_laws - 1))]);
  pb.approach_speed = r.real();
  pb.joints.model = static_cast<JointModel>(r.integer(0, 2));
  detail::read_vector(r, pb.joints.armature, n);
  detail::read_capture_options(r, out.task, out.options, out.controller);
  out.servo = r.flag();
  out.servo_policy.gain = r.real();
  detail::read_vector(r, out.servo_policy.theta_goal, n);
  if (r.ok() && !r.at_end()) r.fail(BlobStatus::Layout);
  return r.status();
}

/// Reads a detumble blob into `out`: Ok, or the first defect.
inline BlobStatus read_detumble_blob(const double* blob, std::size_t count, DetumbleBlob& out) {
  const BlobStatus h = detail::check_blob_header(blob, count, BlobKind::Detumble);
  if (h != BlobStatus::Ok) return h;
  detail::BlobReader r(blob, count);
  out.stack = detail::read_model(r);
  const int n = r.ok() ? out.stack.n() : 0;
  out.gripper = r.integer(0, r.ok() ? static_cast<int>(out.stack.frames().size()) - 1 : 0);
  out.body.mass = r.real();
  r.get(out.body.inertia);
  r.get(out.body.pose.p);
  r.get(out.body.pose.R);
  DetumbleLimits& l = out.limits;
  l.joint_torque.resize(n);
  r.get(l.joint_torque);
  l.actuator = static_cast<BaseActuator>(r.integer(0, 2));
  for (double* x : {&l.wheel_torque, &l.wheel_momentum, &l.thruster_force, &l.thruster_torque}) *x = r.real();
  l.gripper_force = r.real(true);
  l.gripper_moment = r.real(true);
  DetumbleOptions& o = out.options;
  for (double* x : {&o.max_decay, &o.max_base_decay, &o.rest_rate}) *x = r.real();
  o.stop_stack_spin = r.flag();
  o.hold = r.flag();
  out.tick = r.real();
  DetumbleState& s = out.start;
  r.get(s.base.position);
  r.get(s.base.orientation);
  s.theta.resize(n);
  r.get(s.theta);
  s.v.resize(n + 6);
  r.get(s.v);
  r.get(s.wheel_momentum);
  if (r.ok() && !r.at_end()) r.fail(BlobStatus::Layout);
  return r.status();
}

/// The capture controller's set-up as a blob: the problem (its model, target, contact law, initial
/// state), the task, the options and the controller's options; `servo` the servo policy (nullptr:
/// the gradient policy). The clearance barrier (options.rate_guard) does not go onboard: InputError.
/// The blob is read back and its controller built before it is returned (the library's checks).
inline std::vector<double> capture_blob(const CaptureProblem& pb, const CaptureTask& task,
                                        const CaptureOptions& opt, const ControllerOptions& copt = {},
                                        const ServoPolicy* servo = nullptr) {
  if (pb.model == nullptr) FFSR_THROW(InputError("capture_blob: the problem has no model"));
  if (opt.rate_guard) FFSR_THROW(InputError("capture_blob: a rate guard (the clearance barrier) does not go onboard"));
  detail::BlobWriter w(BlobKind::Capture);
  detail::write_model(w, *pb.model);
  w.put(pb.frame);
  w.put(pb.base.position);
  w.put(pb.base.orientation);
  w.put(pb.theta);
  detail::write_target(w, pb.target);
  for (double x : {pb.contact.K, pb.contact.alpha, pb.contact.c_r}) w.put(x);
  w.put(detail::contact_law_index(pb.law));
  w.put(pb.approach_speed);
  w.put(static_cast<int>(pb.joints.model));
  detail::write_vector(w, pb.joints.armature);
  detail::write_capture_options(w, task, opt, copt);
  w.put(servo != nullptr ? 1 : 0);
  w.put(servo != nullptr ? servo->gain : 0.0);
  detail::write_vector(w, servo != nullptr ? servo->theta_goal : Eigen::VectorXd());
  std::vector<double> blob = w.finish();
  CaptureBlob back;
  const BlobStatus s = read_capture_blob(blob.data(), blob.size(), back);
  if (s != BlobStatus::Ok) FFSR_THROW(InputError(detail::str("capture_blob: read back: ", blob_status_name(s))));
  if (back.servo) {
    const CaptureController<ServoPolicy> check(back.problem, back.task, back.options, back.servo_policy,
                                               back.controller);
    (void)check;
  } else {
    const auto check = make_gradient_controller(back.problem, back.task, back.options, back.controller);
    (void)check;
  }
  return blob;
}

/// The detumbling controller's set-up as a blob: the stack (the robot with `body` attached at the
/// gripper frame), the limits, the options, the tick and the stack's state at the start. Read back and
/// its controller built before it is returned.
inline std::vector<double> detumble_blob(const Model& stack, int gripper, const AttachedBody& body,
                                         const DetumbleLimits& limits, const DetumbleOptions& options,
                                         double tick, const DetumbleState& start) {
  detail::BlobWriter w(BlobKind::Detumble);
  detail::write_model(w, stack);
  w.put(gripper);
  w.put(body.mass);
  w.put(body.inertia);
  w.put(body.pose.p);
  w.put(body.pose.R);
  w.put(limits.joint_torque);
  w.put(static_cast<int>(limits.actuator));
  for (double x : {limits.wheel_torque, limits.wheel_momentum, limits.thruster_force, limits.thruster_torque,
                   limits.gripper_force, limits.gripper_moment, options.max_decay, options.max_base_decay,
                   options.rest_rate})
    w.put(x);
  w.put(options.stop_stack_spin ? 1 : 0);
  w.put(options.hold ? 1 : 0);
  w.put(tick);
  w.put(start.base.position);
  w.put(start.base.orientation);
  w.put(start.theta);
  w.put(start.v);
  w.put(start.wheel_momentum);
  std::vector<double> blob = w.finish();
  DetumbleBlob back;
  const BlobStatus s = read_detumble_blob(blob.data(), blob.size(), back);
  if (s != BlobStatus::Ok) FFSR_THROW(InputError(detail::str("detumble_blob: read back: ", blob_status_name(s))));
  const DetumbleController check(back.stack, back.gripper, back.body, back.limits, back.options, back.tick);
  (void)check;
  return blob;
}

/// A blob as C99 source: `const double <name>[]` (hexadecimal floating constants: exact) and
/// `const size_t <name>_count`; `what` goes into the leading comment.
inline std::string blob_c_source(const std::vector<double>& blob, const std::string& name, const std::string& what) {
  std::string s = "/* " + what + " (an ffsr onboard blob, control/onboard_blob.hpp) */\n";
  s += "#include <math.h>\n#include <stddef.h>\n\nconst double " + name + "[] = {\n";
  char buf[64];
  for (std::size_t i = 0; i < blob.size(); ++i) {
    const double x = blob[i];
    if (std::isinf(x))
      (void)std::snprintf(buf, sizeof buf, "%sINFINITY", x < 0 ? "-" : "");
    else
      (void)std::snprintf(buf, sizeof buf, "%a", x);
    s += std::string(i % 4 == 0 ? "  " : " ") + buf + (i + 1 < blob.size() ? "," : "") +
         (i % 4 == 3 || i + 1 == blob.size() ? "\n" : "");
  }
  s += "};\nconst size_t " + name + "_count = " + std::to_string(blob.size()) + ";\n";
  return s;
}

}  // namespace ffsr
