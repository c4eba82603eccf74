// ffsr/optimize/manifold_search.hpp -- the search on the capture manifold (capture_manifold.hpp) for
// the configuration of least objective (docs/branches.md): the SLSQP adapter, the one local-optimum
// routine the searches share (the global search here, the Pareto front in pareto.hpp), and the
// multistart with its branch stage.
#pragma once

#include "ffsr/optimize/capture_manifold.hpp"
#include "ffsr/optimize/multibody_objective.hpp"

#include <nlopt.hpp>

#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <random>

// Multistart: `starts` configurations drawn uniformly within the limits ([-pi, pi] for a continuous
// joint) by std::mt19937_64 with our own mapping to [0, 1) (so a seed gives the same draws on every
// platform), each put on C(B) by damped Newton on c, then NLopt's SLSQP minimizes the capture
// objective's search value (optimize/objective.hpp: M_ie of the joint model, or CVaR_95 for
// robust-force) with its analytic gradient under the equality constraints c = 0. Then the branch
// stage: `branch_starts` Halton points over the joint box, each projected onto C(B); with a null
// space (more joints than task rows) a multi-level single-linkage rule picks which of them start
// SLSQP (the lowest M_ie within `branch_radius`), at most `branch_local_searches`; without one (a
// 6-joint arm with a pose task: C(B) is a set of points, the inverse-kinematics solutions) every
// projection is polished to |c| <= 1e-12 and the distinct ones are the branches. Revolute joints with
// limits are moved by whole turns to the value nearest the initial configuration (one configuration
// per posture). The distinct local optima are kept, sorted. For the multibody-force objective, which
// has no gradient, the distinct local optima of M_ie are ranked by the CVODE multibody peak, evaluated
// directly at each of them. exact-force is a monotone function of M_ie (Eq. 16 scaling), so its
// optimum is M_ie's. robust-force: SLSQP minimizes CVaR_95 of the exact F_max over a fixed set of
// uncertain samples with its analytic gradient, under the same constraints; the optima are compared
// by that value. Needs NLopt (ffsr::global).

namespace ffsr {

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

namespace detail {

/// Uniform double in [0, 1) from the 53 high bits of a 64-bit draw (portable, unlike
/// std::uniform_real_distribution whose algorithm the standard leaves open).
inline double unit_uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace detail

/// NLopt's SLSQP on the capture manifold C(base) (the public adapter of the searches): minimizes an
/// objective -- the search value of a CaptureEvaluator (minimize), or any function with NLopt's
/// signature -- under the task's equality constraints c = 0 (tolerance a tenth of
/// constraint_tolerance), within the joint limits, under the manifold's inequalities (if any; a
/// tenth of their tolerance) and further inequalities (add_inequality), with an evaluation budget.
/// It registers itself with NLopt: not copyable, one object per thread (it holds the workspace).
class ManifoldSlsqp {
 public:
  ManifoldSlsqp(const CaptureProblem& pb, const CaptureTask& task, const CaptureSetup& s,
                const BasePose& base, double constraint_tolerance, int max_evaluations,
                const ManifoldInequalities* inequalities = nullptr)
      : pb_(pb),
        task_(task),
        setup_(s),
        base_(base),
        data_(*pb.model),
        tolerance_(constraint_tolerance),
        inequalities_(inequalities && inequalities->count > 0 ? inequalities : nullptr),
        opt_(nlopt::LD_SLSQP, static_cast<unsigned>(pb.model->n())) {
    const Model& model = *pb.model;
    const int n = model.n();
    opt_.add_equality_mconstraint(
        constraints, this, std::vector<double>(static_cast<size_t>(task.rows()), constraint_tolerance * 0.1));
    std::vector<double> lb(static_cast<size_t>(n)), ub(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k) {
      lb[static_cast<size_t>(k)] = model.joint(k).lower;
      ub[static_cast<size_t>(k)] = model.joint(k).upper;
    }
    if (inequalities_)
      opt_.add_inequality_mconstraint(
          manifold_inequalities, this,
          std::vector<double>(inequalities_->count, inequalities_->tolerance * 0.1));
    opt_.set_lower_bounds(lb);
    opt_.set_upper_bounds(ub);
    opt_.set_xtol_rel(1e-10);
    opt_.set_ftol_rel(1e-12);
    opt_.set_maxeval(max_evaluations);
  }
  ManifoldSlsqp(const ManifoldSlsqp&) = delete;
  ManifoldSlsqp& operator=(const ManifoldSlsqp&) = delete;

