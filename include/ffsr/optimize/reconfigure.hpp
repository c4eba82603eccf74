// ffsr/optimize/reconfigure.hpp -- a reconfiguration of the arm before the capture approach.
#pragma once

#include "ffsr/optimize/capture.hpp"

#include <string>
#include <vector>

// The approach of capture.hpp starts at the initial configuration, so the capture configuration it
// can reach lies on the same component of the self-motion manifold as that configuration (for an
// arm without a null space: the same inverse-kinematics branch). A reconfiguration phase puts the
// arm on another component first. The capture time T stays the scenario's duration (the target's
// motion is given in time): the reconfiguration takes [0, t_r], the approach [t_r, T].
//
// Reconfiguration [0, t_r]. The joints move in joint space from theta_0 to the pre-approach
// configuration theta_pre with the quintic time law of line_reference.hpp,
//   theta(t) = theta_0 + s(t / t_r) (theta_pre - theta_0),  theta_dot = s'(t / t_r) / t_r (theta_pre - theta_0),
// zero rate and acceleration at both ends (a continuous joint takes the shorter way round). The
// base reacts with zero total momentum (Eq. 2: xb = -H_b^-1 H_bm theta_dot), and the state (p_0,
// q_0, theta) is integrated with the approach's RK4 step (free_floating_step.hpp) and watched by
// the same monitors (run_monitors.hpp): momentum, centre of mass, quaternion norm, joint limits.
// The peak joint rate of the quintic is 15/8 |theta_pre,k - theta_0,k| / t_r (at t_r / 2); it must
// not exceed the joint-rate limit (ReconfigurationRateError otherwise).
//
// Pre-approach configuration: the chosen capture configuration itself. The approach then starts
// with zero null-space error on the goal's component (the servo keeps it there, and without a null
// space the inverse-kinematics branch is kept by continuity), and its straight line only has to
// make up the end-effector's offset that the base's reaction in both phases causes. The shooting
// of plan_capture_global (global.hpp) moves the goal with the reached base pose as without the
// reconfiguration.
//
// Approach [t_r, T]. The planner of capture.hpp, unchanged, on the problem that starts at the state
// reached at t_r with the target propagated to t_r and duration T - t_r; its setup takes the capture
// (target at T, capture point, normal, contact law, final orientation) from the whole run's setup,
// so both phases aim at the same capture. The result joins both phases: one series (time from 0 to
// T), the monitors' maxima over both, the drifts from the initial base pose, and a RunPhase per phase.
//
// Neither phase looks at shapes: with a clearance the global run checks each joined run's path
// (GlobalCaptureOptions::check_run) and rejects a run that comes closer than the clearance.

