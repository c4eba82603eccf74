// ffsr/geometry/clearance.hpp -- a clearance for capture plans: the smallest distance of a
// configuration or along a recorded run, the search's inequality constraints
// distance >= clearance (ManifoldInequalities of optimize/global.hpp), and the check of a reaching
// run (GlobalCaptureOptions::check_run). Pairs and the contact exemption: geometry/distance.hpp.
// Component ffsr::geometry.
#pragma once

#include "ffsr/geometry/distance.hpp"
#include "ffsr/model/target.hpp"
#include "ffsr/optimize/global.hpp"

#include <memory>
#include <optional>
#include <sstream>
#include <string>

namespace ffsr {

/// The target frame's pose in o.
inline Pose target_pose(const Target& t) { return {t.position, t.rotation()}; }

namespace detail {

inline ClearanceReport::Entry& entry_of(ClearanceReport& r, PairKind k) {
  return k == PairKind::ArmTarget ? r.arm_target : k == PairKind::ArmBus ? r.arm_bus : r.self;
}

/// Folds the distances of one configuration (at time t) into the report.
inline void fold_clearance(const CollisionChecker& cc, const std::vector<PairDistance>& ds, double t,
                           ClearanceReport& r) {
  for (const PairDistance& d : ds) {
    const PairKind k = cc.pairs()[static_cast<size_t>(d.pair)].kind;
    ClearanceReport::Entry& e = entry_of(r, k);
    if (d.distance < e.distance) e = {d.distance, cc.pair_name(d.pair), t, d.p_a, d.p_b};
    if (d.distance < r.overall.distance) {
      r.overall = {d.distance, cc.pair_name(d.pair), t, d.p_a, d.p_b};
      r.kind = pair_kind_name(k);
    }
  }
}

}  // namespace detail

/// The distances of one configuration (base pose, theta, target pose) as a report (time 0).
/// Runs forward_kinematics.
inline ClearanceReport configuration_clearance(const Model& model, const CollisionChecker& cc, const BasePose& base,
                                               const Eigen::VectorXd& theta, const Pose& target) {
  Data data(model);
  forward_kinematics(model, data, base, theta);
  std::vector<PairDistance> ds;
  cc.distances(data, target, ds);
  ClearanceReport r;
  detail::fold_clearance(cc, ds, 0.0, r);
  return r;
}

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
  for (const BodyPair& p : cc->pairs()) count += p.kind == PairKind::ArmTarget ? static_cast<unsigned>(targets.size()) : 1;
  q->count = count;
  auto data = std::make_shared<Data>(model);
  auto grad = std::make_shared<Eigen::VectorXd>(model.n());
  const Model* m = &model;
  q->eval = [m, cc, data, grad, targets, clearance](const BasePose& base, const Eigen::VectorXd& theta, double* g,
                                                    double* G) {
    forward_kinematics(*m, *data, base, theta);
    const auto n = static_cast<size_t>(m->n());
    size_t row = 0;
    for (size_t i = 0; i < cc->pairs().size(); ++i) {
      const size_t poses = cc->pairs()[i].kind == PairKind::ArmTarget ? targets.size() : 1;
      for (size_t t = 0; t < poses; ++t, ++row) {
        const PairDistance d = cc->pair_distance(*data, targets[t], static_cast<int>(i));
        g[row] = clearance - d.distance;
        if (!G) continue;
        cc->distance_gradient(*m, *data, d, *grad);
        for (size_t k = 0; k < n; ++k) G[row * n + k] = -(*grad)(static_cast<Eigen::Index>(k));
      }
    }
  };
  return q;
}

/// "link3 - target 0.0321 m < clearance 0.05 m at t = 171.3 s", or nothing when the report keeps it
/// (within `tolerance`).
inline std::optional<std::string> clearance_violation(const ClearanceReport& r, double clearance,
                                                      double tolerance = 1e-6) {
  if (r.overall.pair.empty() || r.overall.distance >= clearance - tolerance) return std::nullopt;
  std::ostringstream s;
  s << r.overall.pair << " (" << r.kind << ") " << r.overall.distance << " m < clearance " << clearance
    << " m at t = " << r.overall.time << " s";
  return s.str();
}

}  // namespace ffsr
