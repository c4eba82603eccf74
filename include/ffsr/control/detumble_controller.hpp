// ffsr/control/detumble_controller.hpp -- the post-capture phase as an onboard controller: one call per
// control tick on the stack (robot + grasped target, model/attach.hpp), no heap allocation, no exception.
// Each tick the joint torques brake the joint rates as hard as the joint torque limits and the gripper's
// force and moment limits allow (the largest uniform decay that fits, a passive fallback when none does),
// and hold the stack at rest once there; a base actuator (reaction wheels or thrusters), where there is
// one, brakes the base's own motion as hard as its bounds allow. The law and its cost are in
// docs/detumble.md.
#pragma once

#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/algorithm/rnea.hpp"
#include "ffsr/model/attach.hpp"

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
/// test of a limit: check_detumble's, and the Detumble keys' checks (scenario/detail/detumble_keys.hpp).
inline bool detumble_bound_ok(double x) { return std::isfinite(x) && x > 0; }

/// The hardware's bounds. Per base axis: a component in the base frame.
struct DetumbleLimits {
  Eigen::VectorXd joint_torque;  ///< N m (N for a prismatic joint), one per joint, > 0
  BaseActuator actuator = BaseActuator::None;
  double wheel_torque = 0;     ///< reaction wheels: N m per base axis
  double wheel_momentum = 0;   ///< reaction wheels: N m s stored per base axis
  double thruster_force = 0;   ///< thrusters: N per base axis
  double thruster_torque = 0;  ///< thrusters: N m per base axis
  /// the gripper's load on the target: the force (N) and the moment about the contact point (N m),
  /// each bounded in norm; infinity: not limited
  double gripper_force = std::numeric_limits<double>::infinity();
  double gripper_moment = std::numeric_limits<double>::infinity();
};

/// A decay rate times the tick stays at or below this: the command is held over the tick, and a joint
/// asked to lose at most this fraction of its rate in one tick neither overshoots nor reverses.
inline constexpr double kDetumbleTickFraction = 0.5;

/// The law's settings.
struct DetumbleOptions {
  /// lambda_max (1/s): the fastest decay the joint rates are asked (qdd = -lambda qd, lambda the largest
  /// that fits the limits, at most this and kDetumbleTickFraction / tick): the law's bandwidth
  double max_decay = 20;
  /// k_max (1/s): the fastest decay of the base's momentum with the arm held the actuator is asked
  /// (the moment -k L_b, and the force -k P_b with thrusters, [P_b; L_b] = H_bb v_b; k the largest within
  /// the actuator's bounds, at most this and kDetumbleTickFraction / tick)
  double max_base_decay = 2;
  double rest_rate = 1e-3;       ///< rad/s (m/s prismatic): at rest below it
  bool stop_stack_spin = false;  ///< also stop the stack's spin (needs an actuator)
  /// true: the exact law (qdd = -lambda qd, holding against the velocity terms) with the largest lambda
  /// the limits allow, else the passive one; false: the passive law always (tau . qd <= 0)
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
  double decay = 0;        ///< lambda of the tick (1/s): the exact law's, or the passive law's times its scale
  double base_decay = 0;   ///< k of the tick (1/s): the actuator's (0 without one)
  bool passive = false;    ///< the passive law acted (no decay of the exact law fitted the limits)
  double brake_scale = 1;  ///< the passive law's scale into the limits (1: none cut)
  double joint_rate = 0;                  ///< largest |qd_k|
  double relative_rate = 0;               ///< |angular velocity of the gripper relative to the base|
  double stack_rate = 0;                  ///< |angular velocity of the base|
  DetumbleStatus status = DetumbleStatus::Braking;
  DetumbleFault fault = DetumbleFault::None;
  bool tracking = false;  ///< the plan's command acted (DetumblePlanTracker), not the law's
};

