// ffsr/control/detumble_controller.hpp -- the post-capture phase as an onboard controller: one call per
// control tick on the stack (robot + grasped target, model/attach.hpp), no heap allocation, no exception.
// Joint torques brake the joint rates within per-joint limits; a base actuator (reaction wheels or
// thrusters), where there is one, removes the stack's momentum within its bounds. The law and its cost
// are in docs/detumble.md.
#pragma once

#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/algorithm/rnea.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

namespace ffsr {

/// What acts on the base beside the arm.
enum class BaseActuator {
  None,            ///< free-floating: the stack keeps its momentum
  ReactionWheels,  ///< a torque on the base per base axis, bounded, whose momentum the wheels store (bounded)
  Thrusters,       ///< a force and a torque on the base per base axis, bounded
};

/// Each actuator and its name: the one spelling of the names, read by the key base-actuator (its check
/// and its parsing, scenario/), the JSON's base_actuator, Python's `actuator` and the docs' key table.
inline constexpr std::array<std::pair<BaseActuator, const char*>, 3> kBaseActuators{
    {{BaseActuator::None, "none"},
     {BaseActuator::ReactionWheels, "reaction-wheels"},
     {BaseActuator::Thrusters, "thrusters"}}};

inline const char* actuator_name(BaseActuator a) {
  for (const auto& [x, name] : kBaseActuators)
    if (x == a) return name;
  return "?";
}

/// The actuator named `name` (kBaseActuators), or none.
inline std::optional<BaseActuator> find_base_actuator(const std::string& name) {
  for (const auto& [x, n] : kBaseActuators)
    if (name == n) return x;
  return std::nullopt;
}

/// The names joined by ", ", the last by `last` ("none, reaction-wheels or thrusters").
inline std::string base_actuator_names(const char* last = " or ") {
  std::string out;
  for (size_t i = 0; i < kBaseActuators.size(); ++i)
    out += std::string(i == 0 ? "" : i + 1 == kBaseActuators.size() ? last : ", ") + kBaseActuators[i].second;
  return out;
}

/// Whether `x` can be a bound of the hardware or a setting of the law: positive and finite. The one
/// test of a limit: check_detumble's, and the Detumble keys' checks (scenario/detail/keys.hpp).
inline bool detumble_bound_ok(double x) { return std::isfinite(x) && x > 0; }

/// The hardware's bounds. Per base axis: a component in the base frame.
struct DetumbleLimits {
  Eigen::VectorXd joint_torque;  ///< N m (N for a prismatic joint), one per joint, > 0
  BaseActuator actuator = BaseActuator::None;
  double wheel_torque = 0;     ///< reaction wheels: N m per base axis
  double wheel_momentum = 0;   ///< reaction wheels: N m s stored per base axis
  double thruster_force = 0;   ///< thrusters: N per base axis
  double thruster_torque = 0;  ///< thrusters: N m per base axis
};

/// The law's settings.
struct DetumbleOptions {
  double joint_gain = 1.0;       ///< lambda (1/s): the joint rates asked to decay as qdd = -lambda qd
  double base_gain = 0.1;        ///< k (1/s): the actuator asks dL/dt = -k L (and dP/dt = -k P, thrusters)
  double rest_rate = 1e-3;       ///< rad/s (m/s prismatic): at rest below it
  bool stop_stack_spin = false;  ///< also stop the stack's spin (needs an actuator)
  /// true: the exact law (qdd = -lambda qd, holding against the velocity terms) where the limits allow
  /// it, else the passive one; false: the passive law always (tau . qd <= 0)
  bool hold = true;
};

/// The measured state of the stack at a tick: base pose, joint angles, generalized velocity
/// (model.hpp), and the momentum the wheels store (inertial frame; zero without wheels).
struct DetumbleState {
  BasePose base;
  Eigen::VectorXd theta, v;
  Vector3 wheel_momentum = Vector3::Zero();
};

enum class DetumbleStatus { Braking, Saturated, AtRest, Fault };

inline const char* status_name(DetumbleStatus s) {
  switch (s) {
    case DetumbleStatus::Braking:
      return "braking";
    case DetumbleStatus::Saturated:
      return "saturated";
    case DetumbleStatus::AtRest:
      return "at-rest";
    case DetumbleStatus::Fault:
      return "fault";
  }
  return "?";
}

/// The input field a fault names.
enum class DetumbleFault {
  None,
  Size,
  BasePosition,
  BaseOrientation,
  JointAngle,
  Velocity,
  WheelMomentum,
  Numerical
};

inline const char* fault_name(DetumbleFault f) {
  switch (f) {
    case DetumbleFault::None:
      return "none";
    case DetumbleFault::Size:
      return "size";
    case DetumbleFault::BasePosition:
      return "base position";
    case DetumbleFault::BaseOrientation:
      return "base orientation";
    case DetumbleFault::JointAngle:
      return "joint angle";
    case DetumbleFault::Velocity:
      return "velocity";
    case DetumbleFault::WheelMomentum:
      return "wheel momentum";
    case DetumbleFault::Numerical:
      return "numerical";
  }
  return "?";
}

/// What a tick writes (caller-owned; make it with DetumbleController::make_command()).
struct DetumbleCommand {
  Eigen::VectorXd tau;                    ///< joint torques (zero on a fault)
  Vector6 base_wrench = Vector6::Zero();  ///< force and moment on the base about its origin, inertial
  double brake_scale = 1;                 ///< the passive law's scale into the limits (1: none cut)
  double joint_rate = 0;                  ///< largest |qd_k|
  double relative_rate = 0;               ///< |angular velocity of the gripper relative to the base|
  double stack_rate = 0;                  ///< |angular velocity of the base|
  DetumbleStatus status = DetumbleStatus::Braking;
  DetumbleFault fault = DetumbleFault::None;
};

namespace detail {

/// The checks of limits and options; InputError naming the field (and `where`).
inline void check_detumble(const Model& stack, const DetumbleLimits& l, const DetumbleOptions& o,
                           const char* where) {
  auto positive = [&](double x, const char* what) {
    if (!detumble_bound_ok(x))
      throw InputError(str(where, ": ", what, " must be positive and finite, got ", x));
  };
  require_size(l.joint_torque.size(), stack.n(), where, "joint torque limits");
  for (int k = 0; k < stack.n(); ++k)
    if (!detumble_bound_ok(l.joint_torque(k)))
      throw InputError(str(where, ": the torque limit of joint '", stack.joint(k).name,
                           "' must be positive and finite, got ", l.joint_torque(k)));
  if (l.actuator == BaseActuator::ReactionWheels) {
    positive(l.wheel_torque, "the reaction wheels' torque");
    positive(l.wheel_momentum, "the reaction wheels' momentum");
  } else if (l.actuator == BaseActuator::Thrusters) {
    positive(l.thruster_force, "the thrusters' force");
    positive(l.thruster_torque, "the thrusters' torque");
  }
  positive(o.joint_gain, "the joint gain");
  positive(o.base_gain, "the base gain");
  positive(o.rest_rate, "the rest rate");
  if (o.stop_stack_spin && l.actuator == BaseActuator::None)
    throw InputError(str(where,
                         ": the stack's spin cannot be stopped without a base actuator: its total "
                         "angular momentum is conserved (name reaction wheels or thrusters)"));
}

/// x clamped to [-L, L] per base axis: the components of x in the base frame (R) clamped, rotated back.
inline Vector3 clamp_in_base(const Matrix3& R, const Vector3& x, double L) {
  const Vector3 b = (R.transpose() * x).cwiseMax(-L).cwiseMin(L);
  return R * b;
}

}  // namespace detail

/// The detumbling controller on the stack model (see the top of the file and docs/detumble.md).
class DetumbleController {
 public:
  /// `stack` (the robot with the target attached, attach_body) must outlive the controller;
  /// `gripper` is the frame whose body carries the target. Allocates; step() then does not.
  /// InputError for bad limits or options (detail::check_detumble) or a bad frame.
  DetumbleController(const Model& stack, int gripper, const DetumbleLimits& limits,
                     const DetumbleOptions& options = {})
      : model_(&stack),
        gripper_(gripper),
        limits_(limits),
        opt_(options),
        data_(stack),
        qdd_(stack.n()),
        hold_(stack.n()) {
    detail::check_detumble(stack, limits, options, "DetumbleController");
    if (gripper < 0 || gripper >= static_cast<int>(stack.frames().size()))
      throw InputError(detail::str("DetumbleController: frame index ", gripper, " out of range"));
    if (stack.nb() - 1 != stack.n()) throw InputError("DetumbleController: the model has mimic joints");
  }

