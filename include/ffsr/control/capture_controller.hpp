// ffsr/control/capture_controller.hpp -- the capture approach as an onboard controller: one call per
// control tick, no heap allocation, no exception.
#pragma once

#include "ffsr/optimize/capture.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

namespace ffsr {

/// The measured state of the robot at a tick: base pose (position, unit quaternion) and joint angles.
struct ControllerState {
  BasePose base;
  Eigen::VectorXd theta;
};

/// What a vision filter measures of the target at a time: centre of mass, attitude, velocity and
/// spin (target frame). Its mass, inertia, contact offset and normal are the plan's.
struct TargetEstimate {
  Vector3 position = Vector3::Zero();
  Quaternion attitude = Quaternion::Identity();
  Vector3 velocity = Vector3::Zero();
  Vector3 angular_velocity = Vector3::Zero();  ///< target frame, rad/s
};

/// The estimate a target describes (its state).
inline TargetEstimate target_estimate(const Target& t) {
  return {t.position, t.attitude, t.velocity, t.angular_velocity};
}

enum class ControlStatus { Ok, Damped, RateLimited, Fault };

/// The input field a fault names.
enum class ControlFault {
  None,
  Time,                   ///< t outside [0, T] or not finite
  BasePosition,           ///< non-finite
  BaseOrientation,        ///< non-finite quaternion
  BaseQuaternionNorm,     ///< | |q| - 1 | above the tolerance
  JointCount,             ///< theta (or the command's theta_dot) has the wrong size
  JointAngle,             ///< non-finite joint angle (fault_index: the joint)
  JointLimit,             ///< joint outside its limits (fault_index: the joint)
  TargetPosition,         ///< non-finite
  TargetAttitude,         ///< non-finite quaternion
  TargetAttitudeNorm,     ///< | |q| - 1 | above the tolerance
  TargetVelocity,         ///< non-finite
  TargetAngularVelocity,  ///< non-finite
  Numerical,              ///< the rate law failed or gave a non-finite rate
};

inline const char* status_name(ControlStatus s) {
  switch (s) {
    case ControlStatus::Ok:
      return "ok";
    case ControlStatus::Damped:
      return "damped";
    case ControlStatus::RateLimited:
      return "rate-limited";
    case ControlStatus::Fault:
      return "fault";
  }
  return "?";
}

inline const char* fault_name(ControlFault f) {
  switch (f) {
    case ControlFault::None:
      return "none";
    case ControlFault::Time:
      return "time";
    case ControlFault::BasePosition:
      return "base position";
    case ControlFault::BaseOrientation:
      return "base orientation";
    case ControlFault::BaseQuaternionNorm:
      return "base quaternion norm";
    case ControlFault::JointCount:
      return "joint count";
    case ControlFault::JointAngle:
      return "joint angle";
    case ControlFault::JointLimit:
      return "joint limit";
    case ControlFault::TargetPosition:
      return "target position";
    case ControlFault::TargetAttitude:
      return "target attitude";
    case ControlFault::TargetAttitudeNorm:
      return "target attitude norm";
    case ControlFault::TargetVelocity:
      return "target velocity";
    case ControlFault::TargetAngularVelocity:
      return "target angular velocity";
    case ControlFault::Numerical:
      return "numerical";
  }
  return "?";
}

/// What a tick writes (caller-owned; make it with CaptureController::make_command()).
struct ControlCommand {
  Eigen::VectorXd theta_dot;                ///< joint-rate command, rad/s (zero on a fault)
  Vector6 base_velocity = Vector6::Zero();  ///< [v_0; omega_0] from zero momentum with theta_dot
  Vector3 reference = Vector3::Zero();      ///< x_d(t)
  Vector3 end_effector = Vector3::Zero();   ///< p_e of the measured state
  ControlStatus status = ControlStatus::Ok;
  ControlFault fault = ControlFault::None;
  int fault_index = -1;   ///< the joint (JointAngle, JointLimit) or the vector component, else -1
  double sigma_min = 0;   ///< smallest task singular value
  double null_scale = 1;  ///< factor applied to the null-space rates (1: not scaled)
};

/// Settings of the controller beside the plan's CaptureOptions.
struct ControllerOptions {
  double quaternion_tolerance = 1e-3;  ///< largest accepted | |q| - 1 | (base and target estimate)
  /// update_target: the capture point (and normal) is the mean of the predictions of the last
  /// `prediction_window` estimates (1: the latest alone). Averaging divides the noise of independent
  /// estimates by sqrt(window) while the target follows its torque-free motion (every estimate then
  /// predicts the same point); a target that changes its motion is followed with that delay.
  int prediction_window = 1;
};

namespace detail {

inline bool finite3(const Vector3& v, int& bad) noexcept {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(v(i))) {
      bad = i;
      return false;
    }
  return true;
}

inline bool finite_quaternion(const Quaternion& q, int& bad) noexcept {
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(q.coeffs()(i))) {
      bad = i;
      return false;
    }
  return true;
}