namespace detail {

/// The checks of limits and options; InputError naming the field (and `where`).
inline void check_detumble(const Model& stack, const DetumbleLimits& l, const DetumbleOptions& o,
                           const char* where) {
  auto positive = [&](double x, const char* what) {
    if (!detumble_bound_ok(x))
      FFSR_THROW(InputError(str(where, ": ", what, " must be positive and finite, got ", x)));
  };
  require_size(l.joint_torque.size(), stack.n(), where, "joint torque limits");
  for (int k = 0; k < stack.n(); ++k)
    if (!detumble_bound_ok(l.joint_torque(k)))
      FFSR_THROW(InputError(str(where, ": the torque limit of joint '", stack.joint(k).name,
                           "' must be positive and finite, got ", l.joint_torque(k))));
  if (l.actuator == BaseActuator::ReactionWheels) {
    positive(l.wheel_torque, "the reaction wheels' torque");
    positive(l.wheel_momentum, "the reaction wheels' momentum");
  } else if (l.actuator == BaseActuator::Thrusters) {
    positive(l.thruster_force, "the thrusters' force");
    positive(l.thruster_torque, "the thrusters' torque");
  }
  auto gripper = [&](double x, const char* what) {
    if (std::isnan(x) || !(x > 0))
      FFSR_THROW(InputError(str(where, ": ", what, " must be positive (infinity: not limited), got ", x)));
  };
  gripper(l.gripper_force, "the gripper's force limit");
  gripper(l.gripper_moment, "the gripper's moment limit");
  positive(o.max_decay, "the largest decay rate");
  positive(o.max_base_decay, "the largest decay rate of the stack's momentum");
  positive(o.rest_rate, "the rest rate");
  if (o.stop_stack_spin && l.actuator == BaseActuator::None)
    FFSR_THROW(InputError(str(where,
                         ": the stack's spin cannot be stopped without a base actuator: its total "
                         "angular momentum is conserved (name reaction wheels or thrusters)")));
}

/// Narrows [lo, hi] to the lambdas with |a + lambda b| <= L (lo > hi: none).
inline void fit_bound(double a, double b, double L, double& lo, double& hi) noexcept {
  if (b == 0) {
    if (std::abs(a) > L) lo = std::numeric_limits<double>::infinity();
    return;
  }
  const double r1 = (-L - a) / b, r2 = (L - a) / b;
  lo = std::max(lo, std::min(r1, r2));
  hi = std::min(hi, std::max(r1, r2));
}

/// Narrows [lo, hi] to the lambdas with |a + lambda b| <= L for 3-vectors (an infinite L: no bound).
inline void fit_norm(const Vector3& a, const Vector3& b, double L, double& lo, double& hi) noexcept {
  if (std::isinf(L)) return;
  const double bb = b.squaredNorm(), ab = a.dot(b), c = a.squaredNorm() - L * L;
  if (bb == 0) {
    if (c > 0) lo = std::numeric_limits<double>::infinity();
    return;
  }
  const double disc = ab * ab - bb * c;
  if (disc < 0) {
    lo = std::numeric_limits<double>::infinity();
    return;
  }
  const double sq = std::sqrt(disc);
  lo = std::max(lo, (-ab - sq) / bb);
  hi = std::min(hi, (-ab + sq) / bb);
}

}  // namespace detail

/// The detumbling controller on the stack model (see the top of the file and docs/detumble.md).
class DetumbleController {
 public:
  /// `stack` (the robot with `body` attached at `gripper`'s frame, attach_body) must outlive the
  /// controller; `gripper` is the frame whose body carries the target, `body` the target as attached
  /// (its load on the gripper is what the gripper limits bound), `tick` the control period (s) over
  /// which each command is held. Allocates; step() then does not. InputError for bad limits or options
  /// (detail::check_detumble), a bad frame, body or tick.
  DetumbleController(const Model& stack, int gripper, const AttachedBody& body, const DetumbleLimits& limits,
                     const DetumbleOptions& options = {}, double tick = 0.01)
      : model_(&stack),
        gripper_(gripper),
        limits_(limits),
        opt_(options),
        tick_(tick),
        data_(stack),
        c_(stack.nv()),
        vd0_(stack.nv()),
        vd1_(stack.nv()),
        vdt_(stack.nv()),
        t0_(stack.n()),
        t1_(stack.n()),
        hold_(stack.n()),
        qdd0_(stack.n()),
        qdd1_(stack.n()),
        hb_(6, stack.n()),
        hstar_(stack.n(), stack.n()),
        inv_(stack.n(), stack.n()),
        llt_m_(stack.n()),
        full_llt_(stack.nv()) {
    detail::check_detumble(stack, limits, options, "DetumbleController");
    if (!std::isfinite(tick) || !(tick > 0))
      FFSR_THROW(InputError(detail::str("DetumbleController: the tick must be positive and finite, got ", tick)));
    if (gripper < 0 || gripper >= static_cast<int>(stack.frames().size()))
      FFSR_THROW(InputError(detail::str("DetumbleController: frame index ", gripper, " out of range")));
    if (stack.nb() - 1 != stack.n()) FFSR_THROW(InputError("DetumbleController: the model has mimic joints"));
    detail::check_attached_body(body);
    const Frame& f = stack.frame(gripper);
    body_index_ = f.body;
    r_gripper_ = f.pose.p;
    const Matrix3 R = f.pose.R * body.pose.R;
    target_ = SpatialInertia::from_com(body.mass, f.pose.p + f.pose.R * body.pose.p,
                                       R * body.inertia * R.transpose());
    decay_cap_ = std::min(opt_.max_decay, kDetumbleTickFraction / tick_);
    base_cap_ = std::min(opt_.max_base_decay, kDetumbleTickFraction / tick_);
  }