  int joints() const noexcept { return model_->n(); }
  const DetumbleLimits& limits() const noexcept { return limits_; }
  const DetumbleOptions& options() const noexcept { return opt_; }

  /// A command sized for this controller (allocates: make it once).
  DetumbleCommand make_command() const {
    DetumbleCommand c;
    c.tau = Eigen::VectorXd::Zero(model_->n());
    return c;
  }

  /// One control tick. Writes `out`; never throws, never allocates.
  void step(const DetumbleState& s, DetumbleCommand& out) noexcept {
    const DetumbleFault f = check(s, out);
    if (f != DetumbleFault::None) return fault(out, f);
    try {
      crba(*model_, data_, s.base, s.theta);
      base_wrench(s, out);
      const bool saturated = joint_torques(s, out);
      rates(s, saturated, out);
    } catch (...) {
      return fault(out, DetumbleFault::Numerical);
    }
    if (!out.tau.allFinite() || !out.base_wrench.allFinite()) return fault(out, DetumbleFault::Numerical);
  }

 private:
  DetumbleFault check(const DetumbleState& s, const DetumbleCommand& out) const noexcept {
    const int n = model_->n();
    if (out.tau.size() != n || s.theta.size() != n || s.v.size() != n + 6) return DetumbleFault::Size;
    if (!s.base.position.allFinite()) return DetumbleFault::BasePosition;
    if (!s.base.orientation.coeffs().allFinite() || std::abs(s.base.orientation.norm() - 1.0) > 1e-3)
      return DetumbleFault::BaseOrientation;
    if (!s.theta.allFinite()) return DetumbleFault::JointAngle;
    if (!s.v.allFinite()) return DetumbleFault::Velocity;
    if (!s.wheel_momentum.allFinite()) return DetumbleFault::WheelMomentum;
    return DetumbleFault::None;
  }

