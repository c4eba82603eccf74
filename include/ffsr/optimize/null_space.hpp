// ffsr/optimize/null_space.hpp -- the null-space policies: the second term of Eq. 30.
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/optimize/capture_problem.hpp"
#include "ffsr/optimize/objective.hpp"

#include <cmath>

// A policy gives the joint rates the robot moves with inside the null space of its task,
// qd_null = N v (N the projector of task_solver.hpp), on top of the task rates J_t^+ (x_d_dot + k_p e).
// The capture run calls it at every evaluation of the joint-rate field, after crba, frame_jacobian
// and generalized_jacobian at (base, theta), and only when active(). Interface:
//   bool active() const;
//   void operator()(const Model&, Data&, const CaptureProblem&, const CaptureSetup&, double t,
//                   const BasePose& base, const Eigen::VectorXd& theta, const Eigen::MatrixXd& N,
//                   Eigen::VectorXd& qd_null);
// It writes qd_null (size n, N applied) and must leave data.H that of (base, theta) (the base
// velocity from zero momentum reads it afterwards).

namespace ffsr {

namespace detail {

/// The joint-limit repulsion added to an objective gradient `grad` (size n) at theta: for each joint
/// with finite limits, inside a margin of 10 % of its range from a limit, a term growing linearly
/// from 0 at the margin to `scale` at the limit, scale = max_k |grad_k| + 1 (taken before the joint's
/// own term), with the sign that a descent (rho < 0) moves away from the limit. Reads the model's
/// limits. Writes grad.
inline void add_joint_limit_repulsion(const Model& model, const Eigen::VectorXd& theta,
                                      Eigen::VectorXd& grad) {
  for (int k = 0; k < model.n(); ++k) {
    const Joint& j = model.joint(k);
    if (!(std::isfinite(j.lower) && std::isfinite(j.upper))) continue;
    const double margin = 0.1 * (j.upper - j.lower), q = theta(k);
    const double scale = grad.cwiseAbs().maxCoeff() + 1.0;
    if (q < j.lower + margin) grad(k) -= scale * (j.lower + margin - q) / margin;
    if (q > j.upper - margin) grad(k) += scale * (q - (j.upper - margin)) / margin;
  }
}

/// theta_goal - theta, with the difference of a continuous joint (no finite limits) wrapped to
/// [-pi, pi] (the shorter way round). Writes err (size n).
inline void configuration_error(const Model& model, const Eigen::VectorXd& theta_goal,
                                const Eigen::VectorXd& theta, Eigen::VectorXd& err) {
  err = theta_goal - theta;
  for (int k = 0; k < model.n(); ++k) {
    const Joint& j = model.joint(k);
    if (!std::isfinite(j.lower) && !std::isfinite(j.upper)) err(k) = std::remainder(err(k), 2 * kPi);
  }
}

}  // namespace detail

/// The paper's policy (Eq. 30-31): rho N phi, phi the analytic gradient of the objective (M_ie of
/// Eq. 14, or the exact maximum force, a monotone function of it: dF/dtheta = f_scale
/// M_ie^(-1/(alpha+1)) dM_ie/dtheta) at the current base pose, plus the joint-limit repulsion
/// (detail::add_joint_limit_repulsion), M_ie under the problem's joint model (pb.joints). Reads data
/// at (base, theta) as crba left it (the rate field runs crba there first):
/// CaptureEvaluator::mass_gradient_at. Writes data.L, data.w, data.y, data.V, data.F, grad and qd_null.
struct GradientPolicy {
  double gain = 0.0;  ///< rho
  CaptureObjective objective = CaptureObjective::IntegratedEffectiveMass;
  double f_scale = 1.0, alpha = 1.5;  ///< exact force: F = f_scale M^(alpha/(alpha+1)) (Eq. 16 scaling)
  Eigen::VectorXd grad;               ///< phi of the last call (workspace)
  bool active() const { return gain != 0.0; }
  void operator()(const Model& model, Data& data, const CaptureProblem& pb, const CaptureSetup& s,
                  double /*t*/, const BasePose& /*base: data is at it*/, const Eigen::VectorXd& theta,
                  const Eigen::MatrixXd& Nproj, Eigen::VectorXd& qd_null) {
    grad.resize(model.n());
    const double M = CaptureEvaluator(pb, s).mass_gradient_at(data, grad);
    if (objective == CaptureObjective::ExactMaxForce)
      grad *= f_scale * std::pow(M, -1.0 / (alpha + 1));  // dF/dM dM/dtheta
    detail::add_joint_limit_repulsion(model, theta, grad);
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
/// along the shorter way round (detail::configuration_error). The joint-rate limit of
/// CaptureOptions scales this term down, never the task's. Reads the model's limits. Writes err and
/// qd_null; leaves data untouched.
struct ServoPolicy {
  Eigen::VectorXd theta_goal;
  double gain = 0.0;    ///< k, 1/s; 0: 10 / T
  Eigen::VectorXd err;  ///< theta_goal - theta of the last call (workspace)
  bool active() const { return theta_goal.size() > 0; }
  void operator()(const Model& model, Data&, const CaptureProblem&, const CaptureSetup& s, double,
                  const BasePose&, const Eigen::VectorXd& theta, const Eigen::MatrixXd& Nproj,
                  Eigen::VectorXd& qd_null) {
    detail::configuration_error(model, theta_goal, theta, err);
    const double k_s = gain > 0 ? gain : 10.0 / s.line.duration;
    qd_null.noalias() = k_s * (Nproj * err);
  }
};

}  // namespace ffsr