  int joints() const noexcept { return model_->n(); }
  const DetumbleLimits& limits() const noexcept { return limits_; }
  const DetumbleOptions& options() const noexcept { return opt_; }
  double tick() const noexcept { return tick_; }
  /// The largest decay rate the law asks of the joint rates: max_decay, at most
  /// kDetumbleTickFraction / tick.
  double decay_cap() const noexcept { return decay_cap_; }

  /// The stack's mass matrix H (6 + n) at the last step's state (CRBA; valid after a step without fault).
  const Eigen::MatrixXd& mass_matrix() const noexcept { return data_.H; }

  /// The gripper's load under the command c at the state s of the last step (its H and velocity terms):
  /// the accelerations of H vd = [base wrench; tau] - C, then the attached body's Newton-Euler equation;
  /// the force on the target (N) and the moment about the contact point (N m). Never allocates.
  void gripper_load(const DetumbleState& s, const DetumbleCommand& c, Vector3& force, Vector3& moment) noexcept {
    const int n = model_->n();
    full_llt_.compute(data_.H);
    vdt_.head<6>() = c.base_wrench - c_.head<6>();
    vdt_.tail(n) = c.tau - c_.tail(n);
    full_llt_.solveInPlace(vdt_);
    const auto e = static_cast<size_t>(body_index_);
    rnea(*model_, data_, s.base, s.theta, s.v, vdt_);
    const Vector6 A = data_.A[e], V = data_.V[e];
    const Vector6 w = target_ * A + cross_force(V, target_ * V);
    force = w.head<3>();
    moment = w.tail<3>() - r_gripper_.cross(force);
  }

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
    FFSR_TRY {
      crba(*model_, data_, s.base, s.theta);
      base_wrench(s, out);
      const bool saturated = joint_torques(s, out);
      rates(s, saturated, out);
    } FFSR_CATCH(...) {
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
    out.decay = 0;
    out.base_decay = 0;
    out.passive = false;
    out.status = DetumbleStatus::Fault;
    out.fault = f;
  }

  /// The largest k <= base_cap_ with |k x_i| <= L on every base axis i (x in the base frame).
  double base_fit(const Vector3& x, double L) const {
    double k = base_cap_;
    for (int i = 0; i < 3; ++i)
      if (std::abs(x(i)) * k > L) k = L / std::abs(x(i));
    return k;
  }

