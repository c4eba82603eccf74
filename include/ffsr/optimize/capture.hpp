// ffsr/optimize/capture.hpp -- the capture approach and its null-space optimization (Section 4).
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/model/target.hpp"
#include "ffsr/optimize/base_attitude.hpp"
#include "ffsr/optimize/capture_problem.hpp"
#include "ffsr/optimize/free_floating_step.hpp"
#include "ffsr/optimize/line_reference.hpp"
#include "ffsr/optimize/null_space.hpp"
#include "ffsr/optimize/objective.hpp"
#include "ffsr/optimize/run_monitors.hpp"
#include "ffsr/optimize/task_solver.hpp"

#include <algorithm>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

// The free-floating robot moves its end-effector along a straight line in the inertial frame, from
// its initial position to the capture point (the target's contact point at the capture time T),
// with a quintic time law (zero velocity and acceleration at both ends) and a proportional feedback
// on the tracking error so that drift does not accumulate. The total momentum stays zero: the base
// velocity follows from momentum conservation. Joint rates (Eq. 30-31):
//   theta_dot = J_t^+ (x_d_dot + k_p e) + rho (E - J_t^+ J_t) phi,
// with J_t the task rows of the generalized Jacobian J_f, J_t^+ its pseudo-inverse (SVD; damped
// least squares near a singularity, reported), and phi the analytic gradient of the objective with
// respect to the joint angles at the current base pose; rho < 0 lowers the objective. The objective
// is M_ie (Eq. 14, the paper's choice, Eq. 24-28) with the target's contact normal and attitude at
// the capture time, or the exact maximum force, a monotone function of it (same direction, scaled).
// The state (base position, unit quaternion, joint angles) is integrated with fixed-step RK4; the
// quaternion is renormalized after every step.
//
// Joint limits from the URDF: the null-space term is pushed away from a limit by a repulsive
// gradient inside a margin of 10 % of the range, and a run whose joint leaves its range fails with
// a NumericalError naming the joint (the task has priority and is never clamped). A run whose
// end-effector falls more than max(10 tolerance, 1 cm) behind the line stops with a NumericalError:
// the capture point is out of reach (or the line crosses a singularity), not a result.
//
// The run is a composition of named parts, each in its own header:
//   line_reference.hpp      x_d(t), x_d_dot(t) (and R_d, omega_d for a pose task)
//   task_solver.hpp         the rate law of Eq. 30-31 (TaskSolver: task rows, SVD, damping,
//                           projector, joint-rate scaling)
//   null_space.hpp          the null-space policies (GradientPolicy, ServoPolicy)
//   free_floating_step.hpp  the RK4 step of (p_0, q_0, theta) (FreeFloatingRK4)
//   run_monitors.hpp        momentum, centre of mass, tracking error, quaternion, joint limits
// Here: the checks of the input (prepare_capture), the joint-rate field that joins the first three
// (detail::CaptureRateField), and integrate_capture, which steps it and watches the monitors.