  /// Minimizes the evaluator's search value with its analytic gradient (counted in evaluations()).
  void minimize(const CaptureEvaluator& objective) {
    objective_ = &objective;
    opt_.set_min_objective(search_value, this);
  }
  /// Minimizes f (NLopt's signature, data passed through).
  void minimize(nlopt::func f, void* data) { opt_.set_min_objective(f, data); }
  /// Adds the inequality f(theta) <= 0 (NLopt's signature) with its tolerance.
  void add_inequality(nlopt::func f, void* data, double tolerance) {
    opt_.add_inequality_constraint(f, data, tolerance);
  }

  /// SLSQP from x0: the point it ends on (the best point found when roundoff stops it; x0 when NLopt
  /// fails).
  Eigen::VectorXd run(const Eigen::VectorXd& x0) {
    const int n = pb_.model->n();
    std::vector<double> x(x0.data(), x0.data() + n);
    double f = 0;
    try {
      opt_.optimize(x, f);
    } catch (const nlopt::roundoff_limited&) {  // x holds the best point found
    } catch (const std::runtime_error&) {       // NLopt failure: keep the start
      x.assign(x0.data(), x0.data() + n);
    }
    return Eigen::Map<const Eigen::VectorXd>(x.data(), n);
  }

  const CaptureProblem& problem() const { return pb_; }
  const CaptureTask& task() const { return task_; }
  const CaptureSetup& setup() const { return setup_; }
  const BasePose& base() const { return base_; }
  const ManifoldInequalities* inequalities() const { return inequalities_; }
  double constraint_tolerance() const { return tolerance_; }
  Data& data() { return data_; }
  /// Evaluations of the evaluator's search value (minimize(const CaptureEvaluator&)).
  long evaluations() const { return evaluations_; }

 private:
  static double search_value(unsigned n, const double* x, double* grad, void* p) {
    auto& c = *static_cast<ManifoldSlsqp*>(p);
    ++c.evaluations_;
    c.theta_ = Eigen::Map<const Eigen::VectorXd>(x, n);
    c.g_.resize(n);
    const double f = c.objective_->search_value_gradient(c.data_, c.base_, c.theta_, c.g_);
    if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = c.g_;
    return f;
  }
  static void constraints(unsigned m, double* result, unsigned n, const double* x, double* grad, void* p) {
    auto& c = *static_cast<ManifoldSlsqp*>(p);
    c.theta_ = Eigen::Map<const Eigen::VectorXd>(x, n);
    capture_residual(*c.pb_.model, c.data_, c.pb_, c.task_, c.setup_, c.base_, c.theta_, c.r_,
                     grad ? &c.J_ : nullptr);
    Eigen::Map<Eigen::VectorXd>(result, m) = c.r_;
    if (grad)  // NLopt: grad[i * n + j] = d c_i / d x_j (row-major)
      for (unsigned i = 0; i < m; ++i)
        for (unsigned j = 0; j < n; ++j) grad[i * n + j] = c.J_(i, j);
  }
  static void manifold_inequalities(unsigned, double* result, unsigned n, const double* x, double* grad,
                                    void* p) {
    auto& c = *static_cast<ManifoldSlsqp*>(p);
    c.theta_ = Eigen::Map<const Eigen::VectorXd>(x, n);
    c.inequalities_->eval(c.base_, c.theta_, result, grad);
  }