  /// The actuator's wrench that brakes the base's own motion: from the base's momentum with the arm
  /// held, [P_b; L_b] = H_bb v_b (H_bb the stack's composite inertia about the base origin, v_b the
  /// base's twist; inertial axes), the moment -k L_b, and for thrusters the force -k_f P_b, with the
  /// largest k (k_f) up to base_cap_ that keeps every base-axis component within the actuator's bound
  /// (the direction kept); a wheel's torque is cut so that its stored momentum stays within its bound
  /// over the tick. Braking the base rather than the stack's centroidal momentum keeps the actuator at
  /// work while the arm's motion spins the base (the momentum goes out as the whole stack stops).
  /// Reads data_.H. Writes out.base_wrench, out.base_decay.
  void base_wrench(const DetumbleState& s, DetumbleCommand& out) const {
    out.base_wrench.setZero();
    out.base_decay = 0;
    if (!opt_.stop_stack_spin || limits_.actuator == BaseActuator::None) return;
    const Vector6 pb = data_.H.topLeftCorner<6, 6>() * s.v.head<6>();
    const Matrix3 R = s.base.orientation.normalized().toRotationMatrix();
    const Vector3 Lb = R.transpose() * pb.tail<3>();
    if (limits_.actuator == BaseActuator::Thrusters) {
      const Vector3 Pb = R.transpose() * pb.head<3>();
      out.base_wrench.head<3>() = R * (-base_fit(Pb, limits_.thruster_force) * Pb);
      out.base_decay = base_fit(Lb, limits_.thruster_torque);
      out.base_wrench.tail<3>() = R * (-out.base_decay * Lb);
      return;
    }
    out.base_decay = base_fit(Lb, limits_.wheel_torque);
    Vector3 tb = -out.base_decay * Lb;
    const Vector3 hw = R.transpose() * s.wheel_momentum;  // the wheels take -torque: dh_w/dt = -t
    for (int i = 0; i < 3; ++i)
      if (hw(i) * tb(i) < 0)  // the stored momentum grows on this axis: at most up to the bound
        tb(i) = std::copysign(std::min(std::abs(tb(i)), std::max(0.0, limits_.wheel_momentum - std::abs(hw(i))) / tick_),
                              tb(i));
    out.base_wrench.tail<3>() = R * tb;
  }

  /// Narrows [lo, hi] to the parameters x for which the gripper's load at the accelerations
  /// a0 + x a1 stays within its limits (two RNEA passes: the load is affine in the accelerations).
  /// Writes data_ (rnea), vdt_.
  void gripper_fit(const DetumbleState& s, const Eigen::VectorXd& a0, const Eigen::VectorXd& a1, double& lo,
                   double& hi) {
    if (std::isinf(limits_.gripper_force) && std::isinf(limits_.gripper_moment)) return;
    const auto e = static_cast<size_t>(body_index_);
    rnea(*model_, data_, s.base, s.theta, s.v, a0);
    const Vector6 A0 = data_.A[e], V = data_.V[e];
    const Vector6 w0 = target_ * A0 + cross_force(V, target_ * V);
    vdt_ = a0 + a1;
    rnea(*model_, data_, s.base, s.theta, s.v, vdt_);
    const Vector6 w1 = target_ * Vector6(data_.A[e] - A0);
    const Vector3 f0 = w0.head<3>(), f1 = w1.head<3>();
    detail::fit_norm(f0, f1, limits_.gripper_force, lo, hi);
    detail::fit_norm(w0.tail<3>() - r_gripper_.cross(f0), w1.tail<3>() - r_gripper_.cross(f1),
                     limits_.gripper_moment, lo, hi);
  }

  /// The joint torques. The exact law: on the floating stack with the base wrench w_b, the
  /// accelerations that give qdd = -lambda qd are vd0 + lambda vd1,
  ///   vd0 = [H_b^-1 (w_b - C_b); 0],  vd1 = [H_b^-1 H_bm qd; -qd]   (C = bias_forces),
  /// and the torques tau(lambda) = t0 + lambda t1 (t0 = H_m vd0 + C_m holds the arm against the
  /// velocity terms, t1 = -H* qd brakes, H* = H_mm - H_mb H_b^-1 H_bm): affine in lambda, as the
  /// gripper's load is. lambda is the largest in [0, decay_cap_] with every joint torque and the
  /// gripper's force and moment within their limits (an intersection of intervals). When no lambda
  /// fits (and always with hold = false) the passive law tau_k = -s lambda_p H*_kk qd_k with
  /// lambda_p = min(max_decay, kDetumbleTickFraction / (tick rho)), rho Gershgorin's bound on the largest eigenvalue of
  /// D^1/2 H*^-1 D^1/2, D = diag(H*) (1 for uncoupled joints: the held torque's second-order work over
  /// a tick stays below half its first-order one), and the
  /// largest s <= 1 that keeps every joint and, where it can, the gripper within the limits:
  /// tau . qd <= 0. Returns whether a limit bound the law or the passive law acted.
  bool joint_torques(const DetumbleState& s, DetumbleCommand& out) {
    const int n = model_->n();
    const Eigen::MatrixXd& H = data_.H;
    llt_.compute(H.topLeftCorner<6, 6>());
    c_ = bias_forces(*model_, data_, s.base, s.theta, s.v);
    const auto qd = s.v.tail(n);
    const auto Hbm = H.topRightCorner(6, n);
    const auto Hm = H.bottomRows(n);
    vd0_.head<6>() = llt_.solve(Vector6(out.base_wrench - c_.head<6>()));
    vd0_.tail(n).setZero();
    b6_.noalias() = Hbm * qd;
    vd1_.head<6>() = llt_.solve(b6_);
    vd1_.tail(n) = -qd;
    t0_.noalias() = Hm * vd0_;
    t0_ += c_.tail(n);
    t1_.noalias() = Hm * vd1_;
    out.brake_scale = 1.0;
    out.passive = false;
    if (opt_.hold) {
      double lo = 0, hi = decay_cap_;
      for (int k = 0; k < n && lo <= hi; ++k) detail::fit_bound(t0_(k), t1_(k), limits_.joint_torque(k), lo, hi);
      if (lo <= hi) gripper_fit(s, vd0_, vd1_, lo, hi);
      if (lo <= hi) {
        out.decay = hi;
        out.tau = t0_ + hi * t1_;
        return hi < decay_cap_;
      }
    }
    passive(s, out);
    return true;
  }