/// The first bad field of a target estimate (None if none); `bad` the component.
inline ControlFault check_estimate(const TargetEstimate& e, double qtol, int& bad) noexcept {
  if (!finite3(e.position, bad)) return ControlFault::TargetPosition;
  if (!finite_quaternion(e.attitude, bad)) return ControlFault::TargetAttitude;
  if (std::abs(e.attitude.norm() - 1.0) > qtol) return ControlFault::TargetAttitudeNorm;
  if (!finite3(e.velocity, bad)) return ControlFault::TargetVelocity;
  if (!finite3(e.angular_velocity, bad)) return ControlFault::TargetAngularVelocity;
  return ControlFault::None;
}

/// The first bad field of a measured state (None if none); `bad` the joint or component.
inline ControlFault check_state(const Model& model, const ControllerState& s, double qtol,
                                int& bad) noexcept {
  if (!finite3(s.base.position, bad)) return ControlFault::BasePosition;
  if (!finite_quaternion(s.base.orientation, bad)) return ControlFault::BaseOrientation;
  if (std::abs(s.base.orientation.norm() - 1.0) > qtol) return ControlFault::BaseQuaternionNorm;
  if (s.theta.size() != model.n()) return ControlFault::JointCount;
  for (int k = 0; k < model.n(); ++k) {
    bad = k;
    if (!std::isfinite(s.theta(k))) return ControlFault::JointAngle;
    const Joint& j = model.joint(k);
    if (s.theta(k) < j.lower || s.theta(k) > j.upper) return ControlFault::JointLimit;
  }
  bad = -1;
  return ControlFault::None;
}

}  // namespace detail

// The controller runs the planner's rate law (Eq. 30-31) on the measured state instead of
// integrating it: at every tick, from the measured base pose and joint angles,
//   theta_dot = J_t^+ (x_d_dot + k_p (x_d - p_e)) + alpha qd_null,
// with the line reference x_d(t), the task solver and the null-space policy of the planner. It is
// literally the planner's joint-rate field (detail::CaptureRateField of optimize/capture.hpp), held
// with its workspace: driven by the planner's RK4 with the exact state, the controller reproduces
// plan_capture's series (tests/unit/test_controller.cpp checks it to 1e-12).
//
// Storage: everything (the model's Data, the SVD, the policy's workspace) is sized at construction;
// the controller lives behind one heap block so that it can be moved. Model must outlive it.
/// The capture controller. Policy: GradientPolicy (the paper's method)
/// or ServoPolicy (servo to a chosen capture configuration, e.g. the global plan's).
template <class Policy>
class CaptureController {
 public:
  /// The plan: prepare_capture(pb, task, opt) (its input errors, InputError naming
  /// "CaptureController") and the policy. Allocates; step() then does not. opt.rate_guard is not
  /// used (a joint-rate filter such as the clearance barrier may allocate and throw, and it models
  /// the target of the plan, not the estimates of update_target).
  CaptureController(const CaptureProblem& pb, const CaptureTask& task, const CaptureOptions& opt,
                    Policy policy, const ControllerOptions& copt = {})
      : core_(std::make_unique<Core>(pb, task, opt, std::move(policy), copt)) {}

