// ffsr/control/detumble_tracker.hpp -- the onboard controller that follows a post-capture plan (the
// time-optimal planner's, control/detumble_planner.hpp, or any DetumblePlan): one call per tick, no
// heap allocation, no exception. Each tick the plan's controls of the interval holding t (feedforward)
// plus a feedback on the rates against the plan's (cubic between its nodes) through the stack's inertia,
// within the hardware's bounds; the detumbling law (control/detumble_controller.hpp) when the state leaves the
// plan's neighbourhood (from then on), and after the plan's end (it holds the stack at rest).
#pragma once

#include "ffsr/control/detumble_controller.hpp"
#include "ffsr/control/detumble_plan.hpp"

#include "ffsr/algorithm/aba.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ffsr {

/// The plan's neighbourhood: the tracker falls back to the law (for good) when a joint rate is further
/// from the plan's than this fraction of the plan's largest joint rate (plus ten rest rates).
inline constexpr double kDetumbleTrackBand = 0.25;

/// The feedback gain on the rates as a fraction of the law's decay cap: the rate error decays at
/// gain x cap (1/s) through the stack's own inertia (see DetumblePlanTracker::track). Measured on the
/// published planar problem: a quarter rests 0.25 % after the plan, a half 0.8 %, the full cap 2.9 %
/// (the plan's torques sit on their bounds, where a larger correction is clipped on one side only).
inline constexpr double kDetumbleTrackGain = 0.25;

class DetumblePlanTracker {
 public:
  /// `plan` (caller-owned, must outlive the tracker) from the stack's state at t = 0, its intervals no
  /// shorter than the tick; the rest as DetumbleController's (the law that falls back and holds). A
  /// tick whose tracking command would take the gripper's load beyond its limits gets the law's. The feedback gain is the law's decay
  /// cap (1/s) times kDetumbleTrackGain. InputError for a bad plan
  /// and what DetumbleController refuses. Allocates; step() then does not.
  DetumblePlanTracker(const Model& stack, int gripper, const AttachedBody& body, const DetumblePlan& plan,
                      const DetumbleLimits& limits, const DetumbleOptions& options = {}, double tick = 0.01)
      : law_(stack, gripper, body, limits, options, tick), plan_(&plan), limits_(limits),
        ref_(stack.nv()), tau_law_(stack.n()), err_(stack.nv()), corr_(stack.nv()), hb_(6, stack.n()),
        hstar_(stack.n(), stack.n()) {
    detail::check_detumble_plan(stack, plan, "DetumblePlanTracker");
    for (const DetumbleState& x : plan.nodes)
      if (x.v.size() != stack.nv())
        FFSR_THROW(InputError("DetumblePlanTracker: the plan's states are not of this stack"));
    if (plan.interval() < tick * (1 - 1e-9))
      FFSR_THROW(InputError(detail::str("DetumblePlanTracker: the plan's intervals (", plan.interval(),
                                   " s) are shorter than the tick (", tick,
                                   " s): a command held over a tick cannot follow them (plan with fewer "
                                   "intervals, or tick faster)")));
    for (const DetumbleState& x : plan.nodes)
      peak_rate_ = std::max(peak_rate_, x.v.tail(stack.n()).cwiseAbs().maxCoeff());
    // each interval's accelerations at its ends under its controls (ABA), for the reference
    Data d(stack);
    DetumbleCommand c = law_.make_command();
    Eigen::VectorXd u(stack.nv()), acc(stack.nv());
    for (int k = 0; k < plan.intervals(); ++k)
      for (int end = 0; end < 2; ++end) {
        const DetumbleState& x = plan.nodes[static_cast<size_t>(k) + static_cast<size_t>(end)];
        plan_command(plan, k, x.base.orientation, c);
        u << c.base_wrench, c.tau;
        aba(stack, d, x.base, x.theta, x.v, u, acc);
        (end == 0 ? acc_start_ : acc_end_).push_back(acc);
      }
    band_ = kDetumbleTrackBand * peak_rate_ + 10 * options.rest_rate;
  }

  DetumbleCommand make_command() const { return law_.make_command(); }
  const DetumbleController& law() const noexcept { return law_; }
  /// Whether the tracker has fallen back to the law (the state left the plan's neighbourhood).
  bool fell_back() const noexcept { return fell_back_; }
  /// The largest joint-rate deviation from the plan that the tracker accepts (rad/s).
  double band() const noexcept { return band_; }

  /// One tick at time t since the plan's start. Writes `out`; never throws, never allocates.
  void step(const DetumbleState& s, double t, DetumbleCommand& out) noexcept {
    law_.step(s, out);  // the rates, the rest test and the fallback's command
    out.tracking = false;
    if (out.status == DetumbleStatus::Fault || fell_back_ || !(t >= 0) || t >= plan_->duration) return;
    reference(t);
    const int n = law_.joints();
    if ((ref_.tail(n) - s.v.tail(n)).cwiseAbs().maxCoeff() > band_) {
      fell_back_ = true;
      return;
    }
    tau_law_ = out.tau;
    wrench_law_ = out.base_wrench;
    track(s, t, out);
    if (std::isinf(limits_.gripper_force) && std::isinf(limits_.gripper_moment)) return;
    Vector3 f, m;  // the gripper's limits: a tick whose command would exceed them takes the law's
    law_.gripper_load(s, out, f, m);
    if (f.norm() <= limits_.gripper_force && m.norm() <= limits_.gripper_moment) return;
    out.tau = tau_law_;
    out.base_wrench = wrench_law_;
    out.tracking = false;
  }