namespace ffsr {

namespace detail {

/// The errors of plan_capture on the problem, task and options (messages start with `where`).
inline void check_capture_input(const CaptureProblem& pb, const CaptureTask& task, const CaptureOptions& opt,
                                const char* where) {
  if (!pb.model) FFSR_THROW(InputError(str(where, ": no model")));
  const Model& model = *pb.model;
  const int n = model.n();
  detail::check_configuration(model, pb.base, pb.theta, where);
  if (pb.frame < 0 || pb.frame >= static_cast<int>(model.frames().size()))
    FFSR_THROW(InputError(str(where, ": end-effector frame out of range")));
  pb.target.validate((std::string(where) + ": target").c_str());  // no stream: onboard images stay small
  validate(pb.contact, where);
  auto positive = [&](double x, const char* what) {
    if (!std::isfinite(x) || x <= 0)
      FFSR_THROW(InputError(str(where, ": ", what, " must be positive and finite, got ", x)));
  };
  positive(opt.duration, "duration");
  positive(opt.step, "step");
  positive(opt.tolerance, "tolerance");
  positive(opt.orientation_tolerance, "orientation tolerance");
  positive(opt.singular_value_threshold, "singular value threshold");
  detail::require_finite(opt.gain, where, "gain rho");
  detail::require_finite(opt.feedback, where, "feedback gain");
  if (opt.feedback < 0) FFSR_THROW(InputError(str(where, ": feedback gain must be >= 0")));
  if (!std::isfinite(opt.max_joint_rate) || opt.max_joint_rate < 0)
    FFSR_THROW(JointRateLimitError(
        str(where, ": max joint rate must be >= 0 (0: not limited), got ", opt.max_joint_rate)));
  if (opt.duration / opt.step > 1e7)
    FFSR_THROW(InputError(
        str(where, ": duration / step = ", opt.duration / opt.step, " steps is too many (at most 1e7)")));
  if (opt.record_every < 1) FFSR_THROW(InputError(str(where, ": record_every must be >= 1")));
  const int m = task.rows();
  if (m < 1) FFSR_THROW(InputError(str(where, ": the task constrains no axis")));
  if (opt.gain != 0.0 && m >= n)
    FFSR_THROW(InputError(str(where, ": the task has ", m, " rows and the robot ", n,
                         " joints: no null space to optimize in (use gain 0 or a smaller task)")));
}

}  // namespace detail

namespace detail {

/// hold_base_attitude: the directions held (Q of base_attitude.hpp, at the initial state) into
/// s.attitude_basis; InputError when the task and the held rows leave the objective no freedom.
inline void prepare_base_attitude_hold(const CaptureProblem& pb, const CaptureOptions& opt, CaptureSetup& s,
                                       const char* where) {
  const Model& model = *pb.model;
  Data data(model);
  s.attitude_basis = base_attitude_directions(model, data, pb.base, pb.theta, pb.frame);  // and data.Jf
  const int m = static_cast<int>(s.rows.size()), r = static_cast<int>(s.attitude_basis.cols());
  Eigen::MatrixXd Jt(m, model.n());
  for (int i = 0; i < m; ++i) Jt.row(i) = data.Jf.row(s.rows[static_cast<size_t>(i)]);
  s.held_freedom = held_freedom_shares(Jt, s.attitude_basis.transpose() * base_angular_rows(data));
  const int needed = joints_needed_to_hold(m, r, opt.gain != 0.0);
  if (needed > model.n())
    FFSR_THROW(InputError(str(where, ": holding the base attitude takes ", m, " task rows + ", r,
                         r == 1 ? " base-attitude row = " : " base-attitude rows = ", m + r,
                         " of the robot's ", model.n(), " joints",
                         opt.gain != 0.0 ? ": no freedom left for the objective" : "", " (it needs ", needed,
                         " joints)")));
}

}  // namespace detail

/// Checks the problem, task and options (the errors of plan_capture, named after `where`) and builds
/// the capture setup. Runs crba at the initial state.
inline CaptureSetup prepare_capture(const CaptureProblem& pb, const CaptureTask& task,
                                    const CaptureOptions& opt, const char* where = "plan_capture") {
  using detail::str;
  detail::check_capture_input(pb, task, opt, where);
  const Model& model = *pb.model;
  // The capture: the target's contact point, normal and attitude at T.
  CaptureSetup s{{propagate_target(pb.target, opt.duration), {}, {}, 0, 0,
                  make_contact_law("hunt-crossley", ContactParams{}, 1.0), {}},
                 {},
                 {},
                 {},
                 {}};
  CaptureAtT& c = s.capture;
  c.x_cap = c.target.contact_point();
  c.u_cap = c.target.normal_world();
  c.target_inv_mass = c.target.inverse_mass_along_normal();
  c.v_in = approach_velocity(c.u_cap, Vector3(pb.approach_speed * c.u_cap), c.target.velocity,
                             c.target.angular_velocity_world(), c.target.offset_world());
  if (!(c.v_in > 0))
    FFSR_THROW(InputError(
        str(where, ": at the capture the end-effector does not approach the target (delta_dot^- = ", c.v_in,
            " m/s); increase the approach speed")));
  c.law = make_contact_law(pb.law, pb.contact, c.v_in);

  Data data(model);
  crba(model, data, pb.base, pb.theta);
  const Pose ee0 = frame_pose(model, data, pb.frame);
  c.R_end = task.final_orientation ? *task.final_orientation : ee0.R;
  s.line = {ee0.p, c.x_cap, ee0.R, detail::rotation_log(c.R_end * ee0.R.transpose()), opt.duration};
  if (task.kind == CaptureTask::Kind::Pose) {
    for (int r = 0; r < 6; ++r) s.rows.push_back(r);
  } else {
    for (int r = 0; r < 3; ++r)
      if (task.axes[static_cast<size_t>(r)]) s.rows.push_back(r);
  }
  if (opt.hold_base_attitude) detail::prepare_base_attitude_hold(pb, opt, s, where);
  return s;
}

namespace detail {

/// The joint-rate field of a capture run: at (t, base, theta) it writes theta_dot from the task
/// solver and the null-space policy (Eq. 30-31), filtered by the options' rate guard if any, and the
/// base velocity xb from zero momentum (Eq. 2).
/// Runs crba, frame_jacobian and generalized_jacobian at (base, theta), then the policy; data then
/// holds the kinematics and data.H of (base, theta). Records the smallest singular value, the damped
/// evaluations and the largest |theta_dot_k|.
template <class Policy>
struct CaptureRateField {
  const Model& model;
  const CaptureProblem& pb;
  const CaptureTask& task;
  const CaptureOptions& opt;
  const CaptureSetup& setup;
  Policy& policy;
  Data data;
  TaskSolver solver;
  Eigen::VectorXd qd_null;
  Eigen::MatrixXd attitude_rows;     ///< hold_base_attitude: Q^T A (r x n), the held rows
  std::unique_ptr<RateGuard> guard;  ///< opt.rate_guard's filter (null: none)
  double min_singular_value = std::numeric_limits<double>::infinity();
  long damped_steps = 0;
  double first_damped_time = -1;  ///< t of the first damped evaluation (-1: none)
  double max_joint_rate = 0;

