// ffsr/optimize/global.hpp -- the capture manifold search and the reaching planner.
//
// The paper's law (Eq. 30) descends the gradient of the objective in the null space, so it ends in
// the basin it starts in. Here the capture configuration is chosen first, globally, and the approach
// is planned to reach it:
//
// 1. Capture manifold. With the base at a given pose B (the pose at T), the configurations that put
//    the end-effector on the capture point (and, for a pose task, in the final orientation) are
//      C(B) = { theta : c(theta) = 0, theta within the URDF's joint limits },
//    c the task rows of [p_e(theta) - x_cap ; log(R_end R_e(theta)^T)], log the rotation vector
//    (angle in [0, pi] times the axis): zero only at the wanted orientation, of norm pi for a gripper
//    turned half a turn. The base is fixed there, so the constraint Jacobian is the task rows of J_m
//    (the joint columns of J_bm, Eq. 2); for the orientation rows d log(R)/d omega = -J_r^-1(log R),
//    the inverse right Jacobian of SO(3) (detail::rotation_log_rate, manifold_sampling.hxx).
// 2. Search (search_capture_manifold; docs/branches.md). Multistart: `starts` configurations drawn
//    uniformly within the limits ([-pi, pi] for a continuous joint) by std::mt19937_64 with our own
//    mapping to [0, 1) (so a seed gives the same draws on every platform), each put on C(B) by
//    damped Newton on c, then NLopt's SLSQP minimizes M_ie with its analytic gradient
//    (effective_mass.hpp) under the equality constraints c = 0. Then the branch stage:
//    `branch_starts` Halton points over the joint box, each projected onto C(B); with a null space
//    (more joints than task rows) a multi-level single-linkage rule picks which of them start SLSQP
//    (the lowest M_ie within `branch_radius`), at most `branch_local_searches`; without one (a
//    6-joint arm with a pose task: C(B) is a set of points, the inverse-kinematics solutions) every
//    projection is polished to |c| <= 1e-12 and the distinct ones are the branches. Revolute joints
//    with limits are moved by whole turns to the value nearest the initial configuration (one
//    configuration per posture). The distinct local optima are kept, sorted. For the
//    multibody-force objective, which has no gradient, the distinct local optima of M_ie are ranked
//    by the CVODE multibody peak (simulate/multibody.hpp), evaluated directly at each of them.
//    exact-force is a monotone function of M_ie (Eq. 16 scaling), so its optimum is M_ie's.
//    robust-force: SLSQP minimizes CVaR_95 of the exact F_max over a fixed set of
//    uncertain samples (uncertainty/robust_objective.hpp) with its analytic gradient, under the same
//    constraints; the optima are compared by that value.
// 3. Reaching (plan_capture_global). The same line reference and time law as the paper's method,
//    the task first, and the null space servoing to the chosen configuration (ServoPolicy in
//    null_space.hpp), with the joint-rate limit. The base pose at T depends on the path, so it shoots:
//    search at the base pose reached, plan again to the new optimum, until the reached objective is
//    within `gap_percent` of the manifold optimum at the reached base pose.
//
// Needs NLopt (and SUNDIALS CVODE for the multibody objective): the CMake target ffsr::global.
#pragma once

#include "ffsr/optimize/capture.hpp"
#include "ffsr/optimize/detail/manifold_sampling.hxx"
#include "ffsr/optimize/reconfigure.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "ffsr/uncertainty/robust_objective.hpp"

#include <nlopt.hpp>

#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <random>

