// ffsr/control/detail/detumble_replay.hxx -- body of ffsr/control/detumble_replay.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace ffsr {

namespace detail {

/// How far the command c at the state y (base rotation R) exceeds the hardware's bounds (<= 0: within).
inline double plan_bound_excess(const DetumbleLimits& l, const DetumbleCommand& c, const Matrix3& R,
                                const Vector3& wheel_momentum, const Vector3& force, const Vector3& moment) {
  double e = -std::numeric_limits<double>::infinity();
  for (Eigen::Index k = 0; k < c.tau.size(); ++k) e = std::max(e, std::abs(c.tau(k)) - l.joint_torque(k));
  const Vector3 f = R.transpose() * c.base_wrench.head<3>(), m = R.transpose() * c.base_wrench.tail<3>();
  if (l.actuator == BaseActuator::Thrusters) {
    e = std::max(e, f.cwiseAbs().maxCoeff() - l.thruster_force);
    e = std::max(e, m.cwiseAbs().maxCoeff() - l.thruster_torque);
  } else if (l.actuator == BaseActuator::ReactionWheels) {
    e = std::max(e, m.cwiseAbs().maxCoeff() - l.wheel_torque);
    e = std::max(e, wheel_momentum.cwiseAbs().maxCoeff() - l.wheel_momentum);
  }
  if (std::isfinite(l.gripper_force)) e = std::max(e, force.norm() - l.gripper_force);
  if (std::isfinite(l.gripper_moment)) e = std::max(e, moment.norm() - l.gripper_moment);
  return e;
}

/// The re-run of a plan (replay_detumble_plan): the plan's intervals, the rest test at T, the dwell.
class PlanReplay {
 public:
  PlanReplay(const Model& stack, int gripper, const AttachedBody& body, const DetumblePlan& plan,
             const DetumbleLimits& limits, const DetumbleOptions& options, const DetumbleRunOptions& run)
      : stack_(stack), gripper_(gripper), body_(body), plan_(plan), limits_(limits), options_(options),
        run_(run), sys_(stack), probe_(stack), y_(sys_.pack(plan.nodes.front())),
        integ_([this](double, const Eigen::Ref<const Eigen::VectorXd>& yy,
                      Eigen::Ref<Eigen::VectorXd> yd) { rhs(yy, yd); },
               y_, 0.0, cvode_options(run, plan)),
        R_start_(sys_.base(y_).orientation.toRotationMatrix()) {
    cmd_.tau = Eigen::VectorXd::Zero(stack.n());
    res_.worst_bound_excess = -std::numeric_limits<double>::infinity();
    probe_.energy_momentum(y_, res_.energy_start, h0_);
  }

  DetumblePlanRun run() {
    run_plan();
    rest_test();
    if (run_.dwell > 0) dwell();
    return std::move(res_);
  }

 private:
  static cvode::Options cvode_options(const DetumbleRunOptions& run, const DetumblePlan& plan) {
    cvode::Options co;
    co.rtol = run.rtol;
    co.atol = run.atol;
    co.max_step = std::min(run.tick, plan.interval());
    return co;
  }

  void set_plan_command(const Eigen::Ref<const Eigen::VectorXd>& y) {
    plan_command(plan_, k_, Quaternion(y(6), y(3), y(4), y(5)), cmd_);
  }

  /// The plan's command turns with the base (held in its frame); the law's is held as computed.
  void rhs(const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> yd) {
    if (!dwell_) set_plan_command(y);
    sys_.rhs(y, cmd_, limits_.actuator == BaseActuator::ReactionWheels, yd);
  }

  void record(double t, const Eigen::VectorXd& y) {
    DetumbleSample s = detumble_sample(probe_, y, t, cmd_, gripper_, body_, R_start_, res_);
    const int n = stack_.n();
    forward_kinematics(stack_, probe_.data, s.base, s.theta);
    plan_rates(stack_, probe_.data, gripper_, y.segment(7 + n, 6 + n), s.command);
    const Matrix3 R = s.base.orientation.toRotationMatrix();
    res_.worst_bound_excess = std::max(
        res_.worst_bound_excess,
        plan_bound_excess(limits_, s.command, R, s.wheel_momentum, s.gripper_force, s.gripper_moment));
    if (limits_.actuator == BaseActuator::None)
      res_.momentum_drift = std::max(res_.momentum_drift, (s.momentum - h0_).norm() / std::max(h0_.norm(), 1e-300));
    res_.energy_end = s.energy;
    if (run_.record_every > 0) res_.series.push_back(std::move(s));
  }