  int joints() const noexcept { return core_->n; }
  double duration() const noexcept { return core_->opt.duration; }
  /// The current plan: capture point, normal, line reference (re-anchored by update_target).
  const CaptureSetup& setup() const noexcept { return core_->setup; }
  const CaptureProblem& problem() const noexcept { return core_->pb; }
  const Policy& policy() const noexcept { return core_->policy; }

  /// A command sized for this controller (allocates: make it once).
  ControlCommand make_command() const {
    ControlCommand c;
    c.theta_dot = Eigen::VectorXd::Zero(core_->n);
    return c;
  }

  // The tick, step(t, state, estimate, out):
  //   1. checks every input (time, base position, base quaternion, joint angles and limits, the target
  //      estimate): the first bad field gives status Fault, the field in out.fault (fault_name), the
  //      joint or component index in out.fault_index, zero joint rates and zero base velocity;
  //   2. evaluates the rate law; writes the joint rates, the base velocity that zero momentum gives
  //      with them (what the base will do), the reference and the end-effector position;
  //   3. reports Damped (the smallest task singular value is below the threshold: damped least
  //      squares, the arm is near a singularity) or RateLimited (the null-space term was scaled down,
  //      or the task alone asks more than the joint-rate limit: the task keeps priority and is not
  //      clamped), else Ok.
  // step() does not re-plan from the estimate (a propagation of the target; update_target does it at
  // the estimate's rate); it checks it, so that a diverged estimate stops the arm.
  /// One control tick. Writes `out`; never throws, never allocates.
  void step(double t, const ControllerState& state, const TargetEstimate& estimate,
            ControlCommand& out) noexcept {
    Core& c = *core_;
    if (out.theta_dot.size() != c.n) {  // cannot write the rates: report only
      fault(out, ControlFault::JointCount, -1);
      return;
    }
    int bad = -1;
    ControlFault f = ControlFault::None;
    if (!(t >= 0 && t <= c.opt.duration * (1 + 1e-12))) f = ControlFault::Time;
    if (f == ControlFault::None)
      f = detail::check_state(*c.pb.model, state, c.copt.quaternion_tolerance, bad);
    if (f == ControlFault::None) f = detail::check_estimate(estimate, c.copt.quaternion_tolerance, bad);
    if (f != ControlFault::None) {
      fault(out, f, bad);
      return;
    }
    FFSR_TRY {
      c.field(t, state.base, state.theta, out.theta_dot, out.base_velocity);
    } FFSR_CATCH(...) {
      fault(out, ControlFault::Numerical, -1);
      return;
    }
    if (!out.theta_dot.allFinite() || !out.base_velocity.allFinite()) {
      fault(out, ControlFault::Numerical, -1);
      return;
    }
    report(t, out);
  }