 private:
  /// The plan's velocities at t: cubic Hermite between the interval's nodes with their accelerations
  /// under its controls (third order in the interval; velocities only are tracked).
  void reference(double t) noexcept {
    const double h = plan_->interval();
    const int k = plan_->interval_at(t);
    const double a = std::clamp(t / h - k, 0.0, 1.0), a2 = a * a, a3 = a2 * a;
    const auto i = static_cast<size_t>(k);
    ref_ = (2 * a3 - 3 * a2 + 1) * plan_->nodes[i].v + (-2 * a3 + 3 * a2) * plan_->nodes[i + 1].v;
    ref_ += (h * (a3 - 2 * a2 + a)) * acc_start_[i] + (h * (a3 - a2)) * acc_end_[i];
  }

  /// Feedforward plus feedback, within the bounds, so that the rate error e decays at the gain g:
  /// with thrusters the whole state's, H g e (base wrench and joint torques); otherwise the joints'
  /// with the base free under its own command, H* g e_m on the joints (H* = H_mm - H_mb H_b^-1 H_bm,
  /// the inertia the joint torques meet on the floating stack; a diagonal H_jj, the inertia with the
  /// base held, overcorrects the coupled joints of a time-optimal plan until the tracker falls back)
  /// and the wheels' moment g x the base block's rotational inertia x the angular velocity error.
  void track(const DetumbleState& s, double t, DetumbleCommand& out) noexcept {
    const int n = law_.joints(), k = plan_->interval_at(t);
    const double g = kDetumbleTrackGain * law_.decay_cap();
    const Eigen::MatrixXd& H = law_.mass_matrix();
    const auto i = static_cast<size_t>(k);
    err_ = ref_ - s.v;
    const bool thrusters = limits_.actuator == BaseActuator::Thrusters;
    if (thrusters) {  // the whole state's error decays at g: H g e
      corr_.noalias() = H * err_;
    } else {  // the joints' at g with the base free under its own command: H* g e_m
      hb_ = H.topRightCorner(6, n);
      llt_b_.compute(H.topLeftCorner<6, 6>());
      llt_b_.solveInPlace(hb_);  // H_b^-1 H_bm
      hstar_ = H.bottomRightCorner(n, n);
      hstar_.noalias() -= H.bottomLeftCorner(n, 6) * hb_;
      corr_.tail(n).noalias() = hstar_ * err_.tail(n);
      corr_.head<6>().setZero();
    }
    corr_ *= g;
    for (int j = 0; j < n; ++j)
      out.tau(j) = std::clamp(plan_->tau[i](j) + corr_(6 + j), -limits_.joint_torque(j), limits_.joint_torque(j));
    const Matrix3 R = s.base.orientation.normalized().toRotationMatrix();
    const Vector6& w = plan_->base_wrench[i];
    out.base_wrench.setZero();
    if (thrusters) {
      const Vector3 f = w.head<3>() + R.transpose() * corr_.head<3>();
      const Vector3 m = w.tail<3>() + R.transpose() * corr_.segment<3>(3);
      out.base_wrench << R * f.cwiseMax(-limits_.thruster_force).cwiseMin(limits_.thruster_force),
          R * m.cwiseMax(-limits_.thruster_torque).cwiseMin(limits_.thruster_torque);
    } else if (limits_.actuator == BaseActuator::ReactionWheels) {
      Vector3 m = w.tail<3>() + R.transpose() * (g * H.block<3, 3>(3, 3) * err_.segment<3>(3));
      m = m.cwiseMax(-limits_.wheel_torque).cwiseMin(limits_.wheel_torque);
      // the wheels store -m: keep each axis within its bound over the tick
      const Vector3 stored = R.transpose() * s.wheel_momentum, dt = Vector3::Constant(law_.tick());
      const Vector3 hi = (stored + Vector3::Constant(limits_.wheel_momentum)).cwiseQuotient(dt);
      const Vector3 lo = (stored - Vector3::Constant(limits_.wheel_momentum)).cwiseQuotient(dt);
      out.base_wrench.tail<3>() = R * m.cwiseMin(hi).cwiseMax(lo);
    }
    out.decay = 0;
    out.base_decay = 0;
    out.passive = false;
    out.brake_scale = 1;
    out.tracking = true;
    if (out.status == DetumbleStatus::Saturated) out.status = DetumbleStatus::Braking;
  }

  DetumbleController law_;
  const DetumblePlan* plan_;
  DetumbleLimits limits_;
  Eigen::VectorXd ref_, tau_law_, err_, corr_;
  Eigen::LLT<Matrix6> llt_b_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> hb_;
  Eigen::MatrixXd hstar_;
  std::vector<Eigen::VectorXd> acc_start_, acc_end_;  ///< per interval, its accelerations at its ends
  Vector6 wrench_law_ = Vector6::Zero();
  double peak_rate_ = 0, band_ = 0;
  bool fell_back_ = false;
};

}  // namespace ffsr