namespace ffsr {

enum class GlobalObjective { Mass, ExactForce, MultibodyForce, RobustForce };

/// The objective's name as the command spells it.
inline const char* objective_name(GlobalObjective o) {
  switch (o) {
    case GlobalObjective::Mass:
      return "mass";
    case GlobalObjective::ExactForce:
      return "exact-force";
    case GlobalObjective::MultibodyForce:
      return "multibody-force";
    case GlobalObjective::RobustForce:
      return "robust-force";
  }
  return "?";
}

/// Optional inequality constraints g(theta) <= 0 of the search at a fixed base pose (the clearance of
/// geometry/clearance.hpp): `eval` writes the `count` values and, when grad is not null, their
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

struct ManifoldSearchOptions {
  int starts = 32;         ///< random starts of the multistart
  std::uint64_t seed = 1;  ///< seed of std::mt19937_64
  GlobalObjective objective = GlobalObjective::Mass;
  double constraint_tolerance = 1e-10;  ///< |c| accepted as on the manifold (m, rad)
  int max_local_evaluations = 300;      ///< SLSQP budget per start
  MultibodyContactOptions multibody;    ///< for the multibody-force objective
  int max_ranked = 8;                   ///< multibody-force: local optima ranked (the best by M_ie)
  /// robust-force: CVaR_95 of the exact F_max over this fixed sample set (robust_objective.hpp),
  /// minimized by SLSQP with its gradient. Shared by copies of the options; not thread-safe.
  std::shared_ptr<RobustForceObjective> robust;
  /// Branch stage of a full search (docs/branches.md): Halton starts projected onto the manifold
  /// (0: none); with a null space, SLSQP runs from those with the lowest M_ie within branch_radius
  /// (rad, Euclidean over the joints), at most branch_local_searches of them.
  int branch_starts = 256;
  double branch_radius = 0.5;
  int branch_local_searches = 24;
  std::shared_ptr<const ManifoldInequalities> inequalities;  ///< none: equality constraints only
};

/// A configuration on the capture manifold with its M_ie and objective value.
struct ManifoldPoint {
  Eigen::VectorXd theta;
  double M_ie = 0;
  double objective = 0;  ///< kg (mass) or N (exact-force, multibody-force, robust-force: CVaR_95)
};

struct ManifoldSearchResult {
  ManifoldPoint best;
  std::vector<ManifoldPoint>
      local_optima;  ///< distinct, sorted by M_ie (robust-force: by CVaR_95; multibody-force: objective 0 = not ranked)
  std::string method;
  int starts = 0;                  ///< starts drawn (plus extra starts given)
  int projected_starts = 0;        ///< starts that the projection put on the manifold
  long evaluations = 0;            ///< objective (M_ie and gradient) evaluations of SLSQP
  long objective_evaluations = 0;  ///< multibody-force: CVODE simulations
  double seconds = 0;
};

/// The task residual c(theta) at a fixed base pose and its Jacobian (see the top of this file).
/// Runs crba and frame_jacobian. Writes r (task rows) and, if J is given, J (rows x n).
inline void capture_residual(const Model& model, Data& data, const CaptureProblem& pb,
                             const CaptureTask& task, const CaptureSetup& s, const BasePose& base,
                             const Eigen::VectorXd& theta, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
  const int n = model.n();
  crba(model, data, base, theta);
  const Pose ee = frame_pose(model, data, pb.frame);
  Vector6 e;
  e.head<3>() = ee.p - s.x_cap;
  e.tail<3>() = detail::rotation_log(s.R_end * ee.R.transpose());
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

/// Uniform double in [0, 1) from the 53 high bits of a 64-bit draw (portable, unlike
/// std::uniform_real_distribution whose algorithm the standard leaves open).
inline double unit_uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

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

struct SlsqpContext {
  const Model* model;
  Data* data;
  const CaptureProblem* pb;
  const CaptureTask* task;
  const CaptureSetup* setup;
  const BasePose* base;
  RobustForceObjective* robust = nullptr;  ///< robust-force: the objective (else M_ie)
  long evaluations = 0;
  Eigen::VectorXd theta, g, r;
  Eigen::MatrixXd J;
  const ManifoldInequalities* inequalities = nullptr;
};

inline double slsqp_objective(unsigned n, const double* x, double* grad, void* p) {
  auto& c = *static_cast<SlsqpContext*>(p);
  ++c.evaluations;
  c.theta = Eigen::Map<const Eigen::VectorXd>(x, n);
  c.g.resize(n);
  if (c.robust) {
    const double f = c.robust->value_and_gradient(*c.model, *c.data, *c.base, c.theta, c.pb->frame, c.g);
    if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = c.g;
    return f;
  }
  const double M =
      integrated_effective_mass_gradient(*c.model, *c.data, *c.base, c.theta, c.pb->frame, c.setup->u_cap,
                                         c.setup->target_inv_mass, c.pb->joints, c.g);
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = c.g;
  return M;
}

inline void slsqp_constraints(unsigned m, double* result, unsigned n, const double* x, double* grad,
                              void* p) {
  auto& c = *static_cast<SlsqpContext*>(p);
  c.theta = Eigen::Map<const Eigen::VectorXd>(x, n);
  capture_residual(*c.model, *c.data, *c.pb, *c.task, *c.setup, *c.base, c.theta, c.r, grad ? &c.J : nullptr);
  Eigen::Map<Eigen::VectorXd>(result, m) = c.r;
  if (grad)  // NLopt: grad[i * n + j] = d c_i / d x_j (row-major)
    for (unsigned i = 0; i < m; ++i)
      for (unsigned j = 0; j < n; ++j) grad[i * n + j] = c.J(i, j);
}

inline void slsqp_inequalities(unsigned m, double* result, unsigned n, const double* x, double* grad,
                               void* p) {
  auto& c = *static_cast<SlsqpContext*>(p);
  c.theta = Eigen::Map<const Eigen::VectorXd>(x, n);
  (void)m;
  c.inequalities->eval(*c.base, c.theta, result, grad);
}

/// True when every inequality of `so` (if any) is at most `tolerance` at theta (NaN is not).
inline bool inequalities_within(const ManifoldSearchOptions& so, const BasePose& base,
                                const Eigen::VectorXd& theta, double tolerance) {
  if (!so.inequalities || so.inequalities->count == 0) return true;
  std::vector<double> g(so.inequalities->count);
  so.inequalities->eval(base, theta, g.data(), nullptr);
  for (double v : g)
    if (!(v <= tolerance)) return false;
  return true;
}

/// True when the inequalities of `so` (if any) hold at theta within their tolerance.
inline bool satisfies_inequalities(const ManifoldSearchOptions& so, const BasePose& base,
                                   const Eigen::VectorXd& theta) {
  return !so.inequalities || inequalities_within(so, base, theta, so.inequalities->tolerance);
}

/// True when some inequality of `so` exceeds its reach_tolerance at theta (a reached configuration).
inline bool exceeds_reach_tolerance(const ManifoldSearchOptions& so, const BasePose& base,
                                    const Eigen::VectorXd& theta) {
  return so.inequalities && std::isfinite(so.inequalities->reach_tolerance) &&
         !inequalities_within(so, base, theta, so.inequalities->reach_tolerance);
}

}  // namespace detail

/// Value of the objective at a capture configuration (base at T). Mass: M_ie (kg); exact-force:
/// the single-body peak (Eq. 16) at M_ie; multibody-force: the CVODE multibody peak; robust-force:
/// CVaR_95 of `robust` (required then). Runs crba (and CVODE for the multibody objective).
inline ManifoldPoint evaluate_capture(const CaptureProblem& pb, const CaptureSetup& s, const BasePose& base,
                                      const Eigen::VectorXd& theta, GlobalObjective objective,
                                      const MultibodyContactOptions& mo = {},
                                      RobustForceObjective* robust = nullptr) {
  const Model& model = *pb.model;
  Data data(model);
  crba(model, data, base, theta);
  ManifoldPoint p{
      theta, 1.0 / (inverse_effective_mass(model, data, pb.frame, s.u_cap, pb.joints) + s.target_inv_mass),
      0};
  switch (objective) {
    case GlobalObjective::Mass:
      p.objective = p.M_ie;
      break;
    case GlobalObjective::ExactForce:
      p.objective = max_force_exact(s.law, p.M_ie);
      break;
    case GlobalObjective::MultibodyForce:
      p.objective = simulate_contact(model, base, theta, pb.frame, s.capture_target, pb.approach_speed,
                                     pb.contact, pb.law, mo)
                        .f_max;
      break;
    case GlobalObjective::RobustForce:
      if (!robust) throw InputError("evaluate_capture: the robust-force objective needs its sample set");
      p.objective = robust->value(robot_inverse_inertia(model, data, base, theta, pb.frame)).cvar95;
      break;
  }
  return p;
}

/// Searches the capture manifold C(base) for the configuration of least objective (see the top of
/// this file). `extra_starts` are tried first (projected like the random ones). Throws InputError
/// for bad options or when no start can be put on the manifold (the capture point is out of reach
/// from this base pose). Deterministic for a given seed.
namespace detail {
/// search_capture_manifold with `random_starts` random starts (0: the extra starts only, the local
/// optima near them). Does not check the options.
inline ManifoldSearchResult search_manifold(const CaptureProblem& pb, const CaptureTask& task,
                                            const CaptureSetup& s, const BasePose& base,
                                            const ManifoldSearchOptions& so,
                                            const std::vector<Eigen::VectorXd>& extra_starts,
                                            int random_starts);
}  // namespace detail

inline ManifoldSearchResult search_capture_manifold(const CaptureProblem& pb, const CaptureTask& task,
                                                    const CaptureSetup& s, const BasePose& base,
                                                    const ManifoldSearchOptions& so,
                                                    const std::vector<Eigen::VectorXd>& extra_starts = {}) {
  using detail::str;
  if (!pb.model) throw InputError("search_capture_manifold: no model");
  detail::check_configuration(*pb.model, base, pb.theta, "search_capture_manifold");
  if (so.starts < 1) throw InputError(str("search_capture_manifold: starts must be >= 1, got ", so.starts));
  if (!(so.constraint_tolerance > 0))
    throw InputError("search_capture_manifold: constraint tolerance must be positive");
  if (so.max_local_evaluations < 1)
    throw InputError("search_capture_manifold: max_local_evaluations must be >= 1");
  if (so.max_ranked < 1) throw InputError("search_capture_manifold: max_ranked must be >= 1");
  if (so.branch_starts < 0 || so.branch_local_searches < 0 || !(so.branch_radius > 0))
    throw InputError(
        "search_capture_manifold: branch_starts and branch_local_searches must be >= 0, "
        "branch_radius positive");
  return detail::search_manifold(pb, task, s, base, so, extra_starts, so.starts);
}

namespace detail {

/// The starts of the multistart: `extra` first, then `count` configurations drawn uniformly within
/// the limits ([-pi, pi] for a continuous joint) by std::mt19937_64(seed) and unit_uniform.
inline std::vector<Eigen::VectorXd> manifold_starts(const Model& model, std::uint64_t seed,
                                                    const std::vector<Eigen::VectorXd>& extra, int count) {
  const int n = model.n();
  std::mt19937_64 rng(seed);
  std::vector<Eigen::VectorXd> starts = extra;
  for (int i = 0; i < count; ++i) {
    Eigen::VectorXd q(n);
    for (int k = 0; k < n; ++k) {
      const Joint& j = model.joint(k);
      const double lo = std::isfinite(j.lower) ? j.lower : -M_PI,
                   hi = std::isfinite(j.upper) ? j.upper : M_PI;
      q(k) = lo + (hi - lo) * detail::unit_uniform(rng);
    }
    starts.push_back(std::move(q));
  }
  return starts;
}

/// NLopt's SLSQP on the objective of `ctx` under the m equality constraints c = 0 (tolerance a
/// tenth of the search's), within the joint limits, with the search's evaluation budget.
inline void configure_slsqp(nlopt::opt& local, const Model& model, int m, SlsqpContext& ctx,
                            const ManifoldSearchOptions& so) {
  const int n = model.n();
  local.set_min_objective(detail::slsqp_objective, &ctx);
  local.add_equality_mconstraint(detail::slsqp_constraints, &ctx,
                                 std::vector<double>(static_cast<size_t>(m), so.constraint_tolerance * 0.1));
  std::vector<double> lb(static_cast<size_t>(n)), ub(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    lb[static_cast<size_t>(k)] = model.joint(k).lower;
    ub[static_cast<size_t>(k)] = model.joint(k).upper;
  }
  if (so.inequalities && so.inequalities->count > 0) {
    ctx.inequalities = so.inequalities.get();
    local.add_inequality_mconstraint(
        detail::slsqp_inequalities, &ctx,
        std::vector<double>(so.inequalities->count, so.inequalities->tolerance * 0.1));
  }
  local.set_lower_bounds(lb);
  local.set_upper_bounds(ub);
  local.set_xtol_rel(1e-10);
  local.set_ftol_rel(1e-12);
  local.set_maxeval(so.max_local_evaluations);
}

/// The local optimum from start q: projected on C(base), optimized by `local` (SLSQP), projected
/// again (a few Newton steps put SLSQP's point exactly on C), within the limits, with a finite M_ie.
/// Writes `out` (theta, M_ie, the value the optima are compared by: M_ie, or CVaR_95 for
/// robust-force) and returns true; false when the start or the optimum is not usable. Counts a
/// projected start in res.projected_starts.
inline bool local_capture_optimum(const Model& model, Data& data, const CaptureProblem& pb,
                                  const CaptureTask& task, const CaptureSetup& s, const BasePose& base,
                                  const ManifoldSearchOptions& so, nlopt::opt& local, Eigen::VectorXd q,
                                  ManifoldSearchResult& res, ManifoldPoint& out) {
  const int n = model.n();
  if (q.size() != n || !q.allFinite())
    throw InputError("search_capture_manifold: an extra start has the wrong size or is not finite");
  if (!detail::project_to_manifold(model, data, pb, task, s, base, q, so.constraint_tolerance)) return false;
  if (!detail::nearest_representative(model, pb.theta, q) || !detail::within_limits(model, q)) return false;
  ++res.projected_starts;
  std::vector<double> x(q.data(), q.data() + n);
  double f = 0;
  try {
    local.optimize(x, f);
  } catch (const nlopt::roundoff_limited&) {  // x holds the best point found: checked below
  } catch (const std::runtime_error&) {       // NLopt failure: keep the projected start
    x.assign(q.data(), q.data() + n);
  }
  Eigen::VectorXd th = Eigen::Map<const Eigen::VectorXd>(x.data(), n);
  if (!detail::project_to_manifold(model, data, pb, task, s, base, th, so.constraint_tolerance, 20))
    return false;
  if (!detail::nearest_representative(model, pb.theta, th) || !detail::within_limits(model, th) ||
      !detail::satisfies_inequalities(so, base, th))
    return false;
  crba(model, data, base, th);
  const double M =
      1.0 / (inverse_effective_mass(model, data, pb.frame, s.u_cap, pb.joints) + s.target_inv_mass);
  if (!std::isfinite(M)) return false;
  const double v = so.objective == GlobalObjective::RobustForce
                       ? so.robust->value(robot_inverse_inertia(model, data, base, th, pb.frame)).cvar95
                       : M;
  out = {th, M, v};
  return true;
}

/// Adds p to the distinct optima: within 1e-3 rad (configuration_distance) of a kept one, it
/// replaces that one if its objective is lower; else it is appended.
inline void keep_distinct(const Model& model, std::vector<ManifoldPoint>& found, const ManifoldPoint& p) {
  bool duplicate = false;
  for (ManifoldPoint& f : found)
    if (detail::configuration_distance(model, f.theta, p.theta) < 1e-3) {
      duplicate = true;
      if (p.objective < f.objective) f = p;
    }
  if (!duplicate) found.push_back(p);
}

/// The value the optima are compared by at a configuration on C(base): M_ie, or CVaR_95 for
/// robust-force. Writes M. Runs crba.
inline double manifold_value(const Model& model, Data& data, const CaptureProblem& pb, const CaptureSetup& s,
                             const BasePose& base, const ManifoldSearchOptions& so, const Eigen::VectorXd& th,
                             double& M) {
  crba(model, data, base, th);
  M = 1.0 / (inverse_effective_mass(model, data, pb.frame, s.u_cap) + s.target_inv_mass);
  return so.objective == GlobalObjective::RobustForce
             ? so.robust->value(robot_inverse_inertia(model, data, base, th, pb.frame)).cvar95
             : M;
}

/// Without a null space (as many task rows as joints) C(base) is a set of points, the
/// inverse-kinematics solutions: every start is projected (damped Newton to |c| <= 1e-12, or the
/// search's tolerance when roundoff stops it first), moved to the representative of its posture,
/// and kept when within the limits and more than 1e-6 rad (posture_distance) from every solution
/// kept. No SLSQP: each solution is its own local optimum. Appends to `found`; counts into res.
inline void enumerate_solutions(const Model& model, Data& data, const CaptureProblem& pb,
                                const CaptureTask& task, const CaptureSetup& s, const BasePose& base,
                                const ManifoldSearchOptions& so, const std::vector<Eigen::VectorXd>& starts,
                                ManifoldSearchResult& res, std::vector<ManifoldPoint>& found) {
  Eigen::VectorXd r;
  for (Eigen::VectorXd q : starts) {
    if (q.size() != model.n() || !q.allFinite())
      throw InputError("search_capture_manifold: an extra start has the wrong size or is not finite");
    if (!project_to_manifold(model, data, pb, task, s, base, q, 1e-12)) {
      capture_residual(model, data, pb, task, s, base, q, r, nullptr);
      if (!(r.norm() <= so.constraint_tolerance)) continue;
    }
    if (!nearest_representative(model, pb.theta, q) || !within_limits(model, q)) continue;
    ++res.projected_starts;
    bool known = false;
    for (const ManifoldPoint& f : found) known = known || posture_distance(model, f.theta, q) < 1e-6;
    if (known) continue;
    double M = 0;
    const double v = manifold_value(model, data, pb, s, base, so, q, M);
    if (std::isfinite(M)) found.push_back({q, M, v});
  }
}

/// Squared Euclidean distance between two postures (revolute joints modulo 2 pi); no allocation.
inline double posture_distance2(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double d = 0;
  for (int k = 0; k < model.n(); ++k) {
    double e = a(k) - b(k);
    if (model.joint(k).type == JointType::Revolute) e = std::remainder(e, 2 * M_PI);
    d += e * e;
  }
  return d;
}

/// The branch stage with a null space: so.branch_starts Halton points projected onto C(base) and
/// sorted by M_ie; multi-level single linkage (Rinnooy Kan and Timmer 1987) starts SLSQP
/// (local_capture_optimum) from a sample only when no sample of lower M_ie and no local optimum
/// found so far lies within so.branch_radius, at most so.branch_local_searches times. Appends the
/// distinct optima to `found`; counts into res.
inline void branch_stage(const Model& model, Data& data, const CaptureProblem& pb, const CaptureTask& task,
                         const CaptureSetup& s, const BasePose& base, const ManifoldSearchOptions& so,
                         nlopt::opt& local, ManifoldSearchResult& res, std::vector<ManifoldPoint>& found) {
  std::vector<ManifoldPoint> samples;
  for (Eigen::VectorXd q : halton_starts(model, so.branch_starts)) {
    if (!project_to_manifold(model, data, pb, task, s, base, q, so.constraint_tolerance)) continue;
    if (!nearest_representative(model, pb.theta, q) || !within_limits(model, q)) continue;
    double M = 0;
    crba(model, data, base, q);
    M = 1.0 / (inverse_effective_mass(model, data, pb.frame, s.u_cap) + s.target_inv_mass);
    if (std::isfinite(M)) samples.push_back({q, M, M});
  }
  std::stable_sort(samples.begin(), samples.end(),
                   [](const ManifoldPoint& a, const ManifoldPoint& b) { return a.M_ie < b.M_ie; });
  const double r2 = so.branch_radius * so.branch_radius;
  auto near = [&](const ManifoldPoint& a, const ManifoldPoint& b) {
    return posture_distance2(model, a.theta, b.theta) < r2;
  };
  int runs = 0;
  ManifoldPoint p;
  for (size_t i = 0; i < samples.size() && runs < so.branch_local_searches; ++i) {
    bool linked = false;
    for (size_t j = 0; j < i && !linked; ++j) linked = near(samples[j], samples[i]);
    for (size_t j = 0; j < found.size() && !linked; ++j) linked = near(found[j], samples[i]);
    if (linked) continue;
    ++runs;
    if (local_capture_optimum(model, data, pb, task, s, base, so, local, samples[i].theta, res, p))
      keep_distinct(model, found, p);
  }
}

/// Fills res.best and the objective of res.local_optima (sorted by the compared value): the CVODE
/// peak at the best max_ranked optima for multibody-force (0 for those not ranked), CVaR_95 as
/// compared for robust-force, M_ie or the exact F_max at it otherwise.
inline void rank_local_optima(const CaptureProblem& pb, const CaptureSetup& s, const BasePose& base,
                              const ManifoldSearchOptions& so, ManifoldSearchResult& res) {
  std::vector<ManifoldPoint>& found = res.local_optima;
  if (so.objective == GlobalObjective::MultibodyForce) {
    // no gradient: evaluate the CVODE peak directly at the best local optima of M_ie
    double best = std::numeric_limits<double>::infinity();
    const size_t k = std::min(found.size(), static_cast<size_t>(so.max_ranked));
    for (size_t i = 0; i < k; ++i) {
      ManifoldPoint p = evaluate_capture(pb, s, base, found[i].theta, so.objective, so.multibody);
      ++res.objective_evaluations;
      found[i].objective = p.objective;
      if (p.objective < best) {
        best = p.objective;
        res.best = p;
      }
    }
    for (size_t i = k; i < found.size(); ++i) found[i].objective = 0;  // not evaluated
  } else if (so.objective == GlobalObjective::RobustForce) {
    res.best = found.front();  // sorted by CVaR_95, evaluated by local_capture_optimum
  } else {
    res.best = evaluate_capture(pb, s, base, found.front().theta, so.objective);
    for (ManifoldPoint& p : found)
      p.objective = so.objective == GlobalObjective::ExactForce ? max_force_exact(s.law, p.M_ie) : p.M_ie;
  }
}

}  // namespace detail

inline ManifoldSearchResult detail::search_manifold(const CaptureProblem& pb, const CaptureTask& task,
                                                    const CaptureSetup& s, const BasePose& base,
                                                    const ManifoldSearchOptions& so,
                                                    const std::vector<Eigen::VectorXd>& extra_starts,
                                                    int random_starts) {
  using detail::str;
  const auto t0 = std::chrono::steady_clock::now();
  const Model& model = *pb.model;
  Data data(model);
  ManifoldSearchResult res;
  const bool robust = so.objective == GlobalObjective::RobustForce;
  if (robust && !so.robust)
    throw InputError("search_capture_manifold: the robust-force objective needs its sample set");
  res.method = so.objective == GlobalObjective::MultibodyForce
                   ? "multistart NLopt SLSQP on M_ie, local optima ranked by the CVODE multibody peak"
               : robust ? "multistart NLopt SLSQP on CVaR_95 of the exact F_max over the sample set"
                        : "multistart NLopt SLSQP";
  const std::vector<Eigen::VectorXd> starts = manifold_starts(model, so.seed, extra_starts, random_starts);
  res.starts = static_cast<int>(starts.size());

  detail::SlsqpContext ctx{&model, &data, &pb, &task, &s, &base, robust ? so.robust.get() : nullptr,
                           0,      {},    {},  {},    {}};
  nlopt::opt local(nlopt::LD_SLSQP, static_cast<unsigned>(model.n()));
  configure_slsqp(local, model, task.rows(), ctx, so);
  std::vector<ManifoldPoint> found;
  const bool branch_stage_on = random_starts > 0 && so.branch_starts > 0;
  if (task.rows() >= model.n()) {  // no null space: the inverse-kinematics solutions
    std::vector<Eigen::VectorXd> all = starts;
    if (branch_stage_on)
      for (Eigen::VectorXd& q : halton_starts(model, so.branch_starts)) all.push_back(std::move(q));
    res.starts = static_cast<int>(all.size());
    res.method = "all inverse-kinematics solutions from random and Halton starts (damped Newton)";
    enumerate_solutions(model, data, pb, task, s, base, so, all, res, found);
  } else {
    ManifoldPoint p;
    for (const Eigen::VectorXd& q : starts)
      if (local_capture_optimum(model, data, pb, task, s, base, so, local, q, res, p))
        keep_distinct(model, found, p);
    if (branch_stage_on) {
      res.starts += so.branch_starts;
      res.method += ", then multi-level single linkage over Halton starts";
      branch_stage(model, data, pb, task, s, base, so, local, res, found);
    }
  }
  res.evaluations = ctx.evaluations;
  if (found.empty() && so.inequalities && so.inequalities->count > 0)
    throw InfeasibleInequalitiesError(
        str("search_capture_manifold: no configuration that puts the end-effector on the capture point [",
            s.x_cap.transpose(), "] from the base pose at T satisfies the search's inequality constraints (",
            res.starts, " starts)"));
  if (found.empty())
    throw InputError(
        str("search_capture_manifold: no configuration puts the end-effector on the capture point [",
            s.x_cap.transpose(), "] from the base pose at T (", res.starts,
            " starts); the capture point is out of reach"));
  std::sort(found.begin(), found.end(),
            [](const ManifoldPoint& a, const ManifoldPoint& b) { return a.objective < b.objective; });
  res.local_optima = std::move(found);
  rank_local_optima(pb, s, base, so, res);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

struct GlobalCaptureOptions {
  ManifoldSearchOptions search;
  int max_iterations = 8;    ///< shooting iterations per goal before the goal is given up
  int max_goals = 6;         ///< local optima tried as goals, best first
  double gap_percent = 1.0;  ///< required (reached - optimum) / optimum at the reached base pose, %
  std::vector<Eigen::VectorXd> extra_starts;  ///< e.g. the paper's method's capture configuration
  /// A reconfiguration before the approach (reconfigure.hpp): never (the default), auto (only when
  /// the best goal is not reached by the approach alone) or always; its duration.
  ReconfigureOptions reconfigure;
  /// Optional check of a reaching run (its series recorded) and the time its approach begins (0, or
  /// the end of its reconfiguration): a message rejects the run, whose goal is then given up (e.g.
  /// the clearance along the path, geometry/clearance.hpp).
  std::function<std::optional<std::string>(const CaptureResult&, double approach_begin)> check_run;
};

struct GlobalCaptureResult {
  CaptureResult run;                  ///< the reaching run (its capture configuration and checks)
  ManifoldSearchResult search;        ///< the last search, at the reached base pose
  double objective = 0;               ///< objective at the reached capture configuration
  double manifold_optimum = 0;        ///< objective at the optimum of C(reached base pose)
  double optimality_gap_percent = 0;  ///< 100 (objective - manifold_optimum) / manifold_optimum
  /// false: no better optimum than the one reached could be reached (it lies on another component
  /// of the self-motion manifold: the servo ended elsewhere); the gap then exceeds gap_percent
  bool reached_manifold_optimum = true;
  int shooting_iterations = 0;  ///< reaching runs over every goal tried
  int goals_tried = 0;
  int goals_out_of_limits = 0;     ///< goals given up because the way to them crosses a joint limit
  long evaluations = 0;            ///< over every search
  long objective_evaluations = 0;  ///< multibody simulations over every search
  double search_seconds = 0;       ///< over every search
  /// The phases of `run`: the approach alone, or the reconfiguration then the approach.
  std::vector<RunPhase> phases;
  bool reconfigured = false;  ///< `run` begins with a reconfiguration
  int goals_rejected = 0;     ///< reached goals whose run check_run rejected
  std::string rejection;      ///< the last rejection's message
  /// With a clearance (io/scenario_geometry.hpp): the distance bound of the searches, m (the
  /// clearance plus the margin of the round that planned the run); manifold_optimum is the optimum
  /// under it. 0: no distance bound.
  double search_distance_bound = 0;
  /// Empty when the task alone (no null-space motion) followed the line and gave the first base pose
  /// at T; otherwise its error (possible only with a reconfiguration allowed): the first search was at
  /// the initial base pose.
  std::string task_alone_failure;
  /// The error of the last reaching run that failed and whose goal was given up for it (an approach
  /// after a reconfiguration, or alone where a reconfiguration may follow); empty if none.
  std::string run_failure;
};

namespace detail {

inline void check_global_options(const GlobalCaptureOptions& g, const char* where) {
  if (g.max_iterations < 1) throw InputError(str(where, ": max_iterations must be >= 1"));
  if (g.max_goals < 1) throw InputError(str(where, ": max_goals must be >= 1"));
  if (!(g.gap_percent > 0)) throw InputError(str(where, ": gap_percent must be positive"));
}

/// Adds a search's evaluation counts and time to the planner's counters.
inline void account(GlobalCaptureResult& res, const ManifoldSearchResult& sr) {
  res.evaluations += sr.evaluations;
  res.objective_evaluations += sr.objective_evaluations;
  res.search_seconds += sr.seconds;
}

/// Pose task: the angle between the end-effector's orientation at (base, theta) and the final one
/// (0 for a position task). Runs crba.
inline double goal_orientation_error(const CaptureProblem& pb, const CaptureTask& task, const CaptureSetup& s,
                                     const BasePose& base, const Eigen::VectorXd& theta) {
  if (task.kind != CaptureTask::Kind::Pose) return 0.0;
  Data data(*pb.model);
  crba(*pb.model, data, base, theta);
  return rotation_angle(s.R_end * frame_pose(*pb.model, data, pb.frame).R.transpose());
}

/// Drops the local optima whose end-effector is not in the final orientation (a residual that
/// vanishes at a half turn too lets them through) and makes the best remaining one res.best. The
/// result keeps at least one point (the best, even if off). Runs crba per optimum.
inline void drop_turned_optima(const CaptureProblem& pb, const CaptureTask& task, const CaptureSetup& s,
                               const BasePose& base, const GlobalCaptureOptions& g,
                               ManifoldSearchResult& res) {
  if (task.kind != CaptureTask::Kind::Pose || g.search.objective == GlobalObjective::MultibodyForce) return;
  std::vector<ManifoldPoint> kept;
  for (const ManifoldPoint& p : res.local_optima)
    if (goal_orientation_error(pb, task, s, base, p.theta) < 1e-4) kept.push_back(p);
  if (kept.empty() || kept.size() == res.local_optima.size()) return;
  res.local_optima = std::move(kept);
  res.best = res.local_optima.front();
}

/// The goals of plan_capture_global at the base pose of the task-only run: the best max_goals local
/// optima of a search from `extra` and random starts (multibody-force: the ranked ones), and the
/// local optima next to each extra start (on the component of the self-motion manifold the arm is
/// on, so reachable when the better ones are not), sorted by objective. Counts into res.
inline std::vector<ManifoldPoint> capture_goals(const CaptureProblem& pb, const CaptureTask& task,
                                                const CaptureSetup& setup, const BasePose& base,
                                                const GlobalCaptureOptions& g,
                                                const std::vector<Eigen::VectorXd>& extra,
                                                GlobalCaptureResult& res) {
  ManifoldSearchResult first = search_capture_manifold(pb, task, setup, base, g.search, extra);
  account(res, first);
  drop_turned_optima(pb, task, setup, base, g, first);
  std::vector<ManifoldPoint> goals;
  for (const ManifoldPoint& p : first.local_optima)
    if (p.objective > 0) goals.push_back(p);  // multibody-force: the ranked ones
  auto by_objective = [](const ManifoldPoint& a, const ManifoldPoint& b) {
    return a.objective < b.objective;
  };
  std::stable_sort(goals.begin(), goals.end(), by_objective);
  if (goals.size() > static_cast<size_t>(g.max_goals)) goals.resize(static_cast<size_t>(g.max_goals));
  for (const Eigen::VectorXd& x : extra) {
    try {
      const ManifoldSearchResult near = detail::search_manifold(pb, task, setup, base, g.search, {x}, 0);
      account(res, near);
      goals.push_back(near.best);
    } catch (const InputError&) {
    }
  }
  std::stable_sort(goals.begin(), goals.end(), by_objective);
  return goals;
}

/// The shooting loop for one goal: reaching runs with ServoPolicy, the goal re-optimized locally at
/// each reached base pose, until the reached objective is within gap_percent of that local optimum;
/// then a full search at the reached base pose gives the gap. Returns that result (counters as of
/// then), or nothing when the goal is given up: a joint limit on the way (goals_out_of_limits), the
/// goal off the manifold at the reached base pose, the run ending on another component (more than
/// 0.5 rad from the goal on some joint), or max_iterations spent. Counts into res.
/// t_r > 0: each run reconfigures the arm to the goal in t_r seconds first (plan_reconfigured_capture),
/// and a better optimum of the full search (on another component, which the reconfiguration can
/// reach) becomes the next goal while iterations remain.
inline std::optional<GlobalCaptureResult> reach_goal(const CaptureProblem& pb, const CaptureTask& task,
                                                     const CaptureOptions& run_opt, const CaptureSetup& setup,
                                                     const GlobalCaptureOptions& g, Eigen::VectorXd goal,
                                                     GlobalCaptureResult& res, const char* where,
                                                     double t_r = 0) {
  for (int it = 1; it <= g.max_iterations; ++it) {
    ServoPolicy servo;
    servo.theta_goal = goal;
    ++res.shooting_iterations;
    CaptureResult run;
    std::vector<RunPhase> phases;
    try {
      if (t_r > 0) {
        ReconfiguredRun rr = plan_reconfigured_capture(pb, task, run_opt, setup, goal, t_r, servo, where);
        run = std::move(rr.run);
        phases = std::move(rr.phases);
      } else {
        run = integrate_capture(pb, task, run_opt, setup, servo, where);
        phases = approach_only_phases(run, run_opt.duration);
      }
    } catch (const JointLimitError&) {
      ++res.goals_out_of_limits;
      return std::nullopt;
    } catch (const NumericalError& e) {
      // the approach fails (after a reconfiguration, or alone where one may follow): give the goal
      // up; the approach alone without a reconfiguration to fall back on: the run's error
      if (t_r > 0 || g.reconfigure.mode != ReconfigureMode::Never) {
        res.run_failure = e.what();
        return std::nullopt;
      }
      throw;
    }
    const ManifoldPoint reached = evaluate_capture(pb, setup, run.base, run.theta, g.search.objective,
                                                   g.search.multibody, g.search.robust.get());
    if (g.search.objective == GlobalObjective::MultibodyForce) ++res.objective_evaluations;
    ManifoldSearchResult local;  // the goal re-optimized locally at the reached base pose
    try {
      local = detail::search_manifold(pb, task, setup, run.base, g.search, {goal}, 0);
    } catch (const InputError&) {
      return std::nullopt;
    }
    account(res, local);
    // the servo leaves ~e^-10 of the error; the rest is the move of the manifold with the base pose,
    // small against the distance between components
    if (detail::configuration_distance(*pb.model, run.theta, local.best.theta) > 0.5) return std::nullopt;
    if (detail::exceeds_reach_tolerance(g.search, run.base, run.theta)) {  // outside the constraints
      goal = local.best.theta;
      continue;
    }
    const double local_gap = 100.0 * (reached.objective - local.best.objective) / local.best.objective;
    if (!std::isfinite(local_gap)) throw NumericalError(str(where, ": the optimality gap is not finite"));
    if (local_gap > g.gap_percent) {
      goal = local.best.theta;
      continue;
    }
    std::vector<Eigen::VectorXd> ex = g.extra_starts;  // the goal is reached: the whole manifold
    ex.push_back(goal);
    ex.push_back(run.theta);
    ManifoldSearchResult full = search_capture_manifold(pb, task, setup, run.base, g.search, ex);
    account(res, full);
    drop_turned_optima(pb, task, setup, run.base, g, full);
    const double gap = 100.0 * (reached.objective - full.best.objective) / full.best.objective;
    if (t_r > 0 && gap > g.gap_percent && it < g.max_iterations) {
      goal = full.best.theta;  // reachable too: the reconfiguration moves to its component
      continue;
    }
    GlobalCaptureResult r = res;
    r.run = std::move(run);
    r.search = std::move(full);
    r.objective = reached.objective;
    r.manifold_optimum = r.search.best.objective;
    r.optimality_gap_percent = gap;
    r.reached_manifold_optimum = gap <= g.gap_percent;
    r.phases = std::move(phases);
    r.reconfigured = t_r > 0;
    return r;
  }
  return std::nullopt;
}

/// InputError unless the reconfiguration duration is 0 (not set) or lies in (0, duration).
inline void check_reconfiguration_duration(double t_r, double duration, const char* where) {
  if (!std::isfinite(t_r) || t_r < 0 || (t_r > 0 && t_r >= duration))
    throw InputError(
        str(where, ": the reconfiguration duration must lie in (0, ", duration, ") s, got ", t_r));
}

/// The best reached goal's result with the counters of every goal tried (`counts`).
inline GlobalCaptureResult with_counters(GlobalCaptureResult best, const GlobalCaptureResult& counts) {
  best.shooting_iterations = counts.shooting_iterations;
  best.goals_tried = counts.goals_tried;
  best.goals_out_of_limits = counts.goals_out_of_limits;
  best.evaluations = counts.evaluations;
  best.objective_evaluations = counts.objective_evaluations;
  best.search_seconds = counts.search_seconds;
  best.goals_rejected = counts.goals_rejected;
  best.run_failure = counts.run_failure;
  return best;
}

}  // namespace detail

/// Global capture planning (see the top of this file). Goals are the local optima of the search at
/// the base pose of the task-only run, best first. For each goal: plan the reaching run, re-optimize
/// the goal locally at the reached base pose, repeat until the reached objective is within
/// gap_percent of that local optimum (the goal is then reached) or the run ends away from it (the
/// goal lies on another component of the self-motion manifold: next goal). A reached goal is checked
/// against a full search at the reached base pose: within gap_percent of its optimum, done.
/// Otherwise the best reached goal is returned with reached_manifold_optimum = false and the gap
/// as measured. opt.gain is not used; opt.max_joint_rate limits the joint rates (0: not limited).
/// Throws InputError for bad arguments (as plan_capture, plus a rate limit below what the task alone
/// needs), NumericalError when a run fails the checks of integrate_capture or no goal is reached.
/// A reaching run that would leave a joint's limits gives its goal up (goals_out_of_limits).
/// g.reconfigure (reconfigure.hpp): never, the approach alone; always, every goal reached with a
/// reconfiguration first; auto, each goal with the approach alone first, then, unless reached,
/// with a reconfiguration. A reconfiguration the joint-rate limit does not allow in its time throws
/// ReconfigurationRateError (an InputError). With a reconfiguration allowed (auto, always), a task
/// the arm cannot follow from its start is no error: the failure of the task alone goes into
/// task_alone_failure, the first search is at the initial base pose, and an approach alone that fails
/// gives its goal up to the reconfiguration.
inline GlobalCaptureResult plan_capture_global(const CaptureProblem& pb, const CaptureTask& task,
                                               const CaptureOptions& opt, const GlobalCaptureOptions& g) {
  using detail::str;
  const char* where = "plan_capture_global";
  CaptureOptions o = opt;
  o.gain = 0.0;
  o.progress = nullptr;
  const CaptureSetup setup = prepare_capture(pb, task, o, where);
  detail::check_global_options(g, where);
  detail::check_reconfiguration_duration(g.reconfigure.duration, o.duration, where);
  CaptureOptions quiet = o;
  quiet.record_series = false;

  // the task alone (no null-space motion): a first base pose at T, and the rate it needs
  ServoPolicy none;
  // With a reconfiguration allowed, a task the arm cannot follow from its start (a grasp orientation
  // far from the initial one, an algorithmic singularity on the way) is no error: the search starts
  // at the initial base pose instead, and the reconfiguration moves the arm to where the approach works.
  GlobalCaptureResult res;
  std::vector<Eigen::VectorXd> extra = g.extra_starts;
  BasePose first_base = pb.base;
  try {
    const CaptureResult plain = integrate_capture(pb, task, quiet, setup, none, where);
    if (o.max_joint_rate > 0 && plain.max_joint_rate > o.max_joint_rate)
      throw JointRateLimitError(str(where, ": max joint rate ", o.max_joint_rate * 180 / M_PI,
                           " deg/s is below what the task alone needs (", plain.max_joint_rate * 180 / M_PI,
                           " deg/s)"));
    extra.push_back(plain.theta);
    first_base = plain.base;
  } catch (const NumericalError& e) {
    if (g.reconfigure.mode == ReconfigureMode::Never) throw;
    res.task_alone_failure = e.what();
  }
  std::vector<ManifoldPoint> goals;
  try {
    goals = detail::capture_goals(pb, task, setup, first_base, g, extra, res);
  } catch (const InputError& e) {  // e.g. a capture point out of reach: the task alone's error first
    if (res.task_alone_failure.empty()) throw;
    throw NumericalError(str(res.task_alone_failure, "; the search at the initial base pose: ", e.what()));
  }

  CaptureOptions run_opt = quiet;
  run_opt.record_series = opt.record_series || static_cast<bool>(g.check_run);
  std::optional<GlobalCaptureResult> fallback;
  auto keep = [&fallback](std::optional<GlobalCaptureResult>& r) {
    if (r && (!fallback || r->objective < fallback->objective)) fallback = std::move(r);
  };
  auto reject = [&g, &res](std::optional<GlobalCaptureResult>& r) {  // the run's check (e.g. the clearance)
    if (!r || !g.check_run) return;
    if (std::optional<std::string> why =
            g.check_run(r->run, r->reconfigured ? r->phases.front().t_end : 0.0)) {
      ++res.goals_rejected;
      res.rejection = *why;
      r.reset();
    }
  };
  const ReconfigureMode mode = g.reconfigure.mode;
  for (size_t i = 0; i < goals.size(); ++i) {
    ++res.goals_tried;
    std::optional<GlobalCaptureResult> r;
    if (mode != ReconfigureMode::Always) {  // the approach alone
      r = detail::reach_goal(pb, task, run_opt, setup, g, goals[i].theta, res, where);
      reject(r);
      if (r && r->reached_manifold_optimum) return std::move(*r);
      keep(r);
    }
    if (mode != ReconfigureMode::Never) {  // auto: the goal was not reached by the approach alone
      const double t_r = g.reconfigure.duration > 0
                             ? g.reconfigure.duration
                             : default_reconfiguration_duration(*pb.model, pb.theta, goals[i].theta, o);
      try {
        r = detail::reach_goal(pb, task, run_opt, setup, g, goals[i].theta, res, where, t_r);
      } catch (const ReconfigurationRateError&) {
        // a duration chosen here (not given) fits the first goal; a goal that moved while shooting
        // may need more: that goal is not reached, the next is tried. A given duration is the user's.
        if (g.reconfigure.duration > 0) throw;
        r.reset();
      }
      reject(r);
      if (r && r->reached_manifold_optimum) return std::move(*r);
      keep(r);
    }
  }
  if (fallback) return detail::with_counters(std::move(*fallback), res);
  throw NumericalError(str(
      where, ": no capture configuration chosen by the search was reached (", res.goals_tried, " goals, ",
      res.goals_out_of_limits, " of them behind a joint limit, ", res.shooting_iterations, " reaching runs)",
      res.goals_rejected ? str("; the last reached goal was rejected: ", res.rejection) : "",
      res.task_alone_failure.empty() ? "" : str("; the task alone failed: ", res.task_alone_failure),
      res.run_failure.empty() ? "" : str("; the last reaching run that failed: ", res.run_failure)));
}

}  // namespace ffsr
