// ffsr/optimize/pareto.hpp -- the trade-off between the contact force and the base disturbance on
// the capture manifold: the non-dominated set of (M_ie, |Delta w_0|) at a fixed base pose.
#pragma once

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/optimize/manifold_search.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

// M_ie (Eq. 14) sets the peak contact force; |Delta w_0| is the jump of the base's angular velocity
// caused by the contact impulse (algorithm/base_disturbance.hpp): |Delta w_0| = P |b_w|, with
// P = M_ie delta_dot^- (1 + e) and b_w the angular base rows of H^-1 J^T [u; 0] per unit impulse.
// Both are functions of the capture configuration theta on the capture manifold C(B) of
// capture_manifold.hpp (the base at the pose B, the task's constraints c(theta) = 0 within the joint
// limits), both of the problem's joint model (the capture objective, objective.hpp).
//
// Epsilon-constraint sweep with the searches' SLSQP adapter and local-optimum routine
// (manifold_search.hpp; the base-rate function and constraint: capture_manifold.hpp):
//  1. the M_ie end: search_capture_manifold (mass objective) from `starts` random starts;
//  2. the rate end: SLSQP minimizing (|Delta w_0| / w_ref)^2 from the same starts and the M_ie local
//     optima (w_ref the rate at the M_ie end);
//  3. for `levels` values eps between the two ends' rates: SLSQP minimizing M_ie under
//     (|Delta w_0| / eps)^2 <= 1 and c = 0, started from the previous level's point and from the
//     M_ie end (the better feasible result kept);
//  4. the non-dominated set of every point found, sorted by M_ie, rates within 1e-9 of the M_ie end's
//     counted as equal (the arm can turn the impulse's line through the point that leaves the base's
//     rotation alone: the least rate is then zero to rounding, reached on a whole set of
//     configurations, and the rate end is the one of least M_ie among them).
// The gradient of M_ie is analytic (effective_mass_gradient.hpp); that of |Delta w_0|^2 a central difference
// (step 1e-6 rad), 2n evaluations of crba and one back substitution each.
//
// Reported beside the front: the hypervolume dominated by it up to the nadir of the two ends
// (M_ie of the rate end, rate of the M_ie end), in kg deg/s and normalized by the nadir box; the
// knee, the point farthest from the line through the two ends in the normalized objectives.
// Needs NLopt: CMake target ffsr::global.