  CaptureRateField(const CaptureProblem& pb_, const CaptureTask& task_, const CaptureOptions& opt_,
                   const CaptureSetup& setup_, Policy& policy_)
      : model(*pb_.model),
        pb(pb_),
        task(task_),
        opt(opt_),
        setup(setup_),
        policy(policy_),
        data(model),
        solver(model.n(), setup_.rows, static_cast<int>(setup_.attitude_basis.cols()),
               opt_.singular_value_threshold, opt_.max_damping),
        qd_null(model.n()),
        attitude_rows(setup_.attitude_basis.cols(), model.n()),
        guard(opt_.rate_guard ? opt_.rate_guard() : nullptr) {}

  void operator()(double t, const BasePose& base, const Eigen::VectorXd& theta, Eigen::VectorXd& theta_dot,
                  Vector6& xb) {
    crba(model, data, base, theta);
    frame_jacobian(model, data, pb.frame);
    generalized_jacobian(model, data);
    const Pose ee = frame_pose(model, data, pb.frame);
    const Vector6 cmd =
        task_velocity_command(setup.line, t, ee, opt.feedback, task.kind == CaptureTask::Kind::Pose);
    if (solver.extra_rows() > 0)
      attitude_rows.noalias() = setup.attitude_basis.transpose() * base_angular_rows(data);
    const bool projector = policy.active() || guard;
    const TaskRates& r = solver.extra_rows() > 0 ? solver.solve(data.Jf, cmd, projector, attitude_rows)
                                                 : solver.solve(data.Jf, cmd, projector);
    min_singular_value = std::min(min_singular_value, r.sigma_min);
    if (r.damped && damped_steps++ == 0) first_damped_time = t;
    if (policy.active()) {  // data still holds crba at (base, theta): the policy reads it
      policy(model, data, pb, setup, t, base, theta, solver.projector(), qd_null);
      solver.add_null_space(qd_null, opt.max_joint_rate);
    }
    theta_dot = r.theta_dot;
    if (guard) guard->filter(model, data, t, solver.projector(), theta_dot);
    max_joint_rate = std::max(max_joint_rate, theta_dot.cwiseAbs().maxCoeff());
    xb = base_velocity_from_momentum(model, data, theta_dot);  // data.H is H(base, theta)
  }
};

/// One sample of the series at time t. Runs crba.
inline CaptureSample capture_sample(const Model& model, Data& data, const CaptureProblem& pb,
                                    const CaptureSetup& s, double t, const BasePose& base,
                                    const Eigen::VectorXd& theta) {
  CaptureSample c;
  c.t = t;
  c.theta = theta;
  c.base = base;
  crba(model, data, base, theta);
  c.end_effector = frame_pose(model, data, pb.frame).p;
  const CaptureEvaluator objective(pb, s);
  c.M_ie = objective.mass_at(data);
  c.f_max_estimate = objective.f_max_closed_form(c.M_ie);
  return c;
}

/// The result at T from the final state: errors against the capture point and orientation, base
/// drift, M_ie and F_max; then the capture tolerances (NumericalError, messages start with `where`).
/// Runs crba. Writes the fields of `res` that describe the final state.
inline void finish_capture(const Model& model, Data& data, const CaptureProblem& pb, const CaptureTask& task,
                           const CaptureOptions& opt, const CaptureSetup& setup, const BasePose& base,
                           const Eigen::VectorXd& theta, CaptureResult& res, const char* where) {
  crba(model, data, base, theta);
  const Pose ee = frame_pose(model, data, pb.frame);
  const Vector3& x_cap = setup.capture.x_cap;
  res.theta = theta;
  res.base = base;
  res.end_effector = ee.p;
  double e2 = 0;  // the tracking error on the constrained position axes (all three for a pose task)
  for (int r : setup.rows)
    if (r < 3) e2 += (ee.p(r) - x_cap(r)) * (ee.p(r) - x_cap(r));
  res.tracking_error = std::sqrt(e2);
  res.capture_distance = (ee.p - x_cap).norm();
  res.orientation_error =
      task.kind == CaptureTask::Kind::Pose ? rotation_angle(setup.capture.R_end * ee.R.transpose()) : 0.0;
  res.base_position_drift = (base.position - pb.base.position).norm();
  res.base_attitude_drift = rotation_angle(base.orientation.toRotationMatrix() *
                                           pb.base.orientation.normalized().toRotationMatrix().transpose());
  const CaptureEvaluator objective(pb, setup);
  res.M_ie = objective.mass_at(data);
  res.approach_velocity = setup.capture.v_in;
  res.f_max_closed_form = objective.f_max_closed_form(res.M_ie);
  res.f_max_exact = objective.f_max_exact(res.M_ie);
  if (!std::isfinite(res.M_ie) || !std::isfinite(res.f_max_exact) || !std::isfinite(res.f_max_closed_form))
    FFSR_THROW(NumericalError(str(where, ": the capture configuration gives a non-finite M_ie or F_max")));
  if (res.tracking_error > opt.tolerance)
    FFSR_THROW(NumericalError(str(where, ": the end-effector missed the capture point by ", res.tracking_error,
                             " m (tolerance ", opt.tolerance, " m); the point may be out of reach")));
  if (task.kind == CaptureTask::Kind::Pose && res.orientation_error > opt.orientation_tolerance)
    FFSR_THROW(NumericalError(str(where, ": the end-effector orientation is off by ", res.orientation_error,
                             " rad at the capture (tolerance ", opt.orientation_tolerance, " rad)")));
}

/// The error of a held approach (hold_base_attitude) that loses the line at an algorithmic
/// singularity: J_t N_A rank-deficient from `t_singular` on, the tracking error `error` at `t`, and
/// the joints that hold the freedom the task and the held rows leave (setup.held_freedom, shares of
/// 10 % and more).
inline std::string held_singularity_message(const Model& model, const CaptureOptions& opt,
                                            const CaptureSetup& setup, const char* where, double t_singular,
                                            double sigma_min, double t, double error) {
  std::vector<std::pair<double, int>> shares;
  for (Eigen::Index k = 0; k < setup.held_freedom.size(); ++k)
    if (setup.held_freedom(k) >= 0.1) shares.emplace_back(setup.held_freedom(k), static_cast<int>(k));
  std::sort(shares.rbegin(), shares.rend());
  const std::vector<std::string> names = model.joint_names();
  std::ostringstream m;
  m.precision(3);
  m << where
    << ": holding the base attitude, the arm meets an algorithmic singularity: from t = " << t_singular
    << " s the task rows in the held rows' null space (J_t N_A) lose rank (smallest singular value "
    << sigma_min << ", damped below " << opt.singular_value_threshold << ") and at t = " << t
    << " s the end-effector is " << error
    << " m off the line, which it cannot follow without turning the base; the freedom the task and the "
    << "held rows leave at t = 0 is in ";
  if (shares.empty()) m << "no joint";
  for (size_t i = 0; i < shares.size(); ++i)
    m << (i == 0 ? "" : ", ") << names[static_cast<size_t>(shares[i].second)] << " (" << 100 * shares[i].first
      << " %)";
  m << " (base-attitude = free turns the base)";
  return m.str();
}

/// The number of RK4 steps: at least one. The 1e-9 slack (a duration that is a whole number of steps
/// up to rounding) must not round a duration shorter than 1e-9 steps down to none -- a run without
/// a step would return the initial state with no Jacobian ever evaluated (min_singular_value = inf).
inline long capture_steps(const CaptureOptions& opt) {
  return std::max(1L, static_cast<long>(std::ceil(opt.duration / opt.step - 1e-9)));
}

}  // namespace detail

/// The free-floating RK4 integration of the capture run with its checks (see the notes after the includes).
/// Joint rates theta_dot = J_t^+ (x_d_dot + k_p e) + alpha qd_null (Eq. 30), qd_null from `policy`
/// (null_space.hpp), alpha in [0, 1] the largest factor that keeps every |theta_dot_k| <=
/// opt.max_joint_rate (1 when not limited; TaskSolver); the base velocity from zero momentum. Each
/// step checks (RunMonitors) the total momentum, the centre of mass, the tracking error at the
/// first stage, then the quaternion norm, finiteness and the joint limits of the new state; at T
/// the capture-point and orientation tolerances. Throws NumericalError (the messages start with
/// `where`). Runs crba many times.
template <class Policy>
CaptureResult integrate_capture(const CaptureProblem& pb, const CaptureTask& task, const CaptureOptions& opt,
                                const CaptureSetup& setup, Policy& policy,
                                const char* where = "plan_capture") {
  const Model& model = *pb.model;
  detail::CaptureRateField<Policy> field(pb, task, opt, setup, policy);
  Data& data = field.data;
  FreeFloatingRK4 rk4(model.n());
  RunMonitors monitors(model, where, std::max(10.0 * opt.tolerance, 1e-2));
  if (task.kind == CaptureTask::Kind::Pose)
    monitors.hint =
        "the point may be out of reach, or the gripper's turn to the final orientation cannot be followed "
        "along the line from this configuration";
  CaptureResult res;
  res.capture_point = setup.capture.x_cap;
  BasePose base = pb.base;
  base.orientation.normalize();
  Eigen::VectorXd theta = pb.theta;
  const long nsteps = detail::capture_steps(opt);
  const double h = opt.duration / static_cast<double>(nsteps);
  if (opt.record_series)
    res.series.push_back(detail::capture_sample(model, data, pb, setup, 0.0, base, theta));
  for (long k = 0; k < nsteps; ++k) {
    const double t = static_cast<double>(k) * h;
    rk4.begin(field, t, base, theta);  // data holds the kinematics of the current state
    monitors.check_motion(model, data, rk4.k_base[0], rk4.k_theta[0]);
    FFSR_TRY {
      monitors.check_tracking(setup.line.position(t) - frame_pose(model, data, pb.frame).p, setup.rows, t);
    } FFSR_CATCH(const NumericalError&) {
      if (setup.held_freedom.size() == 0 || field.first_damped_time < 0) FFSR_RETHROW;
      FFSR_THROW(NumericalError(detail::held_singularity_message(model, opt, setup, where, field.first_damped_time,
                                                            field.min_singular_value, t,
                                                            monitors.max_tracking_error)));
    }
    monitors.check_quaternion(rk4.finish(field, t, h, base, theta));
    monitors.check_state(model, base, theta, t + h);
    ++res.steps;
    if (opt.record_series && ((k + 1) % opt.record_every == 0 || k + 1 == nsteps))
      res.series.push_back(detail::capture_sample(model, data, pb, setup, t + h, base, theta));
    if (opt.progress) opt.progress(static_cast<double>(k + 1) / static_cast<double>(nsteps));
  }
  monitors.record(res);
  res.min_singular_value = field.min_singular_value;
  res.damped_steps = field.damped_steps;
  res.max_joint_rate = field.max_joint_rate;
  detail::finish_capture(model, data, pb, task, opt, setup, base, theta, res, where);
  return res;
}

/// The paper's null-space policy for a capture setup: gain rho = opt.gain, the objective, and for the
/// exact force the scale of F = f_scale M^(alpha/(alpha+1)). Shared by plan_capture and the capture
/// controller (control/capture_controller.hpp).
inline GradientPolicy gradient_policy(const CaptureProblem& pb, const CaptureOptions& opt,
                                      const CaptureSetup& setup) {
  GradientPolicy policy;
  policy.gain = opt.gain;
  policy.objective = opt.objective;
  policy.alpha = pb.contact.alpha;
  if (opt.objective == CaptureObjective::ExactMaxForce)
    policy.f_scale = max_force_exact(setup.capture.law, 1.0) * (pb.contact.alpha / (pb.contact.alpha + 1));
  return policy;
}

/// Plans the approach with the paper's method (see the notes after the includes): the line reference, the
/// gradient policy with gain rho, the RK4 integration. Throws InputError for bad arguments
/// (including rho != 0 on a task without a null space), NumericalError when the capture point is not
/// reached within the tolerance or a joint leaves its limits.
inline CaptureResult plan_capture(const CaptureProblem& pb, const CaptureTask& task,
                                  const CaptureOptions& opt) {
  const CaptureSetup setup = prepare_capture(pb, task, opt);
  GradientPolicy policy = gradient_policy(pb, opt, setup);
  return integrate_capture(pb, task, opt, setup, policy);
}

}  // namespace ffsr