  // Re-planning, update_target(t, estimate): the target's state measured at t is propagated to T with
  // propagate_target (the planner's torque-free propagation), which gives the new capture point and
  // contact normal. The line reference is re-anchored: from t on, its position part is the quintic
  // polynomial that has the position, velocity and acceleration of the old reference at t and
  // reaches the new capture point at T with zero velocity and acceleration (LineReference with
  // start = t, x0, v0, a0; six conditions, one quintic). Reference position, velocity and acceleration
  // are continuous; with an unchanged capture point the reference is unchanged, so the feedback
  // k_p (x_d - p_e) keeps acting on the tracking error. (Measured in the closed loop on the 7-DOF
  // robot, exact target, estimates at 5 Hz, 100 Hz control: re-anchoring at the end-effector's
  // position left 11.3 mm at T, and a re-anchor continuous in position and velocity only 5.6 mm,
  // since each one bends the time law of the rest of the approach.) The orientation
  // reference of a pose task does not depend on the target and is left as it was. The cost is one
  // propagation of the target over T - t (closed form for an isotropic inertia, RK4 with
  // a 1 ms step otherwise), and is measured by bench/bench_controller.cpp. With
  // ControllerOptions::prediction_window > 1 the capture point (and normal) is the mean of the last
  // predictions: a simple filter of independent estimate noise.
  /// Re-plans from a new target estimate measured at t: the capture point
  /// at T from the propagated estimate, the line re-anchored at the reference's position and
  /// velocity at t. Returns the fault of a bad input (time outside
  /// [0, T), a bad estimate, a failed propagation) and then leaves the plan as it was; None on success.
  ControlFault update_target(double t, const TargetEstimate& estimate) noexcept {
    Core& c = *core_;
    const double T = c.opt.duration;
    if (!(t >= 0 && t < T)) return ControlFault::Time;
    int bad = -1;
    const ControlFault f = detail::check_estimate(estimate, c.copt.quaternion_tolerance, bad);
    if (f != ControlFault::None) return f;
    FFSR_TRY {
      Target now = c.pb.target;
      now.position = estimate.position;
      now.attitude = estimate.attitude.normalized();
      now.velocity = estimate.velocity;
      now.angular_velocity = estimate.angular_velocity;
      const Target at_T = propagate_target(now, T - t);
      Vector3 xd, vd, wd;
      Matrix3 Rd;
      c.setup.line.at(t, xd, vd, Rd, wd);
      CaptureSetup& s = c.setup;
      s.capture.target = at_T;
      c.remember(at_T.contact_point(), at_T.normal_world());
      s.capture.x_cap = c.mean_point();
      s.capture.u_cap = c.mean_normal();
      const Vector3 ad = s.line.acceleration(t);
      s.line.x0 = xd;
      s.line.v0 = vd;
      s.line.a0 = ad;
      s.line.start = t;
      s.line.x_cap = s.capture.x_cap;
    } FFSR_CATCH(...) {
      return ControlFault::Numerical;
    }
    return ControlFault::None;
  }

 private:
  struct Core {
    CaptureProblem pb;
    CaptureTask task;
    CaptureOptions opt;
    CaptureSetup setup;
    Policy policy;
    ControllerOptions copt;
    int n;
    detail::CaptureRateField<Policy> field;
    std::vector<Vector3> points, normals;  ///< the last predictions (a ring of prediction_window)
    long predictions = 0;
    void remember(const Vector3& x, const Vector3& u) {
      const auto i = static_cast<size_t>(predictions % static_cast<long>(points.size()));
      points[i] = x;
      normals[i] = u;
      ++predictions;
    }
    long kept() const { return std::min<long>(predictions, static_cast<long>(points.size())); }
    Vector3 mean_point() const {
      Vector3 m = Vector3::Zero();
      for (long i = 0; i < kept(); ++i) m += points[static_cast<size_t>(i)];
      return m / static_cast<double>(kept());
    }
    Vector3 mean_normal() const {
      Vector3 m = Vector3::Zero();
      for (long i = 0; i < kept(); ++i) m += normals[static_cast<size_t>(i)];
      return m.normalized();
    }
    Core(const CaptureProblem& pb_, const CaptureTask& task_, const CaptureOptions& opt_, Policy policy_,
         const ControllerOptions& copt_)
        : pb(pb_),
          task(task_),
          opt(without_callbacks(opt_)),
          setup(prepare_capture(pb_, task_, opt, "CaptureController")),
          policy(std::move(policy_)),
          copt(copt_),
          n(pb_.model->n()),
          field(pb, task, opt, setup, policy) {
      if (!(copt.quaternion_tolerance > 0 && copt.quaternion_tolerance < 1))
        FFSR_THROW(InputError("CaptureController: quaternion tolerance must be in (0, 1)"));
      if (copt.prediction_window < 1 || copt.prediction_window > 100000)
        FFSR_THROW(InputError(detail::str("CaptureController: prediction window must be in 1..100000, got ",
                                     copt.prediction_window)));
      points.assign(static_cast<size_t>(copt.prediction_window), Vector3::Zero());
      normals.assign(static_cast<size_t>(copt.prediction_window), Vector3::Zero());
      presize(policy, n);
    }
    static CaptureOptions without_callbacks(CaptureOptions o) {
      o.progress = nullptr;
      o.record_series = false;
      o.rate_guard = nullptr;  // a filter may allocate and throw; the clearance barrier's target is the plan's
      return o;
    }
    static void presize(GradientPolicy& p, int n) { p.grad = Eigen::VectorXd::Zero(n); }
    static void presize(ServoPolicy& p, int n) {
      if (p.theta_goal.size() != 0 && p.theta_goal.size() != n)
        FFSR_THROW(InputError(detail::str("CaptureController: the servo goal has ", p.theta_goal.size(),
                                     " joints, the robot ", n)));
      if (p.theta_goal.size() != 0 && !p.theta_goal.allFinite())
        FFSR_THROW(InputError("CaptureController: the servo goal is not finite"));
      p.err = Eigen::VectorXd::Zero(n);
    }
  };

