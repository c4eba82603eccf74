// ffsr/control/detail/closed_loop.hxx -- body of ffsr/control/closed_loop.hpp.
#pragma once

#include <optional>

namespace ffsr {

namespace detail {

/// The Dormand-Prince 5(4) pair (Dormand and Prince 1980; Hairer, Norsett and Wanner, Solving
/// Ordinary Differential Equations I, Section II.5): seven stages, the last one at the new state
/// (first same as last), the 5th-order solution carried on, e = b - b_hat the weights of its
/// difference to the embedded 4th-order solution (the error estimate).
struct DormandPrince54 {
  static constexpr int stages = 7;
  static constexpr double error_exponent = 1.0 / 5.0;  ///< 1 / (lower order + 1)
  static constexpr double a[7][6] = {
      {0, 0, 0, 0, 0, 0},
      {1.0 / 5, 0, 0, 0, 0, 0},
      {3.0 / 40, 9.0 / 40, 0, 0, 0, 0},
      {44.0 / 45, -56.0 / 15, 32.0 / 9, 0, 0, 0},
      {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729, 0, 0},
      {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656, 0},
      {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};  // = b
  static constexpr double e[7] = {71.0 / 57600,      0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200,
                                  22.0 / 525, -1.0 / 40};
};

/// The Bogacki-Shampine 3(2) pair (Bogacki and Shampine 1989): four stages, first same as last.
struct BogackiShampine32 {
  static constexpr int stages = 4;
  static constexpr double error_exponent = 1.0 / 3.0;
  static constexpr double a[4][3] = {
      {0, 0, 0}, {1.0 / 2, 0, 0}, {0, 3.0 / 4, 0}, {2.0 / 9, 1.0 / 3, 4.0 / 9}};  // last row = b
  static constexpr double e[4] = {2.0 / 9 - 7.0 / 24, 1.0 / 3 - 1.0 / 4, 4.0 / 9 - 1.0 / 3, -1.0 / 8};
};

/// ClosedLoopIntegrator::RungeKutta: one continuous integration of the plant with an embedded
/// explicit pair whose steps end on the ticks (the command is constant within a control period, so
/// each step sees a smooth right-hand side). The step size is carried from tick to tick; a step
/// whose error estimate exceeds rtol |y_i| + atol (weighted RMS over the state) is taken again,
/// shorter. Storage is sized at construction: advance() does not allocate.
template <class Pair>
class TickRungeKutta {
 public:
  TickRungeKutta(Eigen::Index size, double rtol, double atol, double dt)
      : k_(size, Pair::stages), ys_(size), err_(size), rtol_(rtol), atol_(atol), h_(dt) {}

  /// y(t0) -> y(t1) with the plant's command u held. Writes the plant's workspace. IntegrationError
  /// when the step size collapses or a control period takes more than kMaxSteps steps.
  void advance(ClosedLoopPlant& p, double t0, double t1, Eigen::VectorXd& y) {
    // First stage with the new command. After an accepted step the plant's dynamics() is at y (the
    // last stage was evaluated there), and only the torques change with the command.
    if (dynamics_at_y_)
      p.derivative(y, k_.col(0));
    else
      p.rhs(y, k_.col(0));
    double t = t0;
    for (long tries = 0; t < t1; ++tries) {
      if (tries >= kMaxSteps)
        throw IntegrationError(str("closed loop: more than ", kMaxSteps, " Runge-Kutta steps in the control ",
                                   "period at t = ", t0, " s (too stiff for the explicit integrator: use ",
                                   "ClosedLoopIntegrator::CvodeRestart)"));
      const bool last = t1 - t <= 1.05 * h_;
      const double h = last ? t1 - t : h_;
      const double r = try_step(p, h, y);
      if (r <= 1.0) {  // accepted: the 5th-order (3rd) solution, and its last stage as the next first
        y.swap(ys_);
        k_.col(0) = k_.col(Pair::stages - 1);
        t = last ? t1 : t + h;
        ++steps_;
        dynamics_at_y_ = true;
        h_ = h * (r > 0 ? std::min(5.0, 0.9 * std::pow(r, -Pair::error_exponent)) : 5.0);
      } else {  // refused (also a non-finite estimate): shorter
        ++rejected_;
        dynamics_at_y_ = false;
        h_ = h * (std::isfinite(r) ? std::max(0.2, 0.9 * std::pow(r, -Pair::error_exponent)) : 0.2);
        if (h_ < 1e-12 * (t1 - t0))
          throw IntegrationError(str("closed loop: the Runge-Kutta step size fell below ", h_, " s at t = ", t,
                                     " s (error estimate ", r, ")"));
      }
    }
  }
  /// True when the plant's last evaluation (dynamics()) was at the current y: after an accepted step.
  bool dynamics_at_y() const { return dynamics_at_y_; }
  long steps() const { return steps_; }
  long rejected() const { return rejected_; }

 private:
  static constexpr long kMaxSteps = 100000;