  static void fault(DetumbleCommand& out, DetumbleFault f) noexcept {
    out.tau.setZero();
    out.base_wrench.setZero();
    out.status = DetumbleStatus::Fault;
    out.fault = f;
  }

  /// The actuator's wrench from the stack's centroidal momentum (centroidal_momentum, from the base rows
  /// of H): the moment -k L_c, L_c the angular momentum about the stack's centre of mass, and for
  /// thrusters the force -k P; each clamped per base axis, a wheel torque cut on an axis whose stored
  /// momentum is at its bound and would grow. Reads data_.H. Writes out.base_wrench.
  void base_wrench(const DetumbleState& s, DetumbleCommand& out) const {
    out.base_wrench.setZero();
    if (!opt_.stop_stack_spin || limits_.actuator == BaseActuator::None) return;
    const CentroidalMomentum h = centroidal_momentum(*model_, data_, s.v);
    const Vector3& Lc = h.angular;
    const Matrix3 R = s.base.orientation.normalized().toRotationMatrix();
    const double k = opt_.base_gain;
    if (limits_.actuator == BaseActuator::Thrusters) {
      out.base_wrench.head<3>() = detail::clamp_in_base(R, -k * h.linear, limits_.thruster_force);
      out.base_wrench.tail<3>() = detail::clamp_in_base(R, -k * Lc, limits_.thruster_torque);
      return;
    }
    Vector3 tb = (R.transpose() * (-k * Lc)).cwiseMax(-limits_.wheel_torque).cwiseMin(limits_.wheel_torque);
    const Vector3 hw = R.transpose() * s.wheel_momentum;  // the wheels take -torque: dh_w/dt = -t
    for (int i = 0; i < 3; ++i)
      if (std::abs(hw(i)) >= limits_.wheel_momentum && hw(i) * tb(i) < 0) tb(i) = 0;
    out.base_wrench.tail<3>() = R * tb;
  }

