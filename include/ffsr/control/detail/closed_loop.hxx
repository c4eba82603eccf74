// ffsr/control/detail/closed_loop.hxx -- body of ffsr/control/closed_loop.hpp.
#pragma once

namespace ffsr {

namespace detail {

/// The state at T: capture error against the true target, M_ie (the problem's joint model) and F_max
/// at the reached configuration, base changes. Runs crba. Writes the result's final fields.
template <class Policy>
void finish_closed_loop(const CaptureController<Policy>& ctrl, ClosedLoopPlant& p, const Eigen::VectorXd& y,
                        ClosedLoopResult& res) {
  const CaptureProblem& pb = ctrl.problem();
  const Target truth = propagate_target(pb.target, ctrl.duration());
  res.base = p.base(y);
  res.theta = y.segment(6, p.n);
  crba(p.model, p.data, res.base, res.theta);
  res.end_effector = frame_pose(p.model, p.data, pb.frame).p;
  res.capture_point = truth.contact_point();
  res.capture_error = (res.end_effector - res.capture_point).norm();
  const CaptureEvaluator objective(p.model, pb.frame, truth, &ctrl.setup().law, pb.joints);
  res.M_ie = objective.mass_at(p.data);
  res.f_max_closed_form = objective.f_max_closed_form(res.M_ie);
  res.base_attitude_change = rotation_angle(res.base.orientation.toRotationMatrix() *
                                            p.base0.orientation.toRotationMatrix().transpose());
  res.base_position_change = y.segment<3>(0).norm();
}

/// One sample of the series at tick t (the state y, the command held over the tick).
inline ClosedLoopSample closed_loop_sample(ClosedLoopPlant& p, const Eigen::VectorXd& y, double t,
                                           const ControlCommand& cmd, double momentum_norm) {
  ClosedLoopSample s;
  s.t = t;
  s.theta = y.segment(6, p.n);
  s.theta_dot = y.segment(p.iv() + 6, p.n);
  s.command = p.u;
  s.torque = p.tau.tail(p.n);
  s.end_effector = cmd.end_effector;
  s.reference = cmd.reference;
  s.momentum = momentum_norm;
  return s;
}

}  // namespace detail

template <class Policy>
ClosedLoopResult simulate_closed_loop(CaptureController<Policy>& ctrl, const ClosedLoopOptions& o) {
  using detail::str;
  detail::check_closed_loop_options(o);
  const CaptureProblem& pb = ctrl.problem();
  const Model& model = *pb.model;
  const int n = model.n();
  const double T = ctrl.duration();
  detail::ClosedLoopPlant plant(model, pb.base, pb.theta, o.loop);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(12 + 3 * n);
  y.segment(6, n) = pb.theta;
  cvode::Options co;
  co.rtol = o.rtol;
  co.atol = o.atol;
  if (T * o.control_rate > 1e8 || T * o.estimate_rate > 1e7)
    throw InputError(str("closed loop: ", T * o.control_rate, " ticks and ", T * o.estimate_rate,
                         " estimates over T = ", T, " s: too many (at most 1e8 and 1e7)"));
  const long ticks = std::max(1L, static_cast<long>(std::ceil(T * o.control_rate - 1e-9)));
  const double dt = T / static_cast<double>(ticks);
  co.max_step = dt;
  co.initial_step = 0.1 * dt;  // each tick restarts CVODE: no step-size estimate from scratch
  cvode::Integrator integ([&](double, const Eigen::Ref<const Eigen::VectorXd>& yy,
                              Eigen::Ref<Eigen::VectorXd> yd) { plant.rhs(yy, yd); },
                          y, 0.0, co);
  ClosedLoopResult res;
  ControlCommand cmd = ctrl.make_command();
  ControllerState st{pb.base, pb.theta};
  TargetEstimate est = target_estimate(pb.target);
  const double de = 1.0 / o.estimate_rate;
  long next_est = 0;
  double next_record = 0;
  for (long k = 0; k < ticks; ++k) {
    const double t = static_cast<double>(k) * dt;
    for (double te = static_cast<double>(next_est) * de; te <= t + 1e-9 * dt && te < T;
         te = static_cast<double>(++next_est) * de) {
      est = detail::noisy_estimate(propagate_target(pb.target, te), o, static_cast<std::uint64_t>(next_est));
      const ControlFault f = ctrl.update_target(te, est);
      if (f != ControlFault::None)
        throw NumericalError(
            str("closed loop: update_target at t = ", te, " s: fault (", fault_name(f), ")"));
      ++res.estimates;
    }
    st.base = plant.base(y);
    st.theta = y.segment(6, n);
    ctrl.step(t, st, est, cmd);
    if (cmd.status == ControlStatus::Fault)
      throw NumericalError(str("closed loop: the controller faulted at t = ", t, " s (",
                               fault_name(cmd.fault),
                               cmd.fault_index >= 0 ? str(" ", cmd.fault_index) : std::string(), ")"));
    plant.u = cmd.theta_dot;
    if (plant.torques(y)) ++res.saturated_ticks;
    res.max_torque = std::max(res.max_torque, plant.tau.tail(n).cwiseAbs().maxCoeff());
    detail::record_tick(cmd, res);
    forward_kinematics(model, plant.data, st.base, st.theta);
    const Vector6 h = momentum(model, plant.data, y.segment(plant.iv(), 6 + n));
    const double hn = h.head<3>().norm() + h.tail<3>().norm();
    res.max_momentum = std::max(res.max_momentum, hn);
    if (o.record_every > 0 && t >= next_record - 1e-9 * dt) {
      res.series.push_back(detail::closed_loop_sample(plant, y, t, cmd, hn));
      next_record += o.record_every;
    }
    integ.reinit(t, y);
    integ.advance(k + 1 == ticks ? T : t + dt);
    y = integ.y();
    res.cvode_steps += integ.num_steps();
    res.max_tracking_lag =
        std::max(res.max_tracking_lag, (plant.u - y.segment(plant.iv() + 6, n)).cwiseAbs().maxCoeff());
  }
  detail::finish_closed_loop(ctrl, plant, y, res);
  return res;
}

}  // namespace ffsr