  static void fault(ControlCommand& out, ControlFault f, int index) noexcept {
    out.theta_dot.setZero();
    out.base_velocity.setZero();
    out.status = ControlStatus::Fault;
    out.fault = f;
    out.fault_index = index;
  }

  /// The status of a tick that gave rates.
  void report(double t, ControlCommand& out) noexcept {
    Core& c = *core_;
    const TaskRates& r = c.field.solver.rates();
    out.end_effector = frame_pose(*c.pb.model, c.field.data, c.pb.frame).p;
    out.reference = c.setup.line.position(t);
    out.sigma_min = r.sigma_min;
    out.null_scale = c.policy.active() ? r.null_scale : 1.0;
    out.fault = ControlFault::None;
    out.fault_index = -1;
    const double L = c.opt.max_joint_rate;
    const bool limited =
        out.null_scale < 1 || (L > 0 && out.theta_dot.cwiseAbs().maxCoeff() > L * (1 + 1e-12));
    out.status = r.damped ? ControlStatus::Damped : limited ? ControlStatus::RateLimited : ControlStatus::Ok;
  }

  std::unique_ptr<Core> core_;
};

/// The paper's method as a controller: the gradient policy of plan_capture (gain opt.gain).
inline CaptureController<GradientPolicy> make_gradient_controller(const CaptureProblem& pb,
                                                                  const CaptureTask& task,
                                                                  const CaptureOptions& opt,
                                                                  const ControllerOptions& copt = {}) {
  const CaptureSetup setup = prepare_capture(pb, task, opt, "CaptureController");
  return CaptureController<GradientPolicy>(pb, task, opt, gradient_policy(pb, opt, setup), copt);
}

/// The servo to a chosen capture configuration theta_goal (e.g. plan_capture_global's) as a
/// controller; gain k (1/s, 0: 10 / T); opt.gain is not used (set to 0).
inline CaptureController<ServoPolicy> make_servo_controller(const CaptureProblem& pb, const CaptureTask& task,
                                                            CaptureOptions opt,
                                                            const Eigen::VectorXd& theta_goal,
                                                            double gain = 0.0,
                                                            const ControllerOptions& copt = {}) {
  opt.gain = 0.0;
  ServoPolicy servo;
  servo.theta_goal = theta_goal;
  servo.gain = gain;
  return CaptureController<ServoPolicy>(pb, task, opt, std::move(servo), copt);
}

}  // namespace ffsr
