// ffsr/scenario/geometry.hpp -- a scenario's shapes and clearance (the keys target-shape, target-size,
// target-shape-offset, link-radius, bus-box, clearance, contact-exemption): the collision model built
// with the scenario and its checks; the runs that use it are in ffsr/jobs/scenario_clearance.hpp.
// Needs ffsr::geometry (FCL) when a scenario uses the keys: without it (FFSR_HAVE_GEOMETRY undefined)
// such a scenario is refused.
#pragma once

#include "ffsr/geometry/shape.hpp"
#include "ffsr/scenario/scenario.hpp"

#ifdef FFSR_HAVE_GEOMETRY
#include "ffsr/geometry/clearance.hpp"
#include "ffsr/parsers/urdf_collision.hpp"
#endif

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

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

/// A distance in a message: 6 significant digits.
inline std::string metres(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

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
    throw InputError(str("--contact-offset: the contact point is ", metres(std::abs(d)), " m ",
                         d > 0 ? "outside" : "inside", " the target-shape's surface (it must lie on it)"));
}

/// Checks that the start configuration keeps the clearance (the pair and its distance otherwise).
inline void check_start_clearance(const Scenario& sc, const SceneGeometry& g) {
  const ClearanceReport r = configuration_clearance(*sc.model, *g.checker, sc.problem.base, sc.problem.theta,
                                                    target_pose(sc.problem.target));
  if (!r.overall.pair.empty() && r.overall.distance < g.clearance)
    throw InputError(str("--clearance: the start configuration is already closer than ", metres(g.clearance),
                         " m: ", r.overall.pair, " (", r.kind, ") ", metres(r.overall.distance), " m"));
}

}  // namespace detail

/// The shapes of the keys for `model` and a target with contact point `r_tp` (null when none of the
/// keys is given), without the start configuration's check. InputError naming the key.
inline std::shared_ptr<const SceneGeometry> scene_geometry(const ScenarioKeys& k, const Model& model,
                                                           const Vector3& r_tp,
                                                           const EmbeddedUrdf* embedded) {
  using detail::str;
  if (!scenario_uses_geometry(k)) return nullptr;
  if (!std::isfinite(k.clearance) || k.clearance < 0)
    throw InputError(str("--clearance: must be >= 0 and finite, got ", k.clearance));
  std::optional<Shape> target;
  if (!k.target_shape.empty()) {
    target = target_shape_of(k.target_shape, k.target_size, k.target_shape_offset);
    detail::check_contact_on_surface(*target, r_tp);
  } else if (k.given.count("target-size") || k.given.count("target-shape-offset")) {
    throw InputError("--target-size: needs --target-shape");
  }
  const RobotGeometry rg =
      robot_geometry(model, detail::scenario_urdf_shapes(k, embedded), k.link_radius, k.bus_box);
  auto g = std::make_shared<SceneGeometry>();
  g->checker = std::make_shared<CollisionChecker>(model, rg, target, k.contact_exemption);
  g->clearance = k.clearance;
  return g;
}

/// The scenario's geometry (null when it uses none of the keys); the start configuration must keep
/// the clearance. InputError naming the key.
inline std::shared_ptr<const SceneGeometry> scenario_geometry(const Scenario& sc,
                                                              const EmbeddedUrdf* embedded) {
  std::shared_ptr<const SceneGeometry> g =
      scene_geometry(sc.keys, *sc.model, sc.problem.target.contact_offset, embedded);
  if (g && g->clearance > 0) detail::check_start_clearance(sc, *g);
  return g;
}

#else

struct SceneGeometry {};

inline std::shared_ptr<const SceneGeometry> scene_geometry(const ScenarioKeys& k, const Model&,
                                                           const Vector3&, const EmbeddedUrdf*) {
  if (scenario_uses_geometry(k))
    throw InputError("--clearance: this build has no geometry (ffsr::geometry needs FCL, Debian libfcl-dev)");
  return nullptr;
}
inline std::shared_ptr<const SceneGeometry> scenario_geometry(const Scenario& sc,
                                                              const EmbeddedUrdf* embedded) {
  return scene_geometry(sc.keys, *sc.model, sc.problem.target.contact_offset, embedded);
}
#endif

}  // namespace ffsr
