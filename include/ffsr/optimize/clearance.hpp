// ffsr/optimize/clearance.hpp -- a clearance in the capture planner: the smallest distances along a
// recorded run, the search's inequality constraints distance >= clearance on the capture manifold
// (ManifoldInequalities, capture_manifold.hpp), and the clearance barrier, a joint-rate filter
// (RateGuard) that keeps a capture run's distances >= the clearance through its null space. The
// distances: geometry/clearance.hpp, geometry/distance.hpp. Component ffsr::geometry.
#pragma once

#include "ffsr/geometry/clearance.hpp"
#include "ffsr/optimize/capture_manifold.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

namespace ffsr {

/// The smallest distances along a run's recorded series (every sample; the target propagated from
/// its state at t = 0, `target0`). InputError when the run has no series.
inline ClearanceReport path_clearance(const Model& model, const CollisionChecker& cc, const Target& target0,
                                      const CaptureResult& run) {
  if (run.series.empty()) throw InputError("path_clearance: the run has no recorded series");
  Data data(model);
  std::vector<PairDistance> ds;
  ClearanceReport r;
  Target target = target0;
  double t_target = 0;
  for (const CaptureSample& s : run.series) {
    target = propagate_target(target, s.t - t_target);  // step by step: cheap for a non-isotropic target
    t_target = s.t;
    forward_kinematics(model, data, s.base, s.theta);
    cc.distances(data, target_pose(target), ds);
    detail::fold_clearance(cc, ds, s.t, r);
  }
  return r;
}

/// The search's constraints clearance - d_i(theta) <= 0 at the base pose the search gives, with the
/// gradient of distance.hpp: one per pair, and for the arm-target pairs one per target pose in
/// `targets` (its pose at T first; earlier poses make the capture configuration clear the space the
/// tumbling target sweeps just before the capture, which the arm, nearly at rest there, occupies).
inline std::shared_ptr<ManifoldInequalities> clearance_constraints(const Model& model,
                                                                   std::shared_ptr<const CollisionChecker> cc,
                                                                   const std::vector<Pose>& targets,
                                                                   double clearance) {
  if (targets.empty()) throw InputError("clearance_constraints: no target pose");
  auto q = std::make_shared<ManifoldInequalities>();
  unsigned count = 0;
  for (const BodyPair& p : cc->pairs())
    count += p.kind == PairKind::ArmTarget ? static_cast<unsigned>(targets.size()) : 1;
  q->count = count;
  auto data = std::make_shared<Data>(model);
  auto grad = std::make_shared<Eigen::VectorXd>(model.n());
  // the bus-target pairs do not move with theta: their distances are kept for the last base pose
  auto bus_base = std::make_shared<std::optional<BasePose>>();
  auto bus_rows = std::make_shared<std::vector<double>>(count);
  const Model* m = &model;
  q->eval = [m, cc, data, grad, targets, clearance, bus_base, bus_rows](
                const BasePose& base, const Eigen::VectorXd& theta, double* g, double* G) {
    forward_kinematics(*m, *data, base, theta);
    const auto n = static_cast<size_t>(m->n());
    const bool same_base = bus_base->has_value() && (*bus_base)->position == base.position &&
                           (*bus_base)->orientation.coeffs() == base.orientation.coeffs();
    size_t row = 0;
    for (size_t i = 0; i < cc->pairs().size(); ++i) {
      const BodyPair& p = cc->pairs()[i];
      const size_t poses = p.kind == PairKind::ArmTarget ? targets.size() : 1;
      const bool bus_target = p.a == 0 && p.b < 0;
      for (size_t t = 0; t < poses; ++t, ++row) {
        if (bus_target) {  // zero gradient: the base pose is the search's, fixed
          if (!same_base)
            (*bus_rows)[row] = cc->pair_distance(*data, targets[t], static_cast<int>(i)).distance;
          g[row] = clearance - (*bus_rows)[row];
          if (G)
            for (size_t k = 0; k < n; ++k) G[row * n + k] = 0;
          continue;
        }
        const PairDistance d = cc->pair_distance(*data, targets[t], static_cast<int>(i));
        g[row] = clearance - d.distance;
        if (!G) continue;
        cc->distance_gradient(*m, *data, d, *grad);
        for (size_t k = 0; k < n; ++k) G[row * n + k] = -(*grad)(static_cast<Eigen::Index>(k));
      }
    }
    *bus_base = base;
  };
  return q;
}

/// The clearance barrier of a capture run (a RateGuard, optimize/capture_problem.hpp): a joint-rate
/// filter in the task's null space that keeps every pair's distance d above the clearance c.
///
/// Free-floating distance rate. With the nearest points p_a (on the arm) and p_b and n = (p_a - p_b)
/// / d, d_dot = n^T (v(p_a) - v(p_b)). The arm's part is g^T theta_dot + n^T (v_0 + w_0 x (p_a -
/// p_0)) with g the fixed-base gradient of distance.hpp; the base velocity of zero momentum is
/// [v_0; w_0] = -H_b^-1 H_bm theta_dot, so d_dot = g*^T theta_dot - n^T v(p_b) with
///   g* = g - H_bm^T H_b^-1 [n; (p_a - p_0) x n]
/// for an arm-target pair, v(p_b) the target's point velocity (v_t + omega_t x (p_b - c_t), the
/// target propagated to t). For a pair of two robot bodies (arm-bus, self) the base's rigid motion
/// moves both points alike and n is parallel to p_a - p_b, so its terms cancel: g* = g, v(p_b) from
/// the arm's chain as in g.
///
/// Barrier (a control barrier function on each pair): the rates must keep d_dot >= -lambda (d - c_b),
/// c_b = (1 + margin) c, so that d approaches c_b at most exponentially and never crosses it in
/// continuous time (the margin absorbs the integration step). Where the rates break it, the filter
/// adds the least correction inside the null space, theta_dot += beta N g*, beta = (-lambda (d - c_b) -
/// d_dot) / (g*^T N g*), pair by pair, in up to 8 sweeps over the pairs (Kaczmarz projections onto the
/// half-spaces, which converge where they intersect). A pair whose g* has no component in the null
/// space (g*^T N g* < 1e-12) cannot be kept: the run goes on and its path check reports it.
/// clearance_barrier: lambda = min(100 / T, 0.5 / h) (a time constant of T / 100, and at least two
/// RK4 steps), margin 2 %.
class ClearanceBarrier : public RateGuard {
 public:
  ClearanceBarrier(std::shared_ptr<const CollisionChecker> cc, const Target& target0, double clearance,
                   double lambda, double margin = 0.02)
      : cc_(std::move(cc)),
        initial_(target0),
        target_(target0),
        c_b_((1 + margin) * clearance),
        lambda_(lambda) {
    if (!cc_) throw InputError("ClearanceBarrier: no collision checker");
    if (!std::isfinite(clearance) || clearance <= 0)
      throw InputError(
          detail::str("ClearanceBarrier: the clearance must be positive and finite, got ", clearance));
    if (!std::isfinite(lambda) || lambda <= 0)
      throw InputError(detail::str("ClearanceBarrier: lambda must be positive and finite, got ", lambda));
    if (!std::isfinite(margin) || margin < 0)
      throw InputError(detail::str("ClearanceBarrier: the margin must be >= 0 and finite, got ", margin));
  }