  /// The joint torques. The exact law: the torques that give qdd = -lambda qd on the floating stack
  /// with the base wrench w_b (C = bias_forces):
  ///   a_b = H_b^-1 (w_b - C_b - H_bm qdd),  tau = H_mb a_b + H_mm qdd + C_m,
  /// used when every joint stays within its limit. Otherwise (and always with hold = false) the passive
  /// law tau_k = -s lambda H*_kk qd_k, H*_kk = H_kk - H_kb H_b^-1 H_bk the joint's inertia on the
  /// floating stack, with the largest s <= 1 that keeps every joint within its limit: tau . qd <= 0, so
  /// the joints only take energy out. Reads data_.H (crba). Writes data_.tau (bias_forces), qdd_,
  /// hold_, out.tau, out.brake_scale; returns whether the passive law was used because of the limits.
  bool joint_torques(const DetumbleState& s, DetumbleCommand& out) {
    const int n = model_->n();
    const Eigen::MatrixXd& H = data_.H;
    llt_.compute(H.topLeftCorner<6, 6>());
    const auto qd = s.v.tail(n);
    out.brake_scale = 1.0;
    if (opt_.hold) {
      const Eigen::VectorXd& C = bias_forces(*model_, data_, s.base, s.theta, s.v);
      qdd_ = -opt_.joint_gain * qd;
      Vector6 rhs = out.base_wrench - C.head<6>();
      for (int r = 0; r < 6; ++r) rhs(r) -= H.row(r).tail(n).dot(qdd_);
      const Vector6 ab = llt_.solve(rhs);
      bool within = true;
      for (int k = 0; k < n; ++k) {
        hold_(k) = H.row(6 + k).head<6>().dot(ab) + H.row(6 + k).tail(n).dot(qdd_) + C(6 + k);
        within = within && std::abs(hold_(k)) <= limits_.joint_torque(k);
      }
      if (within) {
        out.tau = hold_;
        return false;
      }
    }
    double scale = 1.0;
    for (int k = 0; k < n; ++k) {
      const Vector6 Hbk = H.col(6 + k).head<6>();
      const double Hkk = H(6 + k, 6 + k) - Hbk.dot(llt_.solve(Hbk));
      hold_(k) = -opt_.joint_gain * Hkk * qd(k);
      if (std::abs(hold_(k)) > limits_.joint_torque(k))
        scale = std::min(scale, limits_.joint_torque(k) / std::abs(hold_(k)));
    }
    out.tau = scale * hold_;
    out.brake_scale = scale;
    return opt_.hold || scale < 1.0;
  }

  /// The rates that decide rest: joints, the gripper relative to the base, the base. Writes data_.J.
  void rates(const DetumbleState& s, bool saturated, DetumbleCommand& out) {
    const int n = model_->n();
    frame_jacobian(*model_, data_, gripper_);
    out.joint_rate = s.v.tail(n).cwiseAbs().maxCoeff();
    Vector3 wrel = Vector3::Zero();
    for (int r = 0; r < 3; ++r) wrel(r) = data_.J.row(3 + r).tail(n).dot(s.v.tail(n));
    out.relative_rate = wrel.norm();
    out.stack_rate = s.v.segment<3>(3).norm();
    const double thr = opt_.rest_rate;
    const bool rest =
        out.joint_rate < thr && out.relative_rate < thr && (!opt_.stop_stack_spin || out.stack_rate < thr);
    out.fault = DetumbleFault::None;
    out.status = rest        ? DetumbleStatus::AtRest
                 : saturated ? DetumbleStatus::Saturated
                             : DetumbleStatus::Braking;
  }

  const Model* model_;
  int gripper_;
  DetumbleLimits limits_;
  DetumbleOptions opt_;
  Data data_;
  Eigen::LLT<Matrix6> llt_;
  Eigen::VectorXd qdd_, hold_;
};

}  // namespace ffsr