  /// The plan's intervals, a fresh start of the integrator at each (the command jumps there); a sample
  /// every tick and at T.
  void run_plan() {
    const int N = plan_.intervals();
    const double h = plan_.interval(), tick = run_.tick;
    for (k_ = 0; k_ < N; ++k_) {
      const double t0 = k_ * h, t1 = k_ + 1 == N ? plan_.duration : (k_ + 1) * h;
      if (k_ > 0) integ_.reinit(t0, y_);
      for (; static_cast<double>(j_) * tick < t1 - 1e-12; ++j_) {
        const double ts = static_cast<double>(j_) * tick;
        if (ts > t0 + 1e-12) integ_.advance(ts);
        const Eigen::VectorXd ys = ts > t0 + 1e-12 ? integ_.y() : y_;
        set_plan_command(ys);
        record(ts, ys);
      }
      integ_.advance(t1);
      y_ = integ_.y();
      res_.steps += integ_.num_steps();
    }
    k_ = N - 1;
    set_plan_command(y_);
    record(plan_.duration, y_);
    res_.ticks = j_;
  }

  /// The rest test at T: every rate, and with stop_stack_spin the base's (its speed too with thrusters).
  void rest_test() {
    const int n = stack_.n();
    forward_kinematics(stack_, probe_.data, sys_.base(y_), y_.segment(7, n));
    DetumbleCommand c = cmd_;
    plan_rates(stack_, probe_.data, gripper_, y_.segment(7 + n, 6 + n), c);
    res_.end_joint_rate = c.joint_rate;
    res_.end_relative_rate = c.relative_rate;
    res_.end_base_rate = c.stack_rate;
    res_.end_base_speed = y_.segment<3>(7 + n).norm();
    const double thr = options_.rest_rate;
    const bool thrusters = limits_.actuator == BaseActuator::Thrusters;
    const bool base = c.stack_rate <= thr && (!thrusters || res_.end_base_speed <= thr);
    res_.at_rest = c.joint_rate <= thr && c.relative_rate <= thr && (!options_.stop_stack_spin || base);
    res_.time_to_rest = plan_.duration;
    res_.dwell_at_rest = res_.at_rest;
  }

  /// The detumbling law holding the stack from T for the dwell.
  void dwell() {
    dwell_ = true;
    const double tick = run_.tick, T = plan_.duration;
    DetumbleController ctrl(stack_, gripper_, body_, limits_, options_, tick);
    cmd_ = ctrl.make_command();
    const auto ticks = static_cast<long>(std::ceil(run_.dwell / tick - 1e-9));
    for (long m = 0; m <= ticks; ++m) {
      const double t = T + static_cast<double>(m) * tick;
      ctrl.step(sys_.unpack(y_), cmd_);
      if (cmd_.status == DetumbleStatus::Fault)
        throw NumericalError(str("replay_detumble_plan: the controller faulted (", fault_name(cmd_.fault),
                                 ") at t = ", t, " s"));
      if (m > 0) {
        record(t, y_);
        const double spin = options_.stop_stack_spin ? cmd_.stack_rate : 0.0;
        res_.dwell_peak_rate = std::max({res_.dwell_peak_rate, cmd_.joint_rate, cmd_.relative_rate, spin});
        res_.dwell_at_rest = res_.dwell_at_rest && cmd_.status == DetumbleStatus::AtRest;
      }
      if (m == ticks) break;
      integ_.reinit(t, y_);
      integ_.advance(t + tick);
      y_ = integ_.y();
      res_.steps += integ_.num_steps();
      ++res_.ticks;
    }
  }

  const Model& stack_;
  int gripper_;
  const AttachedBody& body_;
  const DetumblePlan& plan_;
  const DetumbleLimits& limits_;
  const DetumbleOptions& options_;
  const DetumbleRunOptions& run_;
  DetumbleSystem sys_, probe_;
  DetumbleCommand cmd_;
  Eigen::VectorXd y_;
  cvode::Integrator integ_;
  Matrix3 R_start_;
  DetumblePlanRun res_;
  Vector6 h0_ = Vector6::Zero();
  int k_ = 0;
  long j_ = 0;
  bool dwell_ = false;
};

}  // namespace detail

inline DetumblePlanRun replay_detumble_plan(const Model& stack, int gripper, const AttachedBody& body,
                                            const DetumblePlan& plan, const DetumbleLimits& limits,
                                            const DetumbleOptions& options, const DetumbleRunOptions& run) {
  constexpr const char* w = "replay_detumble_plan";
  detail::check_detumble_plan(stack, plan, w);
  detail::check_detumble_run(stack, gripper, body, plan.nodes.front(), run);
  detail::check_detumble(stack, limits, options, w);
  detail::PlanReplay replay(stack, gripper, body, plan, limits, options, run);
  return replay.run();
}

}  // namespace ffsr
