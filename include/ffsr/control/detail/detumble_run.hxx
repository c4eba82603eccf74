// ffsr/control/detail/detumble_run.hxx -- body of ffsr/control/detumble_run.hpp.
#pragma once

#include <cmath>

namespace ffsr {

namespace detail {

inline void check_detumble_run(const Model& stack, int gripper, const AttachedBody& body,
                               const DetumbleState& s, const DetumbleRunOptions& r) {
  constexpr const char* w = "run_detumble";
  if (!std::isfinite(r.tick) || !(r.tick > 0))
    throw InputError(str(w, ": the tick must be positive and finite, got ", r.tick));
  if (!std::isfinite(r.horizon) || !(r.horizon > 0))
    throw InputError(str(w, ": the horizon must be positive and finite, got ", r.horizon));
  if (!(r.tick < r.horizon))
    throw InputError(
        str(w, ": the tick (", r.tick, " s) must be shorter than the horizon (", r.horizon, " s)"));
  if (!std::isfinite(r.dwell) || !(r.dwell >= 0))
    throw InputError(str(w, ": the dwell must be >= 0 and finite, got ", r.dwell));
  if ((r.horizon + r.dwell) / r.tick > 1e7)
    throw InputError(str(w, ": more than 1e7 ticks: (horizon ", r.horizon, " s + dwell ", r.dwell,
                         " s) / tick ", r.tick, " s = ", (r.horizon + r.dwell) / r.tick));
  if (r.record_every < 0) throw InputError(str(w, ": record_every must be >= 0, got ", r.record_every));
  if (!(r.rtol > 0) || !(r.atol > 0) || !std::isfinite(r.rtol) || !std::isfinite(r.atol))
    throw InputError(str(w, ": the tolerances must be positive and finite"));
  if (gripper < 0 || gripper >= static_cast<int>(stack.frames().size()))
    throw InputError(str(w, ": frame index ", gripper, " out of range"));
  check_attached_body(body);
  require_size(s.theta.size(), stack.n(), w, "theta");
  require_size(s.v.size(), stack.nv(), w, "v");
  require_finite_all(s.theta, w, "theta");
  require_finite_all(s.v, w, "v");
  require_finite_all(s.wheel_momentum, w, "wheel momentum");
  require_finite_all(s.base.position, w, "base position");
  require_finite_all(s.base.orientation.coeffs(), w, "base orientation");
}

/// Records what the tick at `y` (command `cmd`) shows: the sample, and the peaks in `res`.
inline DetumbleSample detumble_sample(DetumbleSystem& sys, const Eigen::VectorXd& y, double t,
                                      const DetumbleCommand& cmd, int gripper, const AttachedBody& body,
                                      const Matrix3& R_start, DetumbleRunResult& res) {
  DetumbleSample s;
  const int n = sys.n;
  s.t = t;
  s.base = sys.base(y);
  s.theta = y.segment(7, n);
  s.theta_dot = y.segment(13 + n, n);
  s.command = cmd;
  sys.gripper_load(y, cmd, gripper, body, s.gripper_force, s.gripper_moment);
  const Matrix3 R = sys.base(y).orientation.toRotationMatrix();
  s.base_attitude = Eigen::AngleAxisd(Matrix3(R_start.transpose() * R)).angle();
  s.wheel_momentum = R.transpose() * y.tail<3>();
  sys.energy_momentum(y, s.energy, s.momentum);
  for (int k = 0; k < n; ++k)
    if (std::abs(cmd.tau(k)) > res.peak_joint_torque) {
      res.peak_joint_torque = std::abs(cmd.tau(k));
      res.peak_joint = k;
    }
  res.peak_gripper_force = std::max(res.peak_gripper_force, s.gripper_force.norm());
  res.peak_gripper_moment = std::max(res.peak_gripper_moment, s.gripper_moment.norm());
  res.base_attitude_excursion = std::max(res.base_attitude_excursion, s.base_attitude);
  res.peak_wheel_momentum = std::max(res.peak_wheel_momentum, s.wheel_momentum.cwiseAbs().maxCoeff());
  return s;
}

}  // namespace detail

namespace detail {

/// The run of run_detumble with the command of `step(state, t, command)` at each tick (the law's, or
/// a plan tracker's); `cmd` sized for the stack.
template <class Step>
DetumbleRunResult run_detumble_loop(const Model& stack, int gripper, const AttachedBody& body,
                                    const DetumbleState& start, const DetumbleLimits& limits,
                                    const DetumbleOptions& options, const DetumbleRunOptions& run,
                                    DetumbleCommand cmd, Step&& step) {
  detail::DetumbleSystem sys(stack), probe(stack);
  const bool wheels = limits.actuator == BaseActuator::ReactionWheels && options.stop_stack_spin;
  const bool closed = limits.actuator == BaseActuator::None || !options.stop_stack_spin;
  cvode::Options co;
  co.rtol = run.rtol;
  co.atol = run.atol;
  co.max_step = run.tick;
  Eigen::VectorXd y = sys.pack(start);
  cvode::Integrator integ([&](double, const Eigen::Ref<const Eigen::VectorXd>& yy,
                              Eigen::Ref<Eigen::VectorXd> yd) { sys.rhs(yy, cmd, wheels, yd); },
                          y, 0.0, co);
  const Matrix3 R_start = sys.base(y).orientation.toRotationMatrix();
  DetumbleRunResult res;
  Vector6 h0;
  probe.energy_momentum(y, res.energy_start, h0);
  const int n = stack.n();
  const auto ticks = static_cast<long>(std::ceil(run.horizon / run.tick - 1e-9));
  const auto dwell_ticks = static_cast<long>(std::ceil(run.dwell / run.tick - 1e-9));
  long last_tick = ticks;  // the horizon, until the first tick at rest sets the end of the dwell
  double T_prev = res.energy_start;
  for (long k = 0;; ++k) {
    const double t = static_cast<double>(k) * run.tick;
    step(sys.unpack(y), t, cmd);
    if (cmd.status == DetumbleStatus::Fault)
      throw NumericalError(
          detail::str("run_detumble: the controller faulted (", fault_name(cmd.fault), ") at t = ", t, " s"));
    DetumbleSample s = detail::detumble_sample(probe, y, t, cmd, gripper, body, R_start, res);
    res.momentum_drift = std::max(res.momentum_drift, (s.momentum - h0).norm() / std::max(h0.norm(), 1e-300));
    res.energy_end = s.energy;
    res.ticks = k;
    res.wheel_momentum_end = s.wheel_momentum;
    const bool rest = cmd.status == DetumbleStatus::AtRest;
    if (!res.at_rest) {
      res.time_to_rest = t;
      if (rest) {
        res.at_rest = res.dwell_at_rest = true;
        last_tick = k + dwell_ticks;
      }
    } else {  // the dwell
      const double rate = std::max({cmd.joint_rate, cmd.relative_rate, options.stop_stack_spin ? cmd.stack_rate : 0.0});
      res.dwell_peak_rate = std::max(res.dwell_peak_rate, rate);
      res.dwell_at_rest = res.dwell_at_rest && rest;
    }
    const bool last = k == last_tick;
    if (run.record_every > 0 && (k % run.record_every == 0 || last)) res.series.push_back(std::move(s));
    if (last) break;
    const Eigen::VectorXd theta_before = y.segment(7, n);
    if (k > 0) integ.reinit(t, y);  // the command jumps at the tick: a fresh start of the BDF history
    integ.advance(static_cast<double>(k + 1) * run.tick);
    y = integ.y();
    res.steps += integ.num_steps();
    const double W = cmd.tau.dot(y.segment(7, n) - theta_before);
    res.joint_work += W;
    if (closed) {
      double T;
      Vector6 h;
      probe.energy_momentum(y, T, h);
      res.max_energy_balance =
          std::max(res.max_energy_balance, std::abs(T - T_prev - W) / std::max(res.energy_start, 1e-300));
      T_prev = T;
    }
  }
  return res;
}

}  // namespace detail

inline DetumbleRunResult run_detumble(const Model& stack, int gripper, const AttachedBody& body,
                                      const DetumbleState& start, const DetumbleLimits& limits,
                                      const DetumbleOptions& options, const DetumbleRunOptions& run) {
  detail::check_detumble_run(stack, gripper, body, start, run);
  const bool none = limits.actuator == BaseActuator::None;  // no actuator: say so before the limits' checks
  if (none) check_detumble_feasible(stack, start, limits, options, run.horizon);
  detail::check_detumble(stack, limits, options, "run_detumble");
  if (!none) check_detumble_feasible(stack, start, limits, options, run.horizon);
  check_detumble_tick(stack, gripper, start, run.tick);
  DetumbleController ctrl(stack, gripper, body, limits, options, run.tick);
  return detail::run_detumble_loop(stack, gripper, body, start, limits, options, run, ctrl.make_command(),
                                   [&](const DetumbleState& s, double, DetumbleCommand& c) { ctrl.step(s, c); });
}

}  // namespace ffsr