  /// The passive law of joint_torques. Writes hb_, hstar_, inv_, hold_, qdd0_, qdd1_, vd0_, vd1_.
  void passive(const DetumbleState& s, DetumbleCommand& out) {
    const int n = model_->n();
    const Eigen::MatrixXd& H = data_.H;
    const auto qd = s.v.tail(n);
    hb_ = H.topRightCorner(6, n);
    llt_.solveInPlace(hb_);  // H_b^-1 H_bm
    hstar_ = H.bottomRightCorner(n, n);
    hstar_.noalias() -= H.bottomLeftCorner(n, 6) * hb_;
    llt_m_.compute(hstar_);
    inv_.setIdentity();
    llt_m_.solveInPlace(inv_);
    double rho = 0;  // Gershgorin: the largest row sum of |D^1/2 H*^-1 D^1/2|, D = diag(H*)
    for (int i = 0; i < n; ++i) {
      double row = 0;
      for (int j = 0; j < n; ++j) row += std::sqrt(hstar_(i, i) * hstar_(j, j)) * std::abs(inv_(i, j));
      rho = std::max(rho, row);
    }
    const double lambda = std::min(opt_.max_decay, kDetumbleTickFraction / (tick_ * std::max(rho, 1.0)));
    double scale = 1.0;
    for (int k = 0; k < n; ++k) {
      hold_(k) = -lambda * hstar_(k, k) * qd(k);
      if (std::abs(hold_(k)) > limits_.joint_torque(k))
        scale = std::min(scale, limits_.joint_torque(k) / std::abs(hold_(k)));
    }
    // the gripper: the accelerations under s hold_ are vd0 + s vd1 with qdd(s) = H*^-1 (s hold_ - t0)
    double lo = 0, hi = scale;
    qdd0_.noalias() = -inv_ * t0_;
    qdd1_.noalias() = inv_ * hold_;
    vd1_.head<6>().noalias() = -hb_ * qdd1_;
    vd1_.tail(n) = qdd1_;
    vd0_.head<6>().noalias() -= hb_ * qdd0_;
    vd0_.tail(n) = qdd0_;
    gripper_fit(s, vd0_, vd1_, lo, hi);
    if (lo <= hi) scale = hi;  // else no scale keeps the gripper's load within its limits
    out.tau = scale * hold_;
    out.brake_scale = scale;
    out.decay = scale * lambda;
    out.passive = true;
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
  double tick_;
  double decay_cap_ = 0, base_cap_ = 0;
  int body_index_ = 0;
  Vector3 r_gripper_ = Vector3::Zero();  ///< the gripper frame's origin in its body
  SpatialInertia target_;                ///< the attached body, about its body's origin, body axes
  Data data_;
  Eigen::LLT<Matrix6> llt_;
  Eigen::VectorXd c_, vd0_, vd1_, vdt_, t0_, t1_, hold_, qdd0_, qdd1_;
  Vector6 b6_ = Vector6::Zero();
  Eigen::Matrix<double, 6, Eigen::Dynamic> hb_;
  Eigen::MatrixXd hstar_, inv_;
  Eigen::LLT<Eigen::MatrixXd> llt_m_;
  Eigen::LLT<Eigen::MatrixXd> full_llt_;  ///< of H, for gripper_load
};

}  // namespace ffsr