namespace ffsr {

/// When the global run reconfigures the arm before the approach.
enum class ReconfigureMode {
  Never,  ///< the approach from the initial configuration only
  Auto,   ///< only when the best capture configuration is not reached by the approach alone
  Always  ///< before every approach
};

/// The mode's name as the scenario spells it.
inline const char* reconfigure_mode_name(ReconfigureMode m) {
  switch (m) {
    case ReconfigureMode::Never:
      return "never";
    case ReconfigureMode::Auto:
      return "auto";
    case ReconfigureMode::Always:
      return "always";
  }
  return "?";
}

/// The mode named `name` (auto, always, never); InputError starting with `where` otherwise.
inline ReconfigureMode reconfigure_mode_of(const std::string& name, const char* where) {
  if (name == "auto") return ReconfigureMode::Auto;
  if (name == "always") return ReconfigureMode::Always;
  if (name == "never") return ReconfigureMode::Never;
  throw InputError(detail::str(where, ": unknown reconfiguration mode '", name, "' (auto, always or never)"));
}

struct ReconfigureOptions {
  ReconfigureMode mode = ReconfigureMode::Never;
  /// t_r, s, 0 < t_r < T. 0: a quarter of T, lengthened (by 10 % over the least time) when the
  /// joint-rate limit needs more for the first reconfiguration.
  double duration = 0;
};

/// One phase of a capture run: its time span, the base's attitude and position change over it and
/// the largest joint rate in it.
struct RunPhase {
  std::string name;  ///< "reconfiguration" or "approach"
  double t_begin = 0, t_end = 0;
  double base_attitude_change = 0;  ///< rad, rotation angle between the base attitudes at both ends
  double base_position_change = 0;  ///< m
  double max_joint_rate = 0;        ///< rad/s, largest |theta_dot_k|
  long samples = 0;                 ///< samples of the run's series in this phase (in order)
};

/// A reconfiguration the joint-rate limit does not allow in the time given: the joint, the rate it
/// needs and the limit (rad/s), and the duration (s).
class ReconfigurationRateError : public InputError {
 public:
  ReconfigurationRateError(const std::string& what, std::string joint_, double needed_, double limit_,
                           double duration_)
      : InputError(what), joint(std::move(joint_)), needed(needed_), limit(limit_), duration(duration_) {}
  std::string joint;
  double needed, limit, duration;
};

/// The run of one goal with a reconfiguration: the joined run and its two phases.
struct ReconfiguredRun {
  CaptureResult run;
  std::vector<RunPhase> phases;
};

namespace detail {

/// Peak joint rate factor of the quintic time law: max s'(tau) = 15/8 at tau = 1/2.
constexpr double kQuinticPeakRate = 15.0 / 8.0;

/// The joint whose quintic move from theta0 to theta_pre needs the largest peak rate; writes its
/// index and returns that rate for the duration t_r (rad/s).
inline double reconfiguration_peak_rate(const Model& model, const Eigen::VectorXd& theta0,
                                        const Eigen::VectorXd& theta_pre, double t_r, int& joint) {
  Eigen::VectorXd d;
  configuration_error(model, theta_pre, theta0, d);
  d = d.cwiseAbs();
  joint = 0;
  const double peak = d.maxCoeff(&joint);
  return kQuinticPeakRate * peak / t_r;
}

/// The joint-rate field of the reconfiguration: theta_dot of the quintic move (see the notes after
/// the includes) and the base velocity from zero momentum. Runs crba at (base, theta); data then holds its
/// kinematics and data.H. Records the largest |theta_dot_k|.
struct ReconfigurationField {
  const Model& model;
  Data data;
  Eigen::VectorXd delta;  ///< theta_pre - theta_0 (shorter way round for continuous joints)
  double duration;
  double max_joint_rate = 0;

  ReconfigurationField(const Model& m, const Eigen::VectorXd& theta0, const Eigen::VectorXd& theta_pre,
                       double t_r)
      : model(m), data(m), duration(t_r) {
    configuration_error(m, theta_pre, theta0, delta);
  }

