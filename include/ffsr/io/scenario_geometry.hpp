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
#include "ffsr/optimize/clearance.hpp"
#include "ffsr/optimize/global.hpp"
#include "ffsr/io/urdf_collision.hpp"
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

namespace detail {

/// The target's poses at the times `times` (s from the start).
inline std::vector<Pose> target_poses(const Target& t0, std::vector<double> times) {
  std::sort(times.begin(), times.end());
  std::vector<Pose> poses;
  Target t = t0;
  double at = 0;
  for (double x : times) {
    t = propagate_target(t, x - at);
    at = x;
    poses.push_back(target_pose(t));
  }
  return poses;
}

}  // namespace detail

/// The global run with the scenario's clearance (plan_capture_global as is without one). The search
/// keeps distance >= clearance at its capture configurations (base at its pose at T) against the
/// target at T and at the times of `sweep_times` before it (every 3 s over the last 30 s: the space the
/// tumbling target sweeps while the arm, nearly at rest, closes in); each reaching run is checked
/// along its path. When every reached goal fails that check, the target's poses 3 s before, at and
/// 3 s after each arm-target violation of an approach (one during a reconfiguration, with the arm
/// far from its capture configuration, only rejects its run), and after the first round also every
/// 10 s over the last 90 s, are added to the search's constraints and the plan is made again (up
/// to 4 rounds, each asking the search for a wider margin beyond the clearance: 1 %, 3 %, 9 %); the
/// last error is thrown when none keeps the clearance.
inline GlobalCaptureResult plan_global_with_clearance(const Scenario& sc, const CaptureOptions& opt,
                                                      GlobalCaptureOptions g) {
  const SceneGeometry* geo = sc.geometry.get();
  if (!geo || !(geo->clearance > 0)) return plan_capture_global(sc.problem, sc.task, opt, g);
  const double T = sc.capture.duration;
  std::vector<double> times;
  for (double back = 0; back <= std::min(30.0, T) + 1e-9; back += 3.0) times.push_back(T - back);
  const Model* m = sc.model.get();
  const Target t0 = sc.problem.target;
  std::shared_ptr<const CollisionChecker> cc = geo->checker;
  const double c = geo->clearance;
  auto violations = std::make_shared<std::vector<double>>();
  const std::shared_ptr<const ManifoldInequalities> given = g.search.inequalities;  // e.g. the base rate
  g.check_run = [m, t0, cc, c, violations](const CaptureResult& run, double approach_begin) {
    const ClearanceReport r = path_clearance(*m, *cc, t0, run);
    std::optional<std::string> why = clearance_violation(r, c);
    // the target's pose at a violation constrains the capture configuration in the next round; a
    // violation during a reconfiguration (the arm far from that configuration) rejects the run only
    if (why && r.kind == "arm-target" && r.overall.time >= approach_begin)
      violations->push_back(r.overall.time);
    return why;
  };
  double margin = 0;  // the search's distance bound beyond the clearance
  for (int round = 1;; ++round) {
    g.search.inequalities = combine_inequalities(
        given, clearance_constraints(*m, cc, detail::target_poses(t0, times), c + margin));
    violations->clear();
    try {
      GlobalCaptureResult r = plan_capture_global(sc.problem, sc.task, opt, g);
      r.search_distance_bound = c + margin;
      return r;
    } catch (const NumericalError&) {
      if (round == 4 || violations->empty()) throw;
    }
    for (double tv : *violations)
      for (double x : {tv - 3.0, tv, tv + 3.0}) times.push_back(std::clamp(x, 0.0, T));
    // a reaching run lands near, not on, the searched configuration: where the bound is active there,
    // the run may fall short of it by a little (0.4 mm on the Panda example), so each new round also
    // asks the search for a margin (1 %, 3 %, 9 % of the clearance)
    margin = margin == 0 ? 0.01 * c : 3 * margin;
    if (round == 1)  // a wider sweep: every 10 s over the last 90 s
      for (double back = 40; back <= std::min(90.0, T) + 1e-9; back += 10.0) times.push_back(T - back);
  }
}

/// The smallest distances along a run (its series recorded).
inline ClearanceReport run_clearance(const Scenario& sc, const CaptureResult& run) {
  return path_clearance(*sc.model, *sc.geometry->checker, sc.problem.target, run);
}

/// With the scenario's clearance, the plain and the paper's-method runs keep it through the clearance
/// barrier (ClearanceBarrier: a null-space filter of their joint rates); without one, nothing.
inline void add_clearance_barrier(const Scenario& sc, CaptureOptions& opt) {
  const SceneGeometry* geo = sc.geometry.get();
  if (!geo || !(geo->clearance > 0)) return;
  opt.rate_guard = clearance_barrier(geo->checker, sc.problem.target, geo->clearance, opt);
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
inline GlobalCaptureResult plan_global_with_clearance(const Scenario& sc, const CaptureOptions& opt,
                                                      GlobalCaptureOptions g) {
  return plan_capture_global(sc.problem, sc.task, opt, g);
}
inline ClearanceReport run_clearance(const Scenario&, const CaptureResult&) { return {}; }
inline void add_clearance_barrier(const Scenario&, CaptureOptions&) {}

#endif

}  // namespace ffsr
