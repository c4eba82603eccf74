// ffsr/geometry/clearance.hpp -- the clearance of a configuration: its smallest distances as a
// report (overall and per kind of pair), the free-floating rate of a pair's distance, and the
// message of a report below a clearance. Needs the model and its kinematics only; the planner's uses
// of a clearance are in optimize/clearance.hpp, the pairs and the contact exemption in
// geometry/distance.hpp. Component ffsr::geometry.
#pragma once

#include "ffsr/algorithm/crba.hpp"
#include "ffsr/geometry/distance.hpp"
#include "ffsr/model/target.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

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
inline ClearanceReport configuration_clearance(const Model& model, const CollisionChecker& cc,
                                               const BasePose& base, const Eigen::VectorXd& theta,
                                               const Pose& target) {
  Data data(model);
  forward_kinematics(model, data, base, theta);
  std::vector<PairDistance> ds;
  cc.distances(data, target, ds);
  ClearanceReport r;
  detail::fold_clearance(cc, ds, 0.0, r);
  return r;
}

/// The free-floating rate of the distance of pair `d` (at the kinematics and data.H of `data`, crba
/// run; the target in its state at that time): d_dot = g*^T theta_dot + b for joint rates theta_dot
/// with zero momentum (see ClearanceBarrier). `hb`: the Cholesky factor of H_b (data.H's top-left
/// 6 x 6). Writes g (n); returns b (the target's motion; 0 for a pair of two robot bodies).
inline double free_floating_distance_rate(const Model& model, const Data& data, const CollisionChecker& cc,
                                          const PairDistance& d, const Target& target,
                                          const Eigen::LLT<Matrix6>& hb, Eigen::Ref<Eigen::VectorXd> g) {
  cc.distance_gradient(model, data, d, g);
  if (!std::isfinite(d.distance) || d.distance == 0 ||
      cc.pairs()[static_cast<size_t>(d.pair)].kind != PairKind::ArmTarget)
    return 0;
  const Vector3 u = (d.p_a - d.p_b) / d.distance;
  Vector6 w;
  w << u, (d.p_a - data.p[0]).cross(u);
  g.noalias() -= data.H.topRightCorner(6, model.n()).transpose() * hb.solve(w);
  return -u.dot(target.velocity + target.angular_velocity_world().cross(d.p_b - target.position));
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