  const CaptureProblem& pb_;
  const CaptureTask& task_;
  const CaptureSetup& setup_;
  const BasePose& base_;
  Data data_;
  double tolerance_;
  const ManifoldInequalities* inequalities_;
  const CaptureEvaluator* objective_ = nullptr;
  long evaluations_ = 0;
  Eigen::VectorXd theta_, g_, r_;
  Eigen::MatrixXd J_;
  nlopt::opt opt_;
};

/// The one local-optimum routine of the searches on C(base) (the global search and the Pareto
/// front): the start q projected onto C(base) by damped Newton to the constraint tolerance (with
/// `representatives`, moved to the representative of its posture nearest the initial
/// configuration, detail::nearest_representative) and within the limits; SLSQP from there
/// (`slsqp`'s objective); its point projected again (at most 20 Newton iterations: SLSQP ends within
/// a tenth of the tolerance, a few put it exactly on C), moved likewise, within the limits and the
/// manifold's inequalities. Nothing when the start or the optimum is not usable; *projected (if
/// given) counts a start put on the manifold. Runs crba per Newton step and SLSQP evaluation.
inline std::optional<Eigen::VectorXd> local_manifold_optimum(ManifoldSlsqp& slsqp, Eigen::VectorXd q,
                                                             bool representatives, int* projected = nullptr) {
  const CaptureProblem& pb = slsqp.problem();
  const Model& model = *pb.model;
  const double tol = slsqp.constraint_tolerance();
  auto usable = [&](Eigen::VectorXd& x) {
    return (!representatives || detail::nearest_representative(model, pb.theta, x)) &&
           detail::within_limits(model, x);
  };
  if (!detail::project_to_manifold(model, slsqp.data(), pb, slsqp.task(), slsqp.setup(), slsqp.base(), q,
                                   tol) ||
      !usable(q))
    return std::nullopt;
  if (projected) ++*projected;
  Eigen::VectorXd th = slsqp.run(q);
  if (!detail::project_to_manifold(model, slsqp.data(), pb, slsqp.task(), slsqp.setup(), slsqp.base(), th,
                                   tol, 20) ||
      !usable(th) || !detail::satisfies_inequalities(slsqp.inequalities(), slsqp.base(), th))
    return std::nullopt;
  return th;
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

/// The local optimum of the search from start q (local_manifold_optimum with representatives) with
/// a finite M_ie: writes `out` (theta, M_ie, the value the optima are compared by: M_ie, or CVaR_95
/// for robust-force) and returns true; false when the start or the optimum is not usable. Counts a
/// projected start in res.projected_starts.
inline bool local_capture_optimum(ManifoldSlsqp& slsqp, const CaptureEvaluator& objective,
                                  const Eigen::VectorXd& q, ManifoldSearchResult& res, ManifoldPoint& out) {
  if (q.size() != slsqp.problem().model->n() || !q.allFinite())
    throw InputError("search_capture_manifold: an extra start has the wrong size or is not finite");
  const std::optional<Eigen::VectorXd> th = local_manifold_optimum(slsqp, q, true, &res.projected_starts);
  if (!th) return false;
  double M = 0;
  const double v = objective.search_value(slsqp.data(), slsqp.base(), *th, M);
  if (!std::isfinite(M)) return false;
  out = {*th, M, v};
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

/// Without a null space (as many task rows as joints) C(base) is a set of points, the
/// inverse-kinematics solutions: every start is projected (damped Newton to |c| <= 1e-12, or the
/// search's tolerance when roundoff stops it first), moved to the representative of its posture,
/// and kept when within the limits and more than 1e-6 rad (posture_distance) from every solution
/// kept. No SLSQP: each solution is its own local optimum. Appends to `found`; counts into res.
inline void enumerate_solutions(const Model& model, Data& data, const CaptureProblem& pb,
                                const CaptureTask& task, const CaptureSetup& s, const BasePose& base,
                                const ManifoldSearchOptions& so, const CaptureEvaluator& objective,
                                const std::vector<Eigen::VectorXd>& starts, ManifoldSearchResult& res,
                                std::vector<ManifoldPoint>& found) {
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
    const double v = objective.search_value(data, base, q, M);
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
                         const CaptureEvaluator& objective, ManifoldSlsqp& local, ManifoldSearchResult& res,
                         std::vector<ManifoldPoint>& found) {
  std::vector<ManifoldPoint> samples;
  for (Eigen::VectorXd q : halton_starts(model, so.branch_starts)) {
    if (!project_to_manifold(model, data, pb, task, s, base, q, so.constraint_tolerance)) continue;
    if (!nearest_representative(model, pb.theta, q) || !within_limits(model, q)) continue;
    const double M = objective.mass(data, base, q);
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
    if (local_capture_optimum(local, objective, samples[i].theta, res, p)) keep_distinct(model, found, p);
  }
}

/// Fills res.best and the objective of res.local_optima (sorted by the compared value): the CVODE
/// peak at the best max_ranked optima for multibody-force (0 for those not ranked), CVaR_95 as
/// compared for robust-force, M_ie or the exact F_max at it otherwise.
inline void rank_local_optima(const CaptureEvaluator& objective, Data& data, const BasePose& base,
                              const ManifoldSearchOptions& so, ManifoldSearchResult& res) {
  std::vector<ManifoldPoint>& found = res.local_optima;
  if (so.objective == GlobalObjective::MultibodyForce) {
    // no gradient: evaluate the CVODE peak directly at the best local optima of M_ie
    double best = std::numeric_limits<double>::infinity();
    const size_t k = std::min(found.size(), static_cast<size_t>(so.max_ranked));
    for (size_t i = 0; i < k; ++i) {
      ManifoldPoint p = objective.evaluate(data, base, found[i].theta);
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
    res.best = objective.evaluate(data, base, found.front().theta);
    for (ManifoldPoint& p : found) p.objective = objective.of_mass(p.M_ie);
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

  const CvodeMultibodyPeak peak(pb, s.capture.target, so.multibody);
  const CaptureEvaluator objective(pb, s, so.objective, &peak, so.robust.get());
  ManifoldSlsqp local(pb, task, s, base, so.constraint_tolerance, so.max_local_evaluations,
                      so.inequalities.get());
  local.minimize(objective);
  std::vector<ManifoldPoint> found;
  const bool branch_stage_on = random_starts > 0 && so.branch_starts > 0;
  if (task.rows() >= model.n()) {  // no null space: the inverse-kinematics solutions
    std::vector<Eigen::VectorXd> all = starts;
    if (branch_stage_on)
      for (Eigen::VectorXd& q : halton_starts(model, so.branch_starts)) all.push_back(std::move(q));
    res.starts = static_cast<int>(all.size());
    res.method = "all inverse-kinematics solutions from random and Halton starts (damped Newton)";
    enumerate_solutions(model, data, pb, task, s, base, so, objective, all, res, found);
  } else {
    ManifoldPoint p;
    for (const Eigen::VectorXd& q : starts)
      if (local_capture_optimum(local, objective, q, res, p)) keep_distinct(model, found, p);
    if (branch_stage_on) {
      res.starts += so.branch_starts;
      res.method += ", then multi-level single linkage over Halton starts";
      branch_stage(model, data, pb, task, s, base, so, objective, local, res, found);
    }
  }
  res.evaluations = local.evaluations();
  if (found.empty() && so.inequalities && so.inequalities->count > 0)
    throw InfeasibleInequalitiesError(
        str("search_capture_manifold: no configuration that puts the end-effector on the capture point [",
            s.capture.x_cap.transpose(),
            "] from the base pose at T satisfies the search's inequality constraints (", res.starts,
            " starts)"));
  if (found.empty())
    throw InputError(
        str("search_capture_manifold: no configuration puts the end-effector on the capture point [",
            s.capture.x_cap.transpose(), "] from the base pose at T (", res.starts,
            " starts); the capture point is out of reach"));
  std::sort(found.begin(), found.end(),
            [](const ManifoldPoint& a, const ManifoldPoint& b) { return a.objective < b.objective; });
  res.local_optima = std::move(found);
  rank_local_optima(objective, data, base, so, res);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace ffsr