  /// One step of size h from y (first stage in k_.col(0)); the new state in ys_. Returns the
  /// weighted RMS error estimate (<= 1: accepted).
  double try_step(ClosedLoopPlant& p, double h, const Eigen::VectorXd& y) {
    for (int s = 1; s < Pair::stages; ++s) {
      ys_ = y;
      for (int j = 0; j < s; ++j)
        if (Pair::a[s][j] != 0.0) ys_.noalias() += (h * Pair::a[s][j]) * k_.col(j);
      p.rhs(ys_, k_.col(s));
    }
    err_.setZero();
    for (int j = 0; j < Pair::stages; ++j)
      if (Pair::e[j] != 0.0) err_.noalias() += (h * Pair::e[j]) * k_.col(j);
    double sum = 0;
    for (Eigen::Index i = 0; i < y.size(); ++i) {
      const double w = rtol_ * std::max(std::abs(y(i)), std::abs(ys_(i))) + atol_;
      sum += (err_(i) / w) * (err_(i) / w);
    }
    return std::sqrt(sum / static_cast<double>(y.size()));
  }

  Eigen::MatrixXd k_;  ///< the stages, one column each
  Eigen::VectorXd ys_, err_;
  double rtol_, atol_, h_;
  bool dynamics_at_y_ = false;
  long steps_ = 0, rejected_ = 0;
};

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
  const CaptureEvaluator objective(p.model, pb.frame, truth, &ctrl.setup().capture.law, pb.joints);
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

/// The number of control ticks over [0, T]; InputError when the run would take too many.
inline long closed_loop_ticks(double T, const ClosedLoopOptions& o) {
  if (T * o.control_rate > 1e8 || T * o.estimate_rate > 1e7)
    throw InputError(str("closed loop: ", T * o.control_rate, " ticks and ", T * o.estimate_rate,
                         " estimates over T = ", T, " s: too many (at most 1e8 and 1e7)"));
  return std::max(1L, static_cast<long>(std::ceil(T * o.control_rate - 1e-9)));
}

/// ClosedLoopIntegrator::CvodeRestart: CVODE over the plant, restarted at each tick of length dt.
inline void start_cvode(std::optional<cvode::Integrator>& cv, ClosedLoopPlant& plant,
                        const Eigen::VectorXd& y, double dt, const ClosedLoopOptions& o) {
  cvode::Options co;
  co.rtol = o.rtol;
  co.atol = o.atol;
  co.max_step = dt;
  co.initial_step = 0.1 * dt;  // each tick restarts CVODE: no step-size estimate from scratch
  ClosedLoopPlant* pl = &plant;
  cv.emplace([pl](double, const Eigen::Ref<const Eigen::VectorXd>& yy,
                  Eigen::Ref<Eigen::VectorXd> yd) { pl->rhs(yy, yd); },
             y, 0.0, co);
}

/// The momentum at the state y (configuration st). After a Runge-Kutta step of the articulated plant
/// (`from_last_pass`) its last evaluation was at y, and its velocity pass holds the bodies' inertias and
/// velocities there; else from the kinematics again.
inline Vector6 tick_momentum(const Model& model, ClosedLoopPlant& plant, bool from_last_pass,
                             const ControllerState& st, const Eigen::VectorXd& y) {
  if (from_last_pass) return momentum_from_velocity_pass(model, plant.data);
  forward_kinematics(model, plant.data, st.base, st.theta);
  return momentum(model, plant.data, y.segment(plant.iv(), 6 + model.n()));
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
  const long ticks = detail::closed_loop_ticks(T, o);
  const double dt = T / static_cast<double>(ticks);
  detail::TickRungeKutta<detail::DormandPrince54> rk(y.size(), o.rtol, o.atol, dt);
  std::optional<cvode::Integrator> cv;  // CvodeRestart
  if (o.integrator == ClosedLoopIntegrator::CvodeRestart) detail::start_cvode(cv, plant, y, dt, o);
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
    const Vector6 h =
        detail::tick_momentum(model, plant, !cv && plant.articulated && rk.dynamics_at_y(), st, y);
    const double hn = h.head<3>().norm() + h.tail<3>().norm();
    res.max_momentum = std::max(res.max_momentum, hn);
    if (o.record_every > 0 && t >= next_record - 1e-9 * dt) {
      res.series.push_back(detail::closed_loop_sample(plant, y, t, cmd, hn));
      next_record += o.record_every;
    }
    const double t_next = k + 1 == ticks ? T : t + dt;
    if (cv) {
      cv->reinit(t, y);
      cv->advance(t_next);
      y = cv->y();
      res.integrator_steps += cv->num_steps();
    } else {
      rk.advance(plant, t, t_next, y);
    }
    res.max_tracking_lag =
        std::max(res.max_tracking_lag, (plant.u - y.segment(plant.iv() + 6, n)).cwiseAbs().maxCoeff());
  }
  if (!cv) {
    res.integrator_steps = rk.steps();
    res.rejected_steps = rk.rejected();
  }
  detail::finish_closed_loop(ctrl, plant, y, res);
  return res;
}

}  // namespace ffsr
