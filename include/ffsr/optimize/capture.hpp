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
  double duration = 180.0;        ///< T, s
  double step = 0.1;              ///< RK4 step, s
  double gain = 0.0;              ///< rho of Eq. 30 (< 0 lowers the objective; 0: plain tracking)
  double feedback = 1.0;          ///< k_p, 1/s, on the position (m) and orientation (rad) error
  double tolerance = 1e-3;        ///< required end-effector position error at T, m
  double orientation_tolerance = 1e-2;  ///< pose task: required orientation error at T, rad
  CaptureObjective objective = CaptureObjective::IntegratedEffectiveMass;
  double singular_value_threshold = 1e-3;  ///< below it the pseudo-inverse is damped
  double max_damping = 1e-2;               ///< largest damping (lambda) of the damped least squares
  bool record_series = false;
  int record_every = 1;           ///< keep every k-th step in the series
  std::function<void(double)> progress;  ///< called with the fraction done (0..1), optional
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
  double M_ie = 0;          ///< with the target at the capture time
  double f_max_estimate = 0;  ///< closed-form F_max at that M_ie
};

struct CaptureResult {
  Eigen::VectorXd theta;      ///< capture configuration (rad)
  BasePose base;              ///< base pose at T
  Vector3 end_effector = Vector3::Zero();
  Vector3 capture_point = Vector3::Zero();
  double tracking_error = 0;  ///< |p_e(T) - capture point| on the task's constrained axes, m
  double capture_distance = 0;  ///< |p_e(T) - capture point| in 3-D (differs for a task on fewer axes), m
  double orientation_error = 0;  ///< pose task: angle between the reached and desired orientation, rad
  double base_position_drift = 0;   ///< |p_0(T) - p_0(0)|, m
  double base_attitude_drift = 0;   ///< rotation angle between the base attitudes at 0 and T, rad
  double M_ie = 0;
  double approach_velocity = 0;     ///< delta_dot^- at the capture
  double f_max_closed_form = 0;
  double f_max_exact = 0;
  double max_momentum = 0;          ///< largest |total momentum| along the run (checked each step)
  double max_body_momentum = 0;     ///< largest |body momentum| along the run, for scale
  double max_quaternion_error = 0;  ///< largest | |q| - 1 | before renormalization
  double max_com_drift = 0;         ///< largest motion of the system centre of mass (zero momentum: ~0)
  double max_tracking_error = 0;    ///< largest end-effector position error along the line, m
  double min_singular_value = 0;    ///< smallest task singular value seen
  long damped_steps = 0;            ///< evaluations where the pseudo-inverse was damped
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
    const Vector3 k1 = wdot(w), k2 = wdot(w + 0.5 * h * k1), k3 = wdot(w + 0.5 * h * k2), k4 = wdot(w + h * k3);
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

/// Plans the approach (see the top of this file). Throws InputError for bad arguments (including
/// rho != 0 on a task without a null space), NumericalError when the capture point is not reached
/// within the tolerance or a joint leaves its limits.
inline CaptureResult plan_capture(const CaptureProblem& pb, const CaptureTask& task, const CaptureOptions& opt) {
  using detail::str;
  if (!pb.model) throw InputError("plan_capture: no model");
  const Model& model = *pb.model;
  const int n = model.n();
  detail::check_configuration(model, pb.base, pb.theta, "plan_capture");
  if (pb.frame < 0 || pb.frame >= static_cast<int>(model.frames().size()))
    throw InputError("plan_capture: end-effector frame out of range");
  pb.target.validate("plan_capture: target");
  validate(pb.contact, "plan_capture");
  auto positive = [](double x, const char* what) {
    if (!std::isfinite(x) || x <= 0) throw InputError(str("plan_capture: ", what, " must be positive and finite, got ", x));
  };
  positive(opt.duration, "duration");
  positive(opt.step, "step");
  positive(opt.tolerance, "tolerance");
  positive(opt.orientation_tolerance, "orientation tolerance");
  positive(opt.singular_value_threshold, "singular value threshold");
  detail::require_finite(opt.gain, "plan_capture", "gain rho");
  detail::require_finite(opt.feedback, "plan_capture", "feedback gain");
  if (opt.feedback < 0) throw InputError("plan_capture: feedback gain must be >= 0");
  if (opt.duration / opt.step > 1e7) throw InputError(str("plan_capture: duration / step = ", opt.duration / opt.step, " steps is too many (at most 1e7)"));
  if (opt.record_every < 1) throw InputError("plan_capture: record_every must be >= 1");
  const int m = task.rows();
  if (m < 1) throw InputError("plan_capture: the task constrains no axis");
  if (opt.gain != 0.0 && m >= n)
    throw InputError(str("plan_capture: the task has ", m, " rows and the robot ", n,
                         " joints: no null space to optimize in (use gain 0 or a smaller task)"));

  // The capture: the target's contact point, normal and attitude at T.
  const Target capture_target = propagate_target(pb.target, opt.duration);
  const Vector3 x_cap = capture_target.contact_point();
  const Vector3 u_cap = capture_target.normal_world();
  const double target_inv_mass = capture_target.inverse_mass_along_normal();
  const double v_in = approach_velocity(u_cap, Vector3(pb.approach_speed * u_cap), capture_target.velocity,
                                        capture_target.angular_velocity_world(), capture_target.offset_world());
  if (!(v_in > 0))
    throw InputError(str("plan_capture: at the capture the end-effector does not approach the target (delta_dot^- = ",
                         v_in, " m/s); increase the approach speed"));
  const AnyContactLaw law = make_contact_law(pb.law, pb.contact, v_in);

  Data data(model);
  crba(model, data, pb.base, pb.theta);
  const Pose ee0 = frame_pose(model, data, pb.frame);
  const Vector3 x0 = ee0.p;
  const Matrix3 R_end = task.final_orientation ? *task.final_orientation : ee0.R;
  const Vector3 rot_total = detail::rotation_log(R_end * ee0.R.transpose());

  // task row selection
  std::vector<int> rows;
  if (task.kind == CaptureTask::Kind::Pose) {
    for (int r = 0; r < 6; ++r) rows.push_back(r);
  } else {
    for (int r = 0; r < 3; ++r)
      if (task.axes[static_cast<size_t>(r)]) rows.push_back(r);
  }
  Eigen::MatrixXd Jt(m, n), Jpinv(n, m), Nproj(n, n);
  Eigen::VectorXd xdot(m), grad(n), qd(n);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(m, n, Eigen::ComputeFullU | Eigen::ComputeFullV);

  CaptureResult res;
  res.capture_point = x_cap;
  res.min_singular_value = std::numeric_limits<double>::infinity();
  const double inv_T = 1.0 / opt.duration;
  const double f_scale = opt.objective == CaptureObjective::ExactMaxForce
                             ? max_force_exact(law, 1.0) * (pb.contact.alpha / (pb.contact.alpha + 1))
                             : 1.0;

  // joint-rate field: returns theta_dot and the base velocity for state (base, theta) at time t
  auto rates = [&](double t, const BasePose& base, const Eigen::VectorXd& theta, Eigen::VectorXd& theta_dot,
                   Vector6& xb) {
    crba(model, data, base, theta);
    frame_jacobian(model, data, pb.frame);
    generalized_jacobian(model, data);
    const Pose ee = frame_pose(model, data, pb.frame);
    double s, sdot;
    detail::quintic(t * inv_T, s, sdot);
    sdot *= inv_T;
    const Vector3 xd = x0 + s * (x_cap - x0);
    const Vector3 vd = sdot * (x_cap - x0);
    Vector6 cmd;
    cmd.head<3>() = vd + opt.feedback * (xd - ee.p);
    if (task.kind == CaptureTask::Kind::Pose) {
      const Matrix3 Rd = rotation_from_vector(s * rot_total) * ee0.R;
      cmd.tail<3>() = sdot * rot_total + opt.feedback * detail::rotation_log(Rd * ee.R.transpose());
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
    if (opt.gain != 0.0) {
      integrated_effective_mass_gradient(model, data, base, theta, pb.frame, u_cap, target_inv_mass, grad);
      if (opt.objective == CaptureObjective::ExactMaxForce) {
        const double M = 1.0 / (data.w.dot(data.y) + target_inv_mass);  // y = H^-1 w after the gradient
        grad *= f_scale * std::pow(M, -1.0 / (pb.contact.alpha + 1));  // dF/dM dM/dtheta
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
      // null-space projector from the right singular vectors of the non-negligible singular values
      Nproj.setIdentity();
      for (Eigen::Index i = 0; i < sv.size(); ++i)
        if (sv(i) > 1e-12) Nproj.noalias() -= svd.matrixV().col(i) * svd.matrixV().col(i).transpose();
      theta_dot.noalias() += opt.gain * (Nproj * grad);
    }
    xb = base_velocity_from_momentum(model, data, theta_dot);  // data.H is H(base, theta): the gradient re-ran crba there
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
      for_each_body_velocity(model, data, vgen, [&](int i, const Vector3& w, const Vector3& vc, const Vector3&) {
        const Inertia& in = model.body(i).inertia;
        res.max_body_momentum = std::max(res.max_body_momentum, in.mass * vc.norm() + (in.I * w).norm());
      });
      const Vector3 com = data.p[0] + data.Ic[0].h / data.Ic[0].m;
      if (k == 0) com0 = com;
      res.max_com_drift = std::max(res.max_com_drift, (com - com0).norm());
      double s, sdot;
      detail::quintic(t * inv_T, s, sdot);
      const Vector3 e = x0 + s * (x_cap - x0) - frame_pose(model, data, pb.frame).p;
      double err2 = 0;
      for (int r : rows)
        if (r < 3) err2 += e(r) * e(r);
      const double err = std::sqrt(err2);
      res.max_tracking_error = std::max(res.max_tracking_error, err);
      if (err > divergence)
        throw NumericalError(str("plan_capture: the end-effector cannot follow the line to the capture point (tracking "
                                 "error ", err, " m at t = ", t, " s); the point may be out of reach"));
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
      throw NumericalError(str("plan_capture: the state became non-finite at t = ", t + h, " s"));
    for (int j = 0; j < n; ++j) {
      const Joint& jt = model.joint(j);
      if (theta(j) < jt.lower - 1e-9 || theta(j) > jt.upper + 1e-9)
        throw NumericalError(str("plan_capture: joint '", jt.name, "' left its limits [", jt.lower, ", ", jt.upper,
                                 "] rad at t = ", t + h, " s (", theta(j), " rad)"));
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
  res.orientation_error = task.kind == CaptureTask::Kind::Pose ? rotation_angle(R_end * ee.R.transpose()) : 0.0;
  res.base_position_drift = (base.position - pb.base.position).norm();
  res.base_attitude_drift = rotation_angle(base.orientation.toRotationMatrix() *
                                           pb.base.orientation.normalized().toRotationMatrix().transpose());
  res.M_ie = 1.0 / (inverse_effective_mass(model, data, pb.frame, u_cap) + target_inv_mass);
  res.approach_velocity = v_in;
  res.f_max_closed_form = max_force_closed_form(law, res.M_ie);
  res.f_max_exact = max_force_exact(law, res.M_ie);
  if (res.tracking_error > opt.tolerance)
    throw NumericalError(str("plan_capture: the end-effector missed the capture point by ", res.tracking_error,
                             " m (tolerance ", opt.tolerance, " m); the point may be out of reach"));
  if (task.kind == CaptureTask::Kind::Pose && res.orientation_error > opt.orientation_tolerance)
    throw NumericalError(str("plan_capture: the end-effector orientation is off by ", res.orientation_error,
                             " rad at the capture (tolerance ", opt.orientation_tolerance, " rad)"));
  return res;
}

}  // namespace ffsr