namespace ffsr {

struct ParetoOptions {
  int starts = 16;                      ///< random starts of the two single-objective searches
  std::uint64_t seed = 1;               ///< their seed (global.hpp's draws)
  int levels = 30;                      ///< eps levels of the sweep between the two ends
  double constraint_tolerance = 1e-10;  ///< |c| accepted as on the manifold (m, rad)
  int max_local_evaluations = 300;      ///< SLSQP budget per start or level
};

/// A capture configuration with its two objectives.
struct ParetoPoint {
  Eigen::VectorXd theta;
  double M_ie = 0;       ///< kg
  double base_rate = 0;  ///< |Delta w_0|, rad/s
};

struct ParetoFront {
  std::vector<ParetoPoint> points;    ///< non-dominated, M_ie increasing (base_rate decreasing)
  ParetoPoint min_mass, min_rate;     ///< the two ends: the single-objective optima
  size_t knee = 0;                    ///< index in points
  double hypervolume = 0;             ///< up to the nadir of the ends, kg rad/s
  double hypervolume_normalized = 0;  ///< the same divided by the nadir box (0..1)
  long evaluations = 0;               ///< objective evaluations (each M_ie or rate with its gradient)
  double seconds = 0;
};

namespace detail {

/// The two objectives at theta (base fixed): M_ie and |Delta w_0| with the restitution e of the law,
/// under the problem's joint model (detail::base_rate of capture_manifold.hpp). Runs crba. Writes data.
inline ParetoPoint pareto_point(const Model& model, Data& data, const CaptureProblem& pb,
                                const CaptureSetup& s, const BasePose& base, const Eigen::VectorXd& theta,
                                double restitution) {
  (void)model;  // pb.model's
  BaseRateContext c;
  c.pb = &pb;
  c.setup = &s;
  c.base = &base;
  c.data = &data;
  c.restitution = restitution;
  double M = 0;
  const double rate = base_rate(c, theta, M);
  return {theta, M, rate};
}

struct ParetoContext {
  BaseRateContext rate;  ///< the problem at the base pose, the rate's scale and its evaluations
  long evaluations = 0;  ///< of M_ie (pareto_mass)
  Eigen::VectorXd theta, g;
};

/// M_ie with its analytic gradient (the capture objective's), NLopt's signature.
inline double pareto_mass(unsigned n, const double* x, double* grad, void* p) {
  auto& c = *static_cast<ParetoContext*>(p);
  ++c.evaluations;
  c.theta = Eigen::Map<const Eigen::VectorXd>(x, n);
  c.g.resize(n);
  const double M =
      CaptureEvaluator(*c.rate.pb, *c.rate.setup).mass_gradient(*c.rate.data, *c.rate.base, c.theta, c.g);
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = c.g;
  return M;
}

/// One local optimum from q (local_manifold_optimum, the routine the global search uses): the rate
/// (eps <= 0) or M_ie under rate <= eps minimized on C(base) within the limits. Returns the point, or
/// nothing when unusable or (for a level) infeasible beyond 1e-6 relative.
inline std::optional<ParetoPoint> pareto_local(ParetoContext& ctx, const CaptureTask& task,
                                               const ParetoOptions& o, const Eigen::VectorXd& q, double eps,
                                               double rate_scale) {
  const BaseRateContext& r = ctx.rate;
  ManifoldSlsqp slsqp(*r.pb, task, *r.setup, *r.base, o.constraint_tolerance, o.max_local_evaluations);
  if (eps > 0) {
    ctx.rate.scale = eps;
    slsqp.minimize(pareto_mass, &ctx);
    slsqp.add_inequality(base_rate_constraint, &ctx.rate, 1e-9);
  } else {
    ctx.rate.scale = rate_scale;
    slsqp.minimize(base_rate2, &ctx.rate);
  }
  const std::optional<Eigen::VectorXd> th = local_manifold_optimum(slsqp, q, false);
  if (!th) return std::nullopt;
  ParetoPoint p = pareto_point(*r.pb->model, *r.data, *r.pb, *r.setup, *r.base, *th, r.restitution);
  if (!std::isfinite(p.M_ie) || !std::isfinite(p.base_rate)) return std::nullopt;
  if (eps > 0 && p.base_rate > eps * (1 + 1e-6)) return std::nullopt;
  return p;
}

/// The non-dominated subset of `all`, M_ie increasing; rates within `floor` of each other count as
/// equal (the one of least M_ie kept), so that rates at rounding level (a configuration whose impulse
/// turns no base) do not make a tail of noise.
inline std::vector<ParetoPoint> non_dominated(std::vector<ParetoPoint> all, double floor) {
  std::sort(all.begin(), all.end(), [](const ParetoPoint& a, const ParetoPoint& b) {
    return a.M_ie < b.M_ie || (a.M_ie == b.M_ie && a.base_rate < b.base_rate);
  });
  std::vector<ParetoPoint> front;
  for (const ParetoPoint& p : all)
    if (front.empty() || p.base_rate < front.back().base_rate * (1 - 1e-9) - floor) front.push_back(p);
  return front;
}

/// Hypervolume (up to the nadir of the ends), its normalized value and the knee of `f`.
inline void pareto_measures(ParetoFront& f) {
  const double M0 = f.min_mass.M_ie, M1 = f.min_rate.M_ie;  // nadir: (M1, rate of the M_ie end)
  const double r0 = f.min_rate.base_rate, r1 = f.min_mass.base_rate;
  double hv = 0, best = -1;
  for (size_t i = 0; i < f.points.size(); ++i) {
    const ParetoPoint& p = f.points[i];
    const double next_M = i + 1 < f.points.size() ? std::min(f.points[i + 1].M_ie, M1) : M1;
    if (p.M_ie < M1 && p.base_rate < r1) hv += (next_M - p.M_ie) * (r1 - p.base_rate);
    const double x = (p.M_ie - M0) / (M1 - M0), y = (p.base_rate - r0) / (r1 - r0);
    const double d = (1.0 - x - y) / std::sqrt(2.0);  // distance below the line through the ends
    if (d > best) {
      best = d;
      f.knee = i;
    }
  }
  f.hypervolume = hv;
  f.hypervolume_normalized = hv / ((M1 - M0) * (r1 - r0));
}

}  // namespace detail

/// The front of (M_ie, |Delta w_0|) on C(base) (see the notes after the includes). `extra_starts` join the
/// random starts (e.g. the capture configurations of the other runs). Throws InputError for bad
/// options or when no start reaches the manifold, NumericalError when the two ends coincide (no
/// trade-off to show).
inline ParetoFront pareto_front(const CaptureProblem& pb, const CaptureTask& task, const CaptureSetup& s,
                                const BasePose& base, const ParetoOptions& o,
                                const std::vector<Eigen::VectorXd>& extra_starts = {}) {
  using detail::str;
  if (o.levels < 1) throw InputError(str("pareto_front: levels must be >= 1, got ", o.levels));
  const auto t0 = std::chrono::steady_clock::now();
  const Model& model = *pb.model;
  ManifoldSearchOptions so;
  so.starts = o.starts;
  so.seed = o.seed;
  so.constraint_tolerance = o.constraint_tolerance;
  so.max_local_evaluations = o.max_local_evaluations;
  const ManifoldSearchResult mass = search_capture_manifold(pb, task, s, base, so, extra_starts);
  ParetoFront f;
  f.evaluations = mass.evaluations;
  Data data(model);
  detail::ParetoContext ctx{};
  ctx.rate.pb = &pb;
  ctx.rate.setup = &s;
  ctx.rate.base = &base;
  ctx.rate.data = &data;
  ctx.rate.restitution = single_body_restitution(s.capture.law);
  const double e = ctx.rate.restitution;
  std::vector<ParetoPoint> all;
  for (const ManifoldPoint& m : mass.local_optima)
    all.push_back(detail::pareto_point(model, data, pb, s, base, m.theta, e));
  f.min_mass = detail::pareto_point(model, data, pb, s, base, mass.best.theta, e);
  // the rate end: from the random starts and the M_ie local optima
  std::vector<Eigen::VectorXd> starts = detail::manifold_starts(model, o.seed, extra_starts, o.starts);
  for (const ManifoldPoint& m : mass.local_optima) starts.push_back(m.theta);
  f.min_rate = f.min_mass;
  for (const Eigen::VectorXd& q : starts)
    if (auto p = detail::pareto_local(ctx, task, o, q, 0.0, f.min_mass.base_rate)) {
      all.push_back(*p);
      if (p->base_rate < f.min_rate.base_rate) f.min_rate = *p;
    }
  if (!(f.min_rate.base_rate < f.min_mass.base_rate * (1 - 1e-6)) || !(f.min_rate.M_ie > f.min_mass.M_ie))
    throw NumericalError("pareto_front: the M_ie optimum also has the least base rate: no trade-off");
  // the sweep: least M_ie with the rate at most eps, eps from the rate end up to the M_ie end
  Eigen::VectorXd previous = f.min_rate.theta;
  for (int k = 1; k <= o.levels; ++k) {
    const double eps = f.min_rate.base_rate +
                       (f.min_mass.base_rate - f.min_rate.base_rate) * k / static_cast<double>(o.levels + 1);
    std::optional<ParetoPoint> best;
    for (const Eigen::VectorXd& q : {previous, f.min_mass.theta})
      if (auto p = detail::pareto_local(ctx, task, o, q, eps, 0.0))
        if (!best || p->M_ie < best->M_ie) best = p;
    if (!best) continue;
    previous = best->theta;
    all.push_back(*best);
  }
  all.push_back(f.min_mass);
  all.push_back(f.min_rate);
  // the ends as the front's: the rate end is the least M_ie among the least rates (within the floor)
  f.points = detail::non_dominated(std::move(all), 1e-9 * f.min_mass.base_rate);
  f.min_mass = f.points.front();
  f.min_rate = f.points.back();
  detail::pareto_measures(f);
  f.evaluations += ctx.evaluations + ctx.rate.evaluations;
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return f;
}

}  // namespace ffsr