  void operator()(double t, const BasePose& base, const Eigen::VectorXd& theta, Eigen::VectorXd& theta_dot,
                  Vector6& xb) {
    double s, sdot;
    quintic(t / duration, s, sdot);
    theta_dot = (sdot / duration) * delta;
    max_joint_rate = std::max(max_joint_rate, theta_dot.cwiseAbs().maxCoeff());
    crba(model, data, base, theta);
    xb = base_velocity_from_momentum(model, data, theta_dot);
  }
};

/// The system centre of mass at (base, theta). Runs crba.
inline Vector3 system_com(const Model& model, Data& data, const BasePose& base,
                          const Eigen::VectorXd& theta) {
  crba(model, data, base, theta);
  return data.p[0] + data.Ic[0].h / data.Ic[0].m;
}

/// The reconfiguration phase from the problem's initial state: RK4 steps of about opt.step over
/// [0, t_r], the monitors at each step, the series (every opt.record_every steps and the last) if
/// opt.record_series. Writes base, theta (the state at t_r), the monitors' maxima, res.series,
/// res.steps and the phase. Throws NumericalError / JointLimitError (the monitors' messages).
inline void integrate_reconfiguration(const CaptureProblem& pb, const CaptureOptions& opt,
                                      const CaptureSetup& setup, const Eigen::VectorXd& theta_pre, double t_r,
                                      BasePose& base, Eigen::VectorXd& theta, RunMonitors& monitors,
                                      CaptureResult& res, RunPhase& phase) {
  const Model& model = *pb.model;
  ReconfigurationField field(model, pb.theta, theta_pre, t_r);
  FreeFloatingRK4 rk4(model.n());
  base = pb.base;
  base.orientation.normalize();
  theta = pb.theta;
  const long nsteps = std::max(1L, static_cast<long>(std::ceil(t_r / opt.step - 1e-9)));
  const double h = t_r / static_cast<double>(nsteps);
  if (opt.record_series) res.series.push_back(capture_sample(model, field.data, pb, setup, 0.0, base, theta));
  for (long k = 0; k < nsteps; ++k) {
    const double t = static_cast<double>(k) * h;
    rk4.begin(field, t, base, theta);
    monitors.check_motion(model, field.data, rk4.k_base[0], rk4.k_theta[0]);
    monitors.check_quaternion(rk4.finish(field, t, h, base, theta));
    monitors.check_state(model, base, theta, t + h);
    ++res.steps;
    if (opt.record_series && ((k + 1) % opt.record_every == 0 || k + 1 == nsteps))
      res.series.push_back(capture_sample(model, field.data, pb, setup, t + h, base, theta));
  }
  phase.name = "reconfiguration";
  phase.t_begin = 0;
  phase.t_end = t_r;
  phase.max_joint_rate = field.max_joint_rate;
  phase.base_position_change = (base.position - pb.base.position).norm();
  phase.base_attitude_change = rotation_angle(
      base.orientation.toRotationMatrix() * pb.base.orientation.normalized().toRotationMatrix().transpose());
  phase.samples = static_cast<long>(res.series.size());
}

/// The approach's setup from the state at t_r: prepare_capture on `pb2` (checks, line start, task
/// rows), then the capture of the whole run (`setup.capture`: target at T, capture point, normal, law,
/// final orientation) so that the line ends at the same capture point and orientation.
inline CaptureSetup approach_setup(const CaptureProblem& pb2, const CaptureTask& task,
                                   const CaptureOptions& opt2, const CaptureSetup& setup, const char* where) {
  CaptureSetup s = prepare_capture(pb2, task, opt2, where);
  s.capture = setup.capture;
  s.line.x_cap = s.capture.x_cap;
  s.line.rot_total = rotation_log(s.capture.R_end * s.line.R0.transpose());
  return s;
}

/// Joins the approach (times shifted by t_r; its first sample, the state at t_r, dropped as the
/// reconfiguration's last) into `res`, which holds the reconfiguration's series and steps.
inline void join_approach(const CaptureResult& app, double t_r, CaptureResult& res) {
  for (size_t i = res.series.empty() ? 0 : 1; i < app.series.size(); ++i) {
    res.series.push_back(app.series[i]);
    res.series.back().t += t_r;
  }
  const long steps = res.steps;
  std::vector<CaptureSample> series = std::move(res.series);
  const double mm = res.max_momentum, mb = res.max_body_momentum, mq = res.max_quaternion_error,
               mc = res.max_com_drift;
  res = app;
  res.series = std::move(series);
  res.steps += steps;
  res.max_momentum = std::max(mm, app.max_momentum);
  res.max_body_momentum = std::max(mb, app.max_body_momentum);
  res.max_quaternion_error = std::max(mq, app.max_quaternion_error);
  res.max_com_drift = std::max(mc, app.max_com_drift);
}

}  // namespace detail

/// Checks the reconfiguration's time and rate: 0 < t_r < opt.duration (InputError), and, when
/// opt.max_joint_rate > 0, the quintic move's peak rate 15/8 |theta_pre,k - theta_0,k| / t_r within
/// it (ReconfigurationRateError naming the joint). Messages start with `where`.
inline void check_reconfiguration(const Model& model, const Eigen::VectorXd& theta0,
                                  const Eigen::VectorXd& theta_pre, double t_r, const CaptureOptions& opt,
                                  const char* where) {
  using detail::str;
  if (!std::isfinite(t_r) || t_r <= 0 || t_r >= opt.duration)
    throw InputError(
        str(where, ": the reconfiguration duration must lie in (0, ", opt.duration, ") s, got ", t_r));
  int k = 0;
  const double rate = detail::reconfiguration_peak_rate(model, theta0, theta_pre, t_r, k);
  if (opt.max_joint_rate > 0 && rate > opt.max_joint_rate * (1 + 1e-9))
    throw ReconfigurationRateError(
        str(where, ": a reconfiguration in ", t_r, " s: joint '", model.joint(k).name, "' needs ",
            rate * 180 / M_PI, " deg/s, the max joint rate is ", opt.max_joint_rate * 180 / M_PI, " deg/s"),
        model.joint(k).name, rate, opt.max_joint_rate, t_r);
}

/// The default reconfiguration duration for the move theta0 -> theta_pre: a quarter of T, or 10 %
/// over the least time the joint-rate limit allows if that is longer (it may reach T; then
/// check_reconfiguration reports the joint).
inline double default_reconfiguration_duration(const Model& model, const Eigen::VectorXd& theta0,
                                               const Eigen::VectorXd& theta_pre, const CaptureOptions& opt) {
  double t_r = 0.25 * opt.duration;
  if (opt.max_joint_rate > 0) {
    int k = 0;
    const double least =
        detail::reconfiguration_peak_rate(model, theta0, theta_pre, 1.0, k) / opt.max_joint_rate;
    t_r = std::max(t_r, 1.1 * least);
  }
  return t_r;
}

/// A capture run with a reconfiguration (see the notes after the includes): the quintic joint-space move to
/// theta_pre over [0, t_r] with the base reacting, then the approach over [t_r, T] (T =
/// opt.duration) with `policy` (e.g. ServoPolicy to the capture configuration) toward the capture of
/// `setup` (prepare_capture(pb, task, opt)). Checks t_r and the joint rate first
/// (check_reconfiguration). The approach's task rates are not limited (only its null-space term is,
/// as in integrate_capture). Throws InputError, NumericalError or JointLimitError (messages start
/// with `where`).
template <class Policy>
ReconfiguredRun plan_reconfigured_capture(const CaptureProblem& pb, const CaptureTask& task,
                                          const CaptureOptions& opt, const CaptureSetup& setup,
                                          const Eigen::VectorXd& theta_pre, double t_r, Policy& policy,
                                          const char* where = "plan_reconfigured_capture") {
  const Model& model = *pb.model;
  check_reconfiguration(model, pb.theta, theta_pre, t_r, opt, where);
  ReconfiguredRun out;
  out.phases.resize(2);
  RunMonitors monitors(model, where, std::max(10.0 * opt.tolerance, 1e-2));
  CaptureProblem pb2 = pb;
  CaptureResult& res = out.run;
  detail::integrate_reconfiguration(pb, opt, setup, theta_pre, t_r, pb2.base, pb2.theta, monitors, res,
                                    out.phases[0]);
  monitors.record(res);
  Data data(model);
  const Vector3 com0 = detail::system_com(model, data, pb.base, pb.theta);
  const Vector3 com_r = detail::system_com(model, data, pb2.base, pb2.theta);
  pb2.target = propagate_target(pb.target, t_r);
  CaptureOptions opt2 = opt;
  opt2.duration = opt.duration - t_r;
  opt2.progress = nullptr;
  const CaptureSetup s2 = detail::approach_setup(pb2, task, opt2, setup, where);
  CaptureResult app = integrate_capture(pb2, task, opt2, s2, policy, where);
  RunPhase& ap = out.phases[1];
  ap.name = "approach";
  ap.t_begin = t_r;
  ap.t_end = opt.duration;
  ap.base_position_change = app.base_position_drift;
  ap.base_attitude_change = app.base_attitude_drift;
  ap.max_joint_rate = app.max_joint_rate;
  ap.samples = app.series.empty() ? 0 : static_cast<long>(app.series.size()) - 1;
  // the approach's centre-of-mass drift is measured from its start: adding the offset of that start
  // from the initial centre of mass bounds the drift over both phases
  app.max_com_drift += (com_r - com0).norm();
  detail::join_approach(app, t_r, res);
  res.max_joint_rate = std::max(out.phases[0].max_joint_rate, ap.max_joint_rate);
  res.base_position_drift = (res.base.position - pb.base.position).norm();
  res.base_attitude_drift = rotation_angle(res.base.orientation.toRotationMatrix() *
                                           pb.base.orientation.normalized().toRotationMatrix().transpose());
  return out;
}

/// The single phase of a run without a reconfiguration (the approach over [0, T]).
inline std::vector<RunPhase> approach_only_phases(const CaptureResult& run, double T) {
  RunPhase p;
  p.name = "approach";
  p.t_begin = 0;
  p.t_end = T;
  p.base_attitude_change = run.base_attitude_drift;
  p.base_position_change = run.base_position_drift;
  p.max_joint_rate = run.max_joint_rate;
  p.samples = static_cast<long>(run.series.size());
  return {p};
}

}  // namespace ffsr
