// ffsr/optimize/capture_manifold.hpp -- the capture manifold: the configurations that put the
// end-effector on the capture point at a fixed base pose, the residual that defines it, the
// projection onto it, and the inequality constraints a search on it may carry (the base-rate
// constraint here; the clearance, optimize/clearance.hpp).
#pragma once

#include "ffsr/optimize/capture.hpp"
#include "ffsr/optimize/detail/manifold_sampling.hpp"
#include "ffsr/optimize/objective.hpp"

#include <functional>
#include <limits>
#include <memory>
#include <vector>

// With the base at a given pose B (the pose at T), the capture manifold is
//   C(B) = { theta : c(theta) = 0, theta within the URDF's joint limits },
// c the task rows of [p_e(theta) - x_cap ; log(R_end R_e(theta)^T)], log the rotation vector (angle
// in [0, pi] times the axis): zero only at the wanted orientation, of norm pi for a gripper turned
// half a turn. The base is fixed there, so the constraint Jacobian is the task rows of J_m (the joint
// columns of J_bm, Eq. 2); for the orientation rows d log(R)/d omega = -J_r^-1(log R), the inverse
// right Jacobian of SO(3) (detail::rotation_log_rate, manifold_sampling.hpp). docs/branches.md.

namespace ffsr {

/// Optional inequality constraints g(theta) <= 0 of a search at a fixed base pose (the clearance of
/// optimize/clearance.hpp, the base rate below): `eval` writes the `count` values and, when grad is not null, their
/// gradients (row-major, count x n, as NLopt). A local optimum with some g > tolerance is dropped.
struct ManifoldInequalities {
  unsigned count = 0;
  std::function<void(const BasePose& base, const Eigen::VectorXd& theta, double* g, double* grad)> eval;
  double tolerance = 1e-6;
  /// plan_capture_global: a reaching run's configuration at T whose values exceed this is planned
  /// again from the constrained optimum at its base pose (the shooting loop); infinity: not checked.
  double reach_tolerance = std::numeric_limits<double>::infinity();
};

/// No configuration on the capture manifold satisfies the search's inequality constraints.
struct InfeasibleInequalitiesError : InputError {
  using InputError::InputError;
};

/// Both sets of inequalities, a's rows first (either may be null or empty: the other is returned),
/// with the smaller of the two tolerances.
inline std::shared_ptr<const ManifoldInequalities> combine_inequalities(
    std::shared_ptr<const ManifoldInequalities> a, std::shared_ptr<const ManifoldInequalities> b) {
  if (!a || a->count == 0) return b;
  if (!b || b->count == 0) return a;
  auto q = std::make_shared<ManifoldInequalities>();
  q->count = a->count + b->count;
  q->tolerance = std::min(a->tolerance, b->tolerance);
  q->reach_tolerance = std::min(a->reach_tolerance, b->reach_tolerance);
  q->eval = [a, b](const BasePose& base, const Eigen::VectorXd& theta, double* g, double* grad) {
    a->eval(base, theta, g, grad);  // grad row-major, one row of theta.size() per inequality
    b->eval(base, theta, g + a->count,
            grad ? grad + static_cast<std::ptrdiff_t>(a->count) * theta.size() : nullptr);
  };
  return q;
}

/// The task residual c(theta) at a fixed base pose and its Jacobian (see the notes after the includes).
/// Runs crba and frame_jacobian. Writes r (task rows) and, if J is given, J (rows x n).
inline void capture_residual(const Model& model, Data& data, const CaptureProblem& pb,
                             const CaptureTask& task, const CaptureSetup& s, const BasePose& base,
                             const Eigen::VectorXd& theta, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
  const int n = model.n();
  crba(model, data, base, theta);
  const Pose ee = frame_pose(model, data, pb.frame);
  Vector6 e;
  e.head<3>() = ee.p - s.capture.x_cap;
  e.tail<3>() = detail::rotation_log(s.capture.R_end * ee.R.transpose());
  const int m = task.rows();
  r.resize(m);
  for (int i = 0; i < m; ++i) r(i) = e(s.rows[static_cast<size_t>(i)]);
  if (!J) return;
  frame_jacobian(model, data, pb.frame);
  Eigen::MatrixXd Jm(6, n);
  Jm.topRows<3>() = data.J.topRightCorner(3, n);
  Jm.bottomRows<3>() = detail::rotation_log_rate(e.tail<3>()) * data.J.bottomRightCorner(3, n);
  J->resize(m, n);
  for (int i = 0; i < m; ++i) J->row(i) = Jm.row(s.rows[static_cast<size_t>(i)]);
}

namespace detail {

inline bool within_limits(const Model& model, const Eigen::VectorXd& theta) {
  for (int k = 0; k < model.n(); ++k) {
    const Joint& j = model.joint(k);
    if (theta(k) < j.lower - 1e-12 || theta(k) > j.upper + 1e-12) return false;
  }
  return true;
}

/// Damped Newton (Levenberg-Marquardt with step halving) on c(theta) = 0 at a fixed base pose.
/// Returns true and the projected theta when |c| <= tol within the iteration budget.
inline bool project_to_manifold(const Model& model, Data& data, const CaptureProblem& pb,
                                const CaptureTask& task, const CaptureSetup& s, const BasePose& base,
                                Eigen::VectorXd& theta, double tol, int max_iterations = 100) {
  Eigen::VectorXd r, r2, trial;
  Eigen::MatrixXd J;
  capture_residual(model, data, pb, task, s, base, theta, r, &J);
  double mu = 1e-4;
  for (int it = 0; it < max_iterations; ++it) {
    const double nr = r.norm();
    if (!std::isfinite(nr)) return false;
    if (nr <= tol) return true;
    const Eigen::MatrixXd JJt = J * J.transpose() + mu * Eigen::MatrixXd::Identity(J.rows(), J.rows());
    const Eigen::VectorXd step = -J.transpose() * JJt.ldlt().solve(r);
    double a = 1.0;
    bool improved = false;
    for (int ls = 0; ls < 20; ++ls, a *= 0.5) {
      trial = theta + a * step;
      capture_residual(model, data, pb, task, s, base, trial, r2, nullptr);
      if (r2.norm() < nr) {
        improved = true;
        break;
      }
    }
    if (!improved) return false;
    theta = trial;
    mu = a == 1.0 ? std::max(1e-12, mu * 0.1) : std::min(1.0, mu * 10);
    capture_residual(model, data, pb, task, s, base, theta, r, &J);
  }
  return r.norm() <= tol;
}

/// Joint-space distance (largest |a_k - b_k|) with continuous joints compared modulo 2 pi
/// (configuration_error of null_space.hpp).
inline double configuration_distance(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd e;
  detail::configuration_error(model, a, b, e);
  double d = 0;
  for (Eigen::Index k = 0; k < e.size(); ++k) d = std::max(d, std::abs(e(k)));
  return d;
}

/// True when every inequality of `q` (if any) is at most `tolerance` at theta (NaN is not).
inline bool inequalities_within(const ManifoldInequalities* q, const BasePose& base,
                                const Eigen::VectorXd& theta, double tolerance) {
  if (!q || q->count == 0) return true;
  std::vector<double> g(q->count);
  q->eval(base, theta, g.data(), nullptr);
  for (double v : g)
    if (!(v <= tolerance)) return false;
  return true;
}

/// True when the inequalities `q` (if any) hold at theta within their tolerance.
inline bool satisfies_inequalities(const ManifoldInequalities* q, const BasePose& base,
                                   const Eigen::VectorXd& theta) {
  return !q || inequalities_within(q, base, theta, q->tolerance);
}

/// True when some inequality of `q` exceeds its reach_tolerance at theta (a reached configuration).
inline bool exceeds_reach_tolerance(const ManifoldInequalities* q, const BasePose& base,
                                    const Eigen::VectorXd& theta) {
  return q && std::isfinite(q->reach_tolerance) && !inequalities_within(q, base, theta, q->reach_tolerance);
}

}  // namespace detail

namespace detail {

/// What the base-rate function reads: the problem at a fixed base pose, a workspace, the law's
/// restitution e and the scale of the rate.
struct BaseRateContext {
  const CaptureProblem* pb = nullptr;
  const CaptureSetup* setup = nullptr;
  const BasePose* base = nullptr;
  Data* data = nullptr;
  double restitution = 0, scale = 1;
  long evaluations = 0;
  Eigen::VectorXd theta;
};

/// |Delta w_0| at theta (the base fixed): the jump of the base's angular rate per the impulse
/// P = M_ie delta_dot^- (1 + e), both of the problem's joint model (CaptureEvaluator). Writes M
/// (M_ie). Runs crba.
inline double base_rate(const BaseRateContext& c, const Eigen::VectorXd& theta, double& M) {
  crba(*c.pb->model, *c.data, *c.base, theta);
  Vector6 b;
  M = CaptureEvaluator(*c.pb, *c.setup).mass_and_base_response_at(*c.data, b);
  const double P = M * approach_velocity(c.setup->capture.law) * (1.0 + c.restitution);
  return P * b.tail<3>().norm();
}

/// (|Delta w_0| / scale)^2 and its central-difference gradient (step 1e-6 rad), NLopt's signature.
inline double base_rate2(unsigned n, const double* x, double* grad, void* p) {
  auto& c = *static_cast<BaseRateContext*>(p);
  ++c.evaluations;
  c.theta = Eigen::Map<const Eigen::VectorXd>(x, n);
  auto f = [&](const Eigen::VectorXd& th) {
    double M = 0;
    const double r = base_rate(c, th, M);
    return (r / c.scale) * (r / c.scale);
  };
  const double value = f(c.theta);
  if (grad) {
    const double h = 1e-6;
    for (unsigned k = 0; k < n; ++k) {
      Eigen::VectorXd t = c.theta;
      t(k) += h;
      const double fp = f(t);
      t(k) -= 2 * h;
      grad[k] = (fp - f(t)) / (2 * h);
    }
  }
  return value;
}

/// (|Delta w_0| / scale)^2 - 1 <= 0: the base-rate constraint, NLopt's signature.
inline double base_rate_constraint(unsigned n, const double* x, double* grad, void* p) {
  return base_rate2(n, x, grad, p) - 1.0;
}

}  // namespace detail

/// The base-rate constraint of a capture search: ((|Delta w_0| / max_rate)^2 - 1 <= 0 at the search's
/// base pose, with the restitution of the law; gradient by central differences as in the sweep), the
/// epsilon-constraint of the front as a ManifoldInequalities for search_capture_manifold and
/// plan_capture_global: their least M_ie under it is the front's point at eps = max_rate, and the
/// reaching planner plans to it as to the unconstrained optimum. max_rate in rad/s, > 0.
inline std::shared_ptr<const ManifoldInequalities> base_rate_inequality(const CaptureProblem& pb,
                                                                        const CaptureSetup& s,
                                                                        double max_rate) {
  if (!pb.model) throw InputError("base_rate_inequality: no model");
  if (!(max_rate > 0) || !std::isfinite(max_rate))
    throw InputError(detail::str(
        "base_rate_inequality: the largest base rate must be positive and finite, got ", max_rate));
  auto q = std::make_shared<ManifoldInequalities>();
  q->count = 1;
  q->tolerance = 1e-6;          // relative: (rate / max)^2 - 1
  q->reach_tolerance = 0.0201;  // a reached configuration: rate <= 1.01 max
  // the constraint function on a context of its own (the searches call it one at a time)
  struct Context {
    CaptureProblem pb;
    CaptureSetup s;
    Data data;
    detail::BaseRateContext ctx{};
  };
  auto c = std::make_shared<Context>(Context{pb, s, Data(*pb.model), {}});
  c->ctx.pb = &c->pb;
  c->ctx.setup = &c->s;
  c->ctx.data = &c->data;
  c->ctx.restitution = single_body_restitution(s.capture.law);
  c->ctx.scale = max_rate;
  q->eval = [c](const BasePose& base, const Eigen::VectorXd& theta, double* g, double* grad) {
    c->ctx.base = &base;
    g[0] = detail::base_rate_constraint(static_cast<unsigned>(theta.size()), theta.data(), grad, &c->ctx);
  };
  return q;
}

}  // namespace ffsr
