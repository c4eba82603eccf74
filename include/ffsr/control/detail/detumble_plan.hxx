// ffsr/control/detail/detumble_plan.hxx -- body of ffsr/control/detumble_plan.hpp.
#pragma once

#include <algorithm>
#include <cmath>

namespace ffsr {

namespace detail {

inline void check_detumble_plan(const Model& stack, const DetumblePlan& plan, const char* w) {
  const int N = plan.intervals();
  if (N < 1) throw InputError(str(w, ": the plan has no interval"));
  if (!std::isfinite(plan.duration) || !(plan.duration > 0))
    throw InputError(str(w, ": the plan's duration must be positive and finite, got ", plan.duration));
  if (plan.nodes.size() != static_cast<size_t>(N) + 1 || plan.base_wrench.size() != static_cast<size_t>(N))
    throw InputError(str(w, ": the plan needs N + 1 nodes and N base wrenches for its N = ", N,
                         " intervals, got ", plan.nodes.size(), " and ", plan.base_wrench.size()));
  for (int k = 0; k < N; ++k) {
    require_size(plan.tau[static_cast<size_t>(k)].size(), stack.n(), w, "the plan's joint torques");
    require_finite_all(plan.tau[static_cast<size_t>(k)], w, "the plan's joint torques");
    require_finite_all(plan.base_wrench[static_cast<size_t>(k)], w, "the plan's base wrench");
  }
}

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

}  // namespace detail

inline DetumblePlanRun replay_detumble_plan(const Model& stack, int gripper, const AttachedBody& body,
                                            const DetumblePlan& plan, const DetumbleLimits& limits,
                                            const DetumbleOptions& options, const DetumbleRunOptions& run) {
  constexpr const char* w = "replay_detumble_plan";
  detail::check_detumble_plan(stack, plan, w);
  detail::check_detumble_run(stack, gripper, body, plan.nodes.front(), run);
  detail::check_detumble(stack, limits, options, w);
  const bool wheels = limits.actuator == BaseActuator::ReactionWheels;
  const int n = stack.n(), N = plan.intervals();
  const double h = plan.interval(), T = plan.duration;
  detail::DetumbleSystem sys(stack), probe(stack);
  DetumbleCommand cmd;
  cmd.tau = Eigen::VectorXd::Zero(n);
  int k_now = 0;
  bool dwell = false;
  cvode::Options co;
  co.rtol = run.rtol;
  co.atol = run.atol;
  co.max_step = std::min(run.tick, h);
  Eigen::VectorXd y = sys.pack(plan.nodes.front());
  const auto set_plan_command = [&](const Eigen::Ref<const Eigen::VectorXd>& yy) {
    plan_command(plan, k_now, Quaternion(yy(6), yy(3), yy(4), yy(5)), cmd);
  };
  cvode::Integrator integ(
      [&](double, const Eigen::Ref<const Eigen::VectorXd>& yy, Eigen::Ref<Eigen::VectorXd> yd) {
        if (!dwell) set_plan_command(yy);  // held in the base frame: it turns with the base
        sys.rhs(yy, cmd, wheels, yd);
      },
      y, 0.0, co);
  const Matrix3 R_start = sys.base(y).orientation.toRotationMatrix();
  DetumblePlanRun res;
  res.worst_bound_excess = -std::numeric_limits<double>::infinity();
  Vector6 h0;
  probe.energy_momentum(y, res.energy_start, h0);
  const bool closed = limits.actuator == BaseActuator::None;
  const auto record = [&](double t, const Eigen::VectorXd& yy) {
    DetumbleSample s = detail::detumble_sample(probe, yy, t, cmd, gripper, body, R_start, res);
    forward_kinematics(stack, probe.data, s.base, s.theta);
    detail::plan_rates(stack, probe.data, gripper, yy.segment(7 + n, 6 + n), s.command);
    const Matrix3 R = s.base.orientation.toRotationMatrix();
    res.worst_bound_excess = std::max(res.worst_bound_excess,
                                      detail::plan_bound_excess(limits, s.command, R, s.wheel_momentum,
                                                                s.gripper_force, s.gripper_moment));
    if (closed)
      res.momentum_drift = std::max(res.momentum_drift, (s.momentum - h0).norm() / std::max(h0.norm(), 1e-300));
    res.energy_end = s.energy;
    if (run.record_every > 0) res.series.push_back(std::move(s));
  };
  // the plan: interval by interval, a fresh start of the integrator at each (the command jumps there)
  const double tick = run.tick;
  long j = 0;  // the next sample's tick
  for (k_now = 0; k_now < N; ++k_now) {
    const double t0 = k_now * h, t1 = k_now + 1 == N ? T : (k_now + 1) * h;
    if (k_now > 0) integ.reinit(t0, y);
    set_plan_command(y);
    for (; static_cast<double>(j) * tick < t1 - 1e-12; ++j) {
      const double ts = static_cast<double>(j) * tick;
      if (ts > t0 + 1e-12) integ.advance(ts);
      const Eigen::VectorXd ys = ts > t0 + 1e-12 ? integ.y() : y;
      set_plan_command(ys);
      record(ts, ys);
    }
    integ.advance(t1);
    y = integ.y();
    res.steps += integ.num_steps();
  }
  k_now = N - 1;
  set_plan_command(y);
  record(T, y);
  // the rest test at T
  {
    forward_kinematics(stack, probe.data, sys.base(y), y.segment(7, n));
    DetumbleCommand c = cmd;
    detail::plan_rates(stack, probe.data, gripper, y.segment(7 + n, 6 + n), c);
    res.end_joint_rate = c.joint_rate;
    res.end_relative_rate = c.relative_rate;
    res.end_base_rate = c.stack_rate;
    res.end_base_speed = y.segment<3>(7 + n).norm();
    const double thr = options.rest_rate;
    const bool thrusters = limits.actuator == BaseActuator::Thrusters;
    res.at_rest = c.joint_rate <= thr && c.relative_rate <= thr &&
                  (!options.stop_stack_spin || (c.stack_rate <= thr && (!thrusters || res.end_base_speed <= thr)));
    res.time_to_rest = T;
  }
  res.ticks = j;
  // the dwell: the detumbling controller holds the stack
  res.dwell_at_rest = res.at_rest;
  if (run.dwell > 0) {
    dwell = true;
    DetumbleController ctrl(stack, gripper, body, limits, options, tick);
    cmd = ctrl.make_command();
    const auto ticks = static_cast<long>(std::ceil(run.dwell / tick - 1e-9));
    for (long m = 0; m <= ticks; ++m) {
      const double t = T + static_cast<double>(m) * tick;
      ctrl.step(sys.unpack(y), cmd);
      if (cmd.status == DetumbleStatus::Fault)
        throw NumericalError(detail::str(w, ": the controller faulted (", fault_name(cmd.fault), ") at t = ", t, " s"));
      if (m > 0) {
        record(t, y);
        const double rate =
            std::max({cmd.joint_rate, cmd.relative_rate, options.stop_stack_spin ? cmd.stack_rate : 0.0});
        res.dwell_peak_rate = std::max(res.dwell_peak_rate, rate);
        res.dwell_at_rest = res.dwell_at_rest && cmd.status == DetumbleStatus::AtRest;
      }
      if (m == ticks) break;
      integ.reinit(t, y);
      integ.advance(t + tick);
      y = integ.y();
      res.steps += integ.num_steps();
      ++res.ticks;
    }
  }
  return res;
}

}  // namespace ffsr