  void filter(const Model& model, const Data& data, double t, const Eigen::MatrixXd& N,
              Eigen::VectorXd& theta_dot) override {
    if (t != t_target_) {  // the run's times increase (the RK4 stages too): propagate from the last
      target_ = t > t_target_ ? propagate_target(target_, t - t_target_) : propagate_target(initial_, t);
      t_target_ = t;
    }
    const auto n = static_cast<Eigen::Index>(model.n());
    const Pose tp = target_pose(target_);
    cc_->distances(data, tp, ds_);
    const auto pairs = static_cast<Eigen::Index>(ds_.size());
    G_.resize(pairs, n);
    NG_.resize(pairs, n);
    bias_.resize(pairs);
    den_.resize(pairs);
    grad_.resize(n);
    hb_.compute(data.H.topLeftCorner<6, 6>());
    for (Eigen::Index i = 0; i < pairs; ++i) {
      bias_(i) =
          free_floating_distance_rate(model, data, *cc_, ds_[static_cast<size_t>(i)], target_, hb_, grad_);
      G_.row(i) = grad_.transpose();
    }
    NG_.noalias() = G_ * N;  // rows (N g*_i)^T, N symmetric
    for (Eigen::Index i = 0; i < pairs; ++i) den_(i) = NG_.row(i).dot(G_.row(i));
    for (int sweep = 0; sweep < 8; ++sweep) {
      bool changed = false;
      for (Eigen::Index i = 0; i < pairs; ++i) {
        const double d = ds_[static_cast<size_t>(i)].distance;
        if (!std::isfinite(d) || !(den_(i) > 1e-12)) continue;
        const double need = -lambda_ * (d - c_b_) - (G_.row(i).dot(theta_dot) + bias_(i));
        if (need <= 1e-12) continue;
        theta_dot.noalias() += (need / den_(i)) * NG_.row(i).transpose();
        changed = true;
        ++corrections_;
      }
      if (!changed) break;
    }
  }

  /// The corrections made so far (pair by pair, every sweep).
  long corrections() const { return corrections_; }

 private:
  std::shared_ptr<const CollisionChecker> cc_;
  Target initial_, target_;  ///< the target at t = 0 and at t_target_
  double t_target_ = 0;
  double c_b_, lambda_;
  long corrections_ = 0;
  std::vector<PairDistance> ds_;
  Eigen::MatrixXd G_, NG_;
  Eigen::VectorXd bias_, den_, grad_;
  Eigen::LLT<Matrix6> hb_;
};

/// The factory of CaptureOptions::rate_guard for a clearance barrier (ClearanceBarrier) on a run of
/// duration T and RK4 step h (the options'): lambda = min(100 / T, 0.5 / h).
inline std::function<std::unique_ptr<RateGuard>()> clearance_barrier(
    std::shared_ptr<const CollisionChecker> cc, const Target& target0, double clearance,
    const CaptureOptions& opt) {
  if (!std::isfinite(opt.duration) || opt.duration <= 0 || !std::isfinite(opt.step) || opt.step <= 0)
    throw InputError(
        detail::str("clearance_barrier: the duration and the step must be positive and finite, got ",
                    opt.duration, " and ", opt.step));
  const double lambda = std::min(100.0 / opt.duration, 0.5 / opt.step);
  return [cc, target0, clearance, lambda]() -> std::unique_ptr<RateGuard> {
    return std::make_unique<ClearanceBarrier>(cc, target0, clearance, lambda);
  };
}

}  // namespace ffsr
