// ffsr/optimize/capture.hpp -- the capture approach and its null-space optimization (Section 4).
//
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
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/contact/contact_law.hpp"

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace ffsr {

/// What the end-effector must follow.
struct CaptureTask {
  enum class Kind { Position, Pose };
  Kind kind = Kind::Position;
  /// Position task: which inertial axes are constrained (x, y, z). The planar robot uses x and y.
  std::array<bool, 3> axes{true, true, true};
  /// Pose task: final end-effector orientation (inertial), reached by slerp; empty: hold the initial one.
  std::optional<Matrix3> final_orientation;
  /// Number of task rows.
  int rows() const {
    if (kind == Kind::Pose) return 6;
    return int(axes[0]) + int(axes[1]) + int(axes[2]);
  }
};

enum class CaptureObjective { IntegratedEffectiveMass, ExactMaxForce };

struct CaptureOptions {
  double duration = 180.0;              ///< T, s
  double step = 0.1;                    ///< RK4 step, s
  double gain = 0.0;                    ///< rho of Eq. 30 (< 0 lowers the objective; 0: plain tracking)
  double feedback = 1.0;                ///< k_p, 1/s, on the position (m) and orientation (rad) error
  double tolerance = 1e-3;              ///< required end-effector position error at T, m
  double orientation_tolerance = 1e-2;  ///< pose task: required orientation error at T, rad
  CaptureObjective objective = CaptureObjective::IntegratedEffectiveMass;
  double singular_value_threshold = 1e-3;  ///< below it the pseudo-inverse is damped
  double max_damping = 1e-2;               ///< largest damping (lambda) of the damped least squares
  bool record_series = false;
  int record_every = 1;                  ///< keep every k-th step in the series
  std::function<void(double)> progress;  ///< called with the fraction done (0..1), optional
  double max_joint_rate = 0;  ///< rad/s; the null-space term is scaled down to respect it (0: not limited)
};

/// The capture problem: robot, end-effector, initial state, target (its initial state at t = 0),
/// contact law and approach speed at the capture.
struct CaptureProblem {
  const Model* model = nullptr;
  int frame = -1;
  BasePose base;
  Eigen::VectorXd theta;
  Target target;
  ContactParams contact;
  std::string law = "herbert-mcwhannell";
  double approach_speed = 0.2;
};

struct CaptureSample {
  double t = 0;
  Eigen::VectorXd theta;
  BasePose base;
  Vector3 end_effector = Vector3::Zero();
  double M_ie = 0;            ///< with the target at the capture time
  double f_max_estimate = 0;  ///< closed-form F_max at that M_ie
};

struct CaptureResult {
  Eigen::VectorXd theta;  ///< capture configuration (rad)
  BasePose base;          ///< base pose at T
  Vector3 end_effector = Vector3::Zero();
  Vector3 capture_point = Vector3::Zero();
  double tracking_error = 0;       ///< |p_e(T) - capture point| on the task's constrained axes, m
  double capture_distance = 0;     ///< |p_e(T) - capture point| in 3-D (differs for a task on fewer axes), m
  double orientation_error = 0;    ///< pose task: angle between the reached and desired orientation, rad
  double base_position_drift = 0;  ///< |p_0(T) - p_0(0)|, m
  double base_attitude_drift = 0;  ///< rotation angle between the base attitudes at 0 and T, rad
  double M_ie = 0;
  double approach_velocity = 0;  ///< delta_dot^- at the capture
  double f_max_closed_form = 0;
  double f_max_exact = 0;
  double max_momentum = 0;          ///< largest |total momentum| along the run (checked each step)
  double max_body_momentum = 0;     ///< largest |body momentum| along the run, for scale
  double max_quaternion_error = 0;  ///< largest | |q| - 1 | before renormalization
  double max_com_drift = 0;         ///< largest motion of the system centre of mass (zero momentum: ~0)
  double max_tracking_error = 0;    ///< largest end-effector position error along the line, m
  double min_singular_value = 0;    ///< smallest task singular value seen
  long damped_steps = 0;            ///< evaluations where the pseudo-inverse was damped
  double max_joint_rate = 0;        ///< largest |theta_dot_k| over every evaluation, rad/s
  long steps = 0;
  std::vector<CaptureSample> series;
};

/// The target at time t: centre of mass drifting with its velocity, attitude and spin from the
/// torque-free Euler equations (RK4 with a fine step; exact rotation when the inertia is isotropic).
inline Target propagate_target(const Target& t0, double t) {
  Target t1 = t0;
  t1.position = t0.position + t0.velocity * t;
  const Matrix3 I = t0.inertia;
  const bool isotropic = (I - I(0, 0) * Matrix3::Identity()).cwiseAbs().maxCoeff() <= 1e-12 * I(0, 0);
  if (isotropic || t0.angular_velocity.norm() == 0.0) {
    t1.attitude = Quaternion(t0.rotation() * rotation_from_vector(t0.angular_velocity * t));
    return t1;
  }
  const Matrix3 Iinv = I.inverse();
  const long nsteps = std::max<long>(1, static_cast<long>(std::ceil(std::abs(t) / 1e-3)));
  if (nsteps > 100000000) throw InputError("propagate_target: time span too long");
  const double h = t / static_cast<double>(nsteps);
  Matrix3 R = t0.rotation();
  Vector3 w = t0.angular_velocity;  // body frame
  auto wdot = [&](const Vector3& x) { return Vector3(Iinv * (-x.cross(I * x))); };
  for (long k = 0; k < nsteps; ++k) {
    const Vector3 k1 = wdot(w), k2 = wdot(w + 0.5 * h * k1), k3 = wdot(w + 0.5 * h * k2),
                  k4 = wdot(w + h * k3);
    const Vector3 wn = w + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    R = R * rotation_from_vector(0.5 * h * (w + wn));  // midpoint rotation, body frame
    w = wn;
  }
  t1.attitude = Quaternion(R);
  t1.angular_velocity = w;
  return t1;
}

namespace detail {

/// log of a rotation matrix as a rotation vector.
inline Vector3 rotation_log(const Matrix3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

/// Quintic time law s(tau) and its derivative, tau in [0, 1].
inline void quintic(double tau, double& s, double& sdot) {
  tau = std::clamp(tau, 0.0, 1.0);
  s = tau * tau * tau * (10 - 15 * tau + 6 * tau * tau);
  sdot = 30 * tau * tau * (1 - 2 * tau + tau * tau);
}

}  // namespace detail

/// The straight-line reference of Section 4: the end-effector goes from x0 to the capture point
/// x_cap along a line with the quintic time law s(t/T), and (pose task) its orientation turns from
/// R0 to R_end about one fixed axis (rot_total = log(R_end R0^T)) with the same law.
struct LineReference {
  Vector3 x0 = Vector3::Zero(), x_cap = Vector3::Zero();
  Matrix3 R0 = Matrix3::Identity();
  Vector3 rot_total = Vector3::Zero();
  double duration = 1.0;
  /// Desired position and velocity at time t; for a pose task also the orientation and angular velocity.
  void at(double t, Vector3& xd, Vector3& vd, Matrix3& Rd, Vector3& wd) const {
    double s, sdot;
    detail::quintic(t / duration, s, sdot);
    sdot /= duration;
    xd = x0 + s * (x_cap - x0);
    vd = sdot * (x_cap - x0);
    Rd = rotation_from_vector(s * rot_total) * R0;
    wd = sdot * rot_total;
  }
  /// Desired position only.
  Vector3 position(double t) const {
    double s, sdot;
    detail::quintic(t / duration, s, sdot);
    return x0 + s * (x_cap - x0);
  }
};

/// Everything a capture run needs that follows from the problem: the target at T, the capture point
/// and direction, the contact law at the capture's approach velocity, the line reference and the task
/// rows. Made (and every input checked) by prepare_capture.
struct CaptureSetup {
  Target capture_target;             ///< the target at T
  Vector3 x_cap = Vector3::Zero();   ///< capture point
  Vector3 u_cap = Vector3::UnitX();  ///< inertial contact normal at T
  double target_inv_mass = 0;        ///< the target's inverse mass along the normal (Eq. 14)
  double v_in = 0;                   ///< delta_dot^- at the capture
  AnyContactLaw law;
  LineReference line;
  Matrix3 R_end = Matrix3::Identity();  ///< pose task: the end-effector orientation at T
  std::vector<int> rows;                ///< rows of J_f (and of the 6-D error) that the task constrains
};

/// Checks the problem, task and options (the errors of plan_capture, named after `where`) and builds
/// the capture setup. Runs crba at the initial state.
inline CaptureSetup prepare_capture(const CaptureProblem& pb, const CaptureTask& task,
                                    const CaptureOptions& opt, const char* where = "plan_capture") {
  using detail::str;
  if (!pb.model) throw InputError(str(where, ": no model"));
  const Model& model = *pb.model;
  const int n = model.n();
  detail::check_configuration(model, pb.base, pb.theta, where);
  if (pb.frame < 0 || pb.frame >= static_cast<int>(model.frames().size()))
    throw InputError(str(where, ": end-effector frame out of range"));
  pb.target.validate(str(where, ": target").c_str());
  validate(pb.contact, where);
  auto positive = [&](double x, const char* what) {
    if (!std::isfinite(x) || x <= 0)
      throw InputError(str(where, ": ", what, " must be positive and finite, got ", x));
  };
  positive(opt.duration, "duration");
  positive(opt.step, "step");
  positive(opt.tolerance, "tolerance");
  positive(opt.orientation_tolerance, "orientation tolerance");
  positive(opt.singular_value_threshold, "singular value threshold");
  detail::require_finite(opt.gain, where, "gain rho");
  detail::require_finite(opt.feedback, where, "feedback gain");
  if (opt.feedback < 0) throw InputError(str(where, ": feedback gain must be >= 0"));
  if (!std::isfinite(opt.max_joint_rate) || opt.max_joint_rate < 0)
    throw InputError(str(where, ": max joint rate must be >= 0 (0: not limited), got ", opt.max_joint_rate));
  if (opt.duration / opt.step > 1e7)
    throw InputError(
        str(where, ": duration / step = ", opt.duration / opt.step, " steps is too many (at most 1e7)"));
  if (opt.record_every < 1) throw InputError(str(where, ": record_every must be >= 1"));
  const int m = task.rows();
  if (m < 1) throw InputError(str(where, ": the task constrains no axis"));
  if (opt.gain != 0.0 && m >= n)
    throw InputError(str(where, ": the task has ", m, " rows and the robot ", n,
                         " joints: no null space to optimize in (use gain 0 or a smaller task)"));

  // The capture: the target's contact point, normal and attitude at T.
  CaptureSetup s{propagate_target(pb.target, opt.duration),
                 {},
                 {},
                 0,
                 0,
                 make_contact_law("hunt-crossley", ContactParams{}, 1.0),
                 {},
                 {},
                 {}};
  s.x_cap = s.capture_target.contact_point();
  s.u_cap = s.capture_target.normal_world();
  s.target_inv_mass = s.capture_target.inverse_mass_along_normal();
  s.v_in = approach_velocity(s.u_cap, Vector3(pb.approach_speed * s.u_cap), s.capture_target.velocity,
                             s.capture_target.angular_velocity_world(), s.capture_target.offset_world());
  if (!(s.v_in > 0))
    throw InputError(
        str(where, ": at the capture the end-effector does not approach the target (delta_dot^- = ", s.v_in,
            " m/s); increase the approach speed"));
  s.law = make_contact_law(pb.law, pb.contact, s.v_in);

  Data data(model);
  crba(model, data, pb.base, pb.theta);
  const Pose ee0 = frame_pose(model, data, pb.frame);
  s.R_end = task.final_orientation ? *task.final_orientation : ee0.R;
  s.line = {ee0.p, s.x_cap, ee0.R, detail::rotation_log(s.R_end * ee0.R.transpose()), opt.duration};
  if (task.kind == CaptureTask::Kind::Pose) {
    for (int r = 0; r < 6; ++r) s.rows.push_back(r);
  } else {
    for (int r = 0; r < 3; ++r)
      if (task.axes[static_cast<size_t>(r)]) s.rows.push_back(r);
  }
  return s;
}

// --- null-space policies: the second term of Eq. 30 -----------------------------------------------
// A policy is called at every evaluation of the joint-rate field, after crba, frame_jacobian and
// generalized_jacobian at (base, theta), with the null-space projector N of the task rows. It writes
// the null-space joint rates (N applied) into `qd_null` and must leave data.H that of (base, theta).

/// The paper's policy (Eq. 30-31): rho N phi, phi the analytic gradient of the objective (M_ie, or
/// the exact maximum force, a monotone function of it) at the current base pose, plus a repulsive
/// gradient inside 10 % of the range of a limited joint.
struct GradientPolicy {
  double gain = 0.0;  ///< rho
  CaptureObjective objective = CaptureObjective::IntegratedEffectiveMass;
  double f_scale = 1.0, alpha = 1.5;  ///< exact force: F = f_scale M^(alpha/(alpha+1)) (Eq. 16 scaling)
  Eigen::VectorXd grad;
  bool active() const { return gain != 0.0; }
  void operator()(const Model& model, Data& data, const CaptureProblem& pb, const CaptureSetup& s,
                  double /*t*/, const BasePose& base, const Eigen::VectorXd& theta,
                  const Eigen::MatrixXd& Nproj, Eigen::VectorXd& qd_null) {
    const int n = model.n();
    grad.resize(n);
    integrated_effective_mass_gradient(model, data, base, theta, pb.frame, s.u_cap, s.target_inv_mass, grad);
    if (objective == CaptureObjective::ExactMaxForce) {
      const double M = 1.0 / (data.w.dot(data.y) + s.target_inv_mass);  // y = H^-1 w after the gradient
      grad *= f_scale * std::pow(M, -1.0 / (alpha + 1));                // dF/dM dM/dtheta
    }
    // joint limits: repulsive gradient inside 10 % of the range
    for (int k = 0; k < n; ++k) {
      const Joint& j = model.joint(k);
      if (!(std::isfinite(j.lower) && std::isfinite(j.upper))) continue;
      const double margin = 0.1 * (j.upper - j.lower), q = theta(k);
      const double scale = grad.cwiseAbs().maxCoeff() + 1.0;
      if (q < j.lower + margin) grad(k) -= scale * (j.lower + margin - q) / margin;
      if (q > j.upper - margin) grad(k) += scale * (q - (j.upper - margin)) / margin;
    }
    qd_null.noalias() = gain * (Nproj * grad);
  }
};

/// Servo to a chosen capture configuration theta_goal: N k (theta_goal - theta), with k = 10 / T.
/// Why this design: the task keeps priority, so the only freedom is the null space; a first-order
/// servo there makes the null-space part of the error decay like exp(-k t), i.e. by a factor e^-10
/// by T whatever the path, and it needs no objective gradient, so the arm can cross the regions
/// where M_ie rises between the paper's basin and the global optimum (which no descent would).
/// At T the end-effector is on the capture point (task) and the null-space error is ~0, so the
/// arm is at theta_goal if theta_goal is on the capture manifold at the reached base pose; the
/// shooting loop of plan_capture_global makes that so. Continuous joints (no finite limits) servo
/// along the shorter way round (the difference wrapped to (-pi, pi]). The joint-rate limit of
/// CaptureOptions scales this term down, never the task's.
struct ServoPolicy {
  Eigen::VectorXd theta_goal;
  double gain = 0.0;  ///< k, 1/s; 0: 10 / T
  Eigen::VectorXd err;
  bool active() const { return theta_goal.size() > 0; }
  void operator()(const Model& model, Data&, const CaptureProblem&, const CaptureSetup& s, double,
                  const BasePose&, const Eigen::VectorXd& theta, const Eigen::MatrixXd& Nproj,
                  Eigen::VectorXd& qd_null) {
    err = theta_goal - theta;
    for (int k = 0; k < model.n(); ++k) {
      const Joint& j = model.joint(k);
      if (!std::isfinite(j.lower) && !std::isfinite(j.upper)) err(k) = std::remainder(err(k), 2 * M_PI);
    }
    const double k_s = gain > 0 ? gain : 10.0 / s.line.duration;
    qd_null.noalias() = k_s * (Nproj * err);
  }
};

/// The free-floating RK4 integration of the capture run with its checks (see the top of the file).
/// Joint rates theta_dot = J_t^+ (x_d_dot + k_p e) + alpha qd_null (Eq. 30), qd_null from `policy`,
/// alpha in [0, 1] the largest factor that keeps every |theta_dot_k| <= opt.max_joint_rate (1 when
/// not limited); the base velocity from zero momentum. Each step checks the total momentum, the
/// centre of mass, the tracking error, the quaternion norm, finiteness and the joint limits; at T
/// the capture-point and orientation tolerances. Throws NumericalError (the messages start with
/// `where`). Runs crba many times.
template <class Policy>
CaptureResult integrate_capture(const CaptureProblem& pb, const CaptureTask& task, const CaptureOptions& opt,
                                const CaptureSetup& setup, Policy& policy,
                                const char* where = "plan_capture") {
  using detail::str;
  const Model& model = *pb.model;
  const int n = model.n();
  const int m = task.rows();
  const std::vector<int>& rows = setup.rows;
  const Vector3& x_cap = setup.x_cap;
  const Vector3& u_cap = setup.u_cap;
  const double target_inv_mass = setup.target_inv_mass;
  const AnyContactLaw& law = setup.law;
  Data data(model);
  Eigen::MatrixXd Jt(m, n), Jpinv(n, m), Nproj(n, n);
  Eigen::VectorXd xdot(m), qd_null(n);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(m, n, Eigen::ComputeFullU | Eigen::ComputeFullV);

  CaptureResult res;
  res.capture_point = x_cap;
  res.min_singular_value = std::numeric_limits<double>::infinity();

  // joint-rate field: returns theta_dot and the base velocity for state (base, theta) at time t
  auto rates = [&](double t, const BasePose& base, const Eigen::VectorXd& theta, Eigen::VectorXd& theta_dot,
                   Vector6& xb) {
    crba(model, data, base, theta);
    frame_jacobian(model, data, pb.frame);
    generalized_jacobian(model, data);
    const Pose ee = frame_pose(model, data, pb.frame);
    Vector3 xd, vd, wd;
    Matrix3 Rd;
    setup.line.at(t, xd, vd, Rd, wd);
    Vector6 cmd;
    cmd.head<3>() = vd + opt.feedback * (xd - ee.p);
    if (task.kind == CaptureTask::Kind::Pose) {
      cmd.tail<3>() = wd + opt.feedback * detail::rotation_log(Rd * ee.R.transpose());
    } else {
      cmd.tail<3>().setZero();
    }
    for (int r = 0; r < m; ++r) {
      Jt.row(r) = data.Jf.row(rows[static_cast<size_t>(r)]);
      xdot(r) = cmd(rows[static_cast<size_t>(r)]);
    }
    svd.compute(Jt);
    const auto& sv = svd.singularValues();
    const double smin = sv(sv.size() - 1);
    res.min_singular_value = std::min(res.min_singular_value, smin);
    double lambda2 = 0;
    if (smin < opt.singular_value_threshold) {
      const double r = smin / opt.singular_value_threshold;
      lambda2 = (1 - r * r) * opt.max_damping * opt.max_damping;
      ++res.damped_steps;
    }
    Jpinv.setZero();
    for (Eigen::Index i = 0; i < sv.size(); ++i) {
      const double sigma = sv(i);
      const double g = lambda2 > 0 ? sigma / (sigma * sigma + lambda2) : (sigma > 1e-12 ? 1.0 / sigma : 0.0);
      Jpinv.noalias() += g * svd.matrixV().col(i) * svd.matrixU().col(i).transpose();
    }
    theta_dot.noalias() = Jpinv * xdot;
    if (policy.active()) {
      // null-space projector from the right singular vectors of the non-negligible singular values
      Nproj.setIdentity();
      for (Eigen::Index i = 0; i < sv.size(); ++i)
        if (sv(i) > 1e-12) Nproj.noalias() -= svd.matrixV().col(i) * svd.matrixV().col(i).transpose();
      policy(model, data, pb, setup, t, base, theta, Nproj, qd_null);
      if (opt.max_joint_rate > 0) {
        // the largest alpha in [0, 1] with |theta_dot_k + alpha qd_null_k| <= limit for every k
        const double L = opt.max_joint_rate;
        double a = 1.0;
        for (int k = 0; k < n; ++k) {
          const double b = qd_null(k), c = theta_dot(k);
          if (b > 0)
            a = std::min(a, (L - c) / b);
          else if (b < 0)
            a = std::min(a, (-L - c) / b);
        }
        qd_null *= std::max(a, 0.0);
      }
      theta_dot += qd_null;
    }
    res.max_joint_rate = std::max(res.max_joint_rate, theta_dot.cwiseAbs().maxCoeff());
    xb = base_velocity_from_momentum(model, data, theta_dot);  // data.H is H(base, theta)
  };

  // RK4 on (p0, q0, theta)
  BasePose base = pb.base;
  base.orientation.normalize();
  Eigen::VectorXd theta = pb.theta;
  // At least one step: the 1e-9 slack (a duration that is a whole number of steps up to rounding)
  // must not round a duration shorter than 1e-9 steps down to none -- a run without a step would
  // return the initial state with no Jacobian ever evaluated (min_singular_value = inf).
  const long nsteps = std::max(1L, static_cast<long>(std::ceil(opt.duration / opt.step - 1e-9)));
  const double h = opt.duration / static_cast<double>(nsteps);
  Eigen::VectorXd k_th[4] = {Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Vector6 k_b[4];
  Eigen::Vector4d k_q[4];
  auto quat_rate = [](const Quaternion& q, const Vector3& w) {  // q_dot = 1/2 [0, w] (x) q, w inertial
    const Quaternion wq(0, w.x(), w.y(), w.z());
    return Eigen::Vector4d(0.5 * (wq * q).coeffs());
  };
  auto stage = [](const BasePose& b, const Eigen::VectorXd& th, const Vector6& kb, const Eigen::Vector4d& kq,
                  const Eigen::VectorXd& kth, double a, BasePose& bo, Eigen::VectorXd& tho) {
    bo.position = b.position + a * kb.head<3>();
    bo.orientation.coeffs() = b.orientation.coeffs() + a * kq;
    tho = th + a * kth;
  };
  auto sample = [&](double t) {
    CaptureSample s;
    s.t = t;
    s.theta = theta;
    s.base = base;
    crba(model, data, base, theta);
    s.end_effector = frame_pose(model, data, pb.frame).p;
    s.M_ie = 1.0 / (inverse_effective_mass(model, data, pb.frame, u_cap) + target_inv_mass);
    s.f_max_estimate = max_force_closed_form(law, s.M_ie);
    res.series.push_back(std::move(s));
  };
  if (opt.record_series) sample(0.0);
  BasePose b2;
  Eigen::VectorXd th2(n), vgen(model.nv());
  Vector3 com0 = Vector3::Zero();
  const double divergence = std::max(10.0 * opt.tolerance, 1e-2);  // m: the line is lost
  for (long k = 0; k < nsteps; ++k) {
    const double t = static_cast<double>(k) * h;
    rates(t, base, theta, k_th[0], k_b[0]);
    // Checks on the first stage of every step (data holds the kinematics of the current state):
    // the total momentum of the commanded motion, the system centre of mass (it must not move when
    // the momentum is zero: an independent check of the integration), and the tracking error.
    {
      vgen << k_b[0], k_th[0];
      res.max_momentum = std::max(res.max_momentum, momentum(model, data, vgen).norm());
      for_each_body_velocity(
          model, data, vgen, [&](int i, const Vector3& w, const Vector3& vc, const Vector3&) {
            const Inertia& in = model.body(i).inertia;
            res.max_body_momentum = std::max(res.max_body_momentum, in.mass * vc.norm() + (in.I * w).norm());
          });
      const Vector3 com = data.p[0] + data.Ic[0].h / data.Ic[0].m;
      if (k == 0) com0 = com;
      res.max_com_drift = std::max(res.max_com_drift, (com - com0).norm());
      const Vector3 e = setup.line.position(t) - frame_pose(model, data, pb.frame).p;
      double err2 = 0;
      for (int r : rows)
        if (r < 3) err2 += e(r) * e(r);
      const double err = std::sqrt(err2);
      res.max_tracking_error = std::max(res.max_tracking_error, err);
      if (err > divergence)
        throw NumericalError(str(where,
                                 ": the end-effector cannot follow the line to the capture point (tracking "
                                 "error ",
                                 err, " m at t = ", t, " s); the point may be out of reach"));
    }
    k_q[0] = quat_rate(base.orientation, k_b[0].tail<3>());
    stage(base, theta, k_b[0], k_q[0], k_th[0], 0.5 * h, b2, th2);
    rates(t + 0.5 * h, b2, th2, k_th[1], k_b[1]);
    k_q[1] = quat_rate(b2.orientation, k_b[1].tail<3>());
    stage(base, theta, k_b[1], k_q[1], k_th[1], 0.5 * h, b2, th2);
    rates(t + 0.5 * h, b2, th2, k_th[2], k_b[2]);
    k_q[2] = quat_rate(b2.orientation, k_b[2].tail<3>());
    stage(base, theta, k_b[2], k_q[2], k_th[2], h, b2, th2);
    rates(t + h, b2, th2, k_th[3], k_b[3]);
    k_q[3] = quat_rate(b2.orientation, k_b[3].tail<3>());
    base.position += h / 6 * (k_b[0] + 2 * k_b[1] + 2 * k_b[2] + k_b[3]).head<3>();
    base.orientation.coeffs() += h / 6 * (k_q[0] + 2 * k_q[1] + 2 * k_q[2] + k_q[3]);
    theta += h / 6 * (k_th[0] + 2 * k_th[1] + 2 * k_th[2] + k_th[3]);
    res.max_quaternion_error = std::max(res.max_quaternion_error, std::abs(base.orientation.norm() - 1.0));
    base.orientation.normalize();
    if (!theta.allFinite() || !base.position.allFinite())
      throw NumericalError(str(where, ": the state became non-finite at t = ", t + h, " s"));
    for (int j = 0; j < n; ++j) {
      const Joint& jt = model.joint(j);
      if (theta(j) < jt.lower - 1e-9 || theta(j) > jt.upper + 1e-9)
        throw JointLimitError(str(where, ": joint '", jt.name, "' left its limits [", jt.lower, ", ",
                                  jt.upper, "] rad at t = ", t + h, " s (", theta(j), " rad)"));
    }
    ++res.steps;
    if (opt.record_series && ((k + 1) % opt.record_every == 0 || k + 1 == nsteps)) sample(t + h);
    if (opt.progress) opt.progress(static_cast<double>(k + 1) / static_cast<double>(nsteps));
  }

  crba(model, data, base, theta);
  const Pose ee = frame_pose(model, data, pb.frame);
  res.theta = theta;
  res.base = base;
  res.end_effector = ee.p;
  // the tracking error on the constrained position axes (all three for a pose task)
  double e2 = 0;
  for (int r : rows)
    if (r < 3) e2 += (ee.p(r) - x_cap(r)) * (ee.p(r) - x_cap(r));
  res.tracking_error = std::sqrt(e2);
  res.capture_distance = (ee.p - x_cap).norm();
  res.orientation_error =
      task.kind == CaptureTask::Kind::Pose ? rotation_angle(setup.R_end * ee.R.transpose()) : 0.0;
  res.base_position_drift = (base.position - pb.base.position).norm();
  res.base_attitude_drift = rotation_angle(base.orientation.toRotationMatrix() *
                                           pb.base.orientation.normalized().toRotationMatrix().transpose());
  res.M_ie = 1.0 / (inverse_effective_mass(model, data, pb.frame, u_cap) + target_inv_mass);
  res.approach_velocity = setup.v_in;
  res.f_max_closed_form = max_force_closed_form(law, res.M_ie);
  res.f_max_exact = max_force_exact(law, res.M_ie);
  if (!std::isfinite(res.M_ie) || !std::isfinite(res.f_max_exact) || !std::isfinite(res.f_max_closed_form))
    throw NumericalError(str(where, ": the capture configuration gives a non-finite M_ie or F_max"));
  if (res.tracking_error > opt.tolerance)
    throw NumericalError(str(where, ": the end-effector missed the capture point by ", res.tracking_error,
                             " m (tolerance ", opt.tolerance, " m); the point may be out of reach"));
  if (task.kind == CaptureTask::Kind::Pose && res.orientation_error > opt.orientation_tolerance)
    throw NumericalError(str(where, ": the end-effector orientation is off by ", res.orientation_error,
                             " rad at the capture (tolerance ", opt.orientation_tolerance, " rad)"));
  return res;
}

/// Plans the approach with the paper's method (see the top of this file): the line reference, the
/// gradient policy with gain rho, the RK4 integration. Throws InputError for bad arguments
/// (including rho != 0 on a task without a null space), NumericalError when the capture point is not
/// reached within the tolerance or a joint leaves its limits.
inline CaptureResult plan_capture(const CaptureProblem& pb, const CaptureTask& task,
                                  const CaptureOptions& opt) {
  const CaptureSetup setup = prepare_capture(pb, task, opt);
  GradientPolicy policy;
  policy.gain = opt.gain;
  policy.objective = opt.objective;
  policy.alpha = pb.contact.alpha;
  if (opt.objective == CaptureObjective::ExactMaxForce)
    policy.f_scale = max_force_exact(setup.law, 1.0) * (pb.contact.alpha / (pb.contact.alpha + 1));
  return integrate_capture(pb, task, opt, setup, policy);
}

}  // namespace ffsr
