// ffsr/io/scenario_geometry.hpp -- a scenario's shapes and clearance (the keys target-shape,
// target-size, target-shape-offset, link-radius, bus-box, clearance, contact-exemption): the
// collision model built with the scenario, its checks (the contact point on the target's surface, the
// start configuration within the clearance), the global run's constraints and path check, and the
// smallest distance of each run. Included by io/scenario.hpp; needs ffsr::geometry (FCL) when a
// scenario uses the keys: without it (FFSR_HAVE_GEOMETRY undefined) such a scenario is refused.
#pragma once

#include "ffsr/geometry/shape.hpp"
#include "ffsr/io/scenario.hpp"

#ifdef FFSR_HAVE_GEOMETRY
#include "ffsr/geometry/clearance.hpp"
#include "ffsr/io/urdf_collision.hpp"
#endif

#include <memory>
#include <string>

namespace ffsr {

/// The geometry keys that make a scenario use shapes (any of them given).
inline bool scenario_uses_geometry(const ScenarioKeys& k) {
  for (const char* key : {"target-shape", "target-size", "target-shape-offset", "link-radius", "bus-box",
                          "clearance", "contact-exemption"})
    if (k.given.count(key)) return true;
  return false;
}

#ifdef FFSR_HAVE_GEOMETRY

struct SceneGeometry {
  std::shared_ptr<const CollisionChecker> checker;
  double clearance = 0;  ///< m; 0: distances reported, not constrained
};

namespace detail {

/// The URDF's collision primitives: from the embedded text of a built-in scenario, else the file.
inline std::vector<LinkShape> scenario_urdf_shapes(const ScenarioKeys& k, const EmbeddedUrdf* embedded) {
  if (embedded && k.urdf == embedded->name)
    return urdf_collision_shapes_from_string(embedded->xml, embedded->source);
  return urdf_collision_shapes(k.urdf);
}

/// Checks that the contact point r_tp lies on the target's surface (within 1e-6 m).
inline void check_contact_on_surface(const Shape& target, const Vector3& r_tp) {
  const double d = point_surface_distance(target, r_tp);
  if (std::abs(d) > 1e-6)
    throw InputError(str("--contact-offset: the contact point is ", std::abs(d), " m ", d > 0 ? "outside" : "inside",
                         " the target-shape's surface (it must lie on it)"));
}

/// Checks that the start configuration keeps the clearance (the pair and its distance otherwise).
inline void check_start_clearance(const Scenario& sc, const SceneGeometry& g) {
  const ClearanceReport r = configuration_clearance(*sc.model, *g.checker, sc.problem.base, sc.problem.theta,
                                                    target_pose(sc.problem.target));
  if (!r.overall.pair.empty() && r.overall.distance < g.clearance)
    throw InputError(str("--clearance: the start configuration is already closer than ", g.clearance, " m: ",
                         r.overall.pair, " (", r.kind, ") ", r.overall.distance, " m"));
}

}  // namespace detail

/// The scenario's geometry (null when it uses none of the keys). InputError naming the key.
inline std::shared_ptr<const SceneGeometry> scenario_geometry(const Scenario& sc, const EmbeddedUrdf* embedded) {
  using detail::str;
  const ScenarioKeys& k = sc.keys;
  if (!scenario_uses_geometry(k)) return nullptr;
  if (!std::isfinite(k.clearance) || k.clearance < 0)
    throw InputError(str("--clearance: must be >= 0 and finite, got ", k.clearance));
  std::optional<Shape> target;
  if (!k.target_shape.empty()) {
    target = target_shape_of(k.target_shape, k.target_size, k.target_shape_offset);
    detail::check_contact_on_surface(*target, sc.problem.target.contact_offset);
  } else if (k.given.count("target-size") || k.given.count("target-shape-offset")) {
    throw InputError("--target-size: needs --target-shape");
  }
  const RobotGeometry rg =
      robot_geometry(*sc.model, detail::scenario_urdf_shapes(k, embedded), k.link_radius, k.bus_box);
  auto g = std::make_shared<SceneGeometry>();
  g->checker = std::make_shared<CollisionChecker>(*sc.model, rg, target, k.contact_exemption);
  g->clearance = k.clearance;
  if (g->clearance > 0) detail::check_start_clearance(sc, *g);
  return g;
}

/// The global run's clearance: the search's constraints at the target's pose at T and the check of
/// each reaching run along its path. Nothing when the scenario has no clearance.
inline void apply_clearance(const Scenario& sc, GlobalCaptureOptions& g) {
  const SceneGeometry* geo = sc.geometry.get();
  if (!geo || !(geo->clearance > 0)) return;
  // the target at T and every 2 s over the 30 s before (the reaching run is checked along its path)
  std::vector<Pose> poses;
  Target t = propagate_target(sc.problem.target, sc.capture.duration);
  const double dt = 2.0;
  for (double back = 0; back <= std::min(30.0, sc.capture.duration) + 1e-9; back += dt) {
    poses.push_back(target_pose(t));
    t = propagate_target(t, -dt);
  }
  g.search.inequalities = clearance_constraints(*sc.model, geo->checker, poses, geo->clearance);
  const Model* m = sc.model.get();
  const Target t0 = sc.problem.target;
  std::shared_ptr<const CollisionChecker> cc = geo->checker;
  const double c = geo->clearance;
  g.check_run = [m, t0, cc, c](const CaptureResult& run) {
    return clearance_violation(path_clearance(*m, *cc, t0, run), c);
  };
}

/// The smallest distances along a run (its series recorded).
inline ClearanceReport run_clearance(const Scenario& sc, const CaptureResult& run) {
  return path_clearance(*sc.model, *sc.geometry->checker, sc.problem.target, run);
}

#else

struct SceneGeometry {};

inline std::shared_ptr<const SceneGeometry> scenario_geometry(const Scenario& sc, const EmbeddedUrdf*) {
  if (scenario_uses_geometry(sc.keys))
    throw InputError("--clearance: this build has no geometry (ffsr::geometry needs FCL, Debian libfcl-dev)");
  return nullptr;
}
inline void apply_clearance(const Scenario&, GlobalCaptureOptions&) {}
inline ClearanceReport run_clearance(const Scenario&, const CaptureResult&) { return {}; }

#endif

}  // namespace ffsr
