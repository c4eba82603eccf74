// ffsr/jobs/scenario_clearance.hpp -- the runs of a scenario with shapes and a clearance
// (the scene of ffsr/scenario/geometry.hpp): the global run's constraints and path check, the
// clearance barrier of the plain and the paper's-method runs, and the smallest distances of a run.
// Without ffsr::geometry (FFSR_HAVE_GEOMETRY undefined) a scenario has no scene and these do nothing.
#pragma once

#include "ffsr/scenario/scenario.hpp"

#ifdef FFSR_HAVE_GEOMETRY
#include "ffsr/optimize/clearance.hpp"
#include "ffsr/optimize/global.hpp"
#endif

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ffsr {

#ifdef FFSR_HAVE_GEOMETRY

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

inline GlobalCaptureResult plan_global_with_clearance(const Scenario& sc, const CaptureOptions& opt,
                                                      GlobalCaptureOptions g) {
  return plan_capture_global(sc.problem, sc.task, opt, g);
}
inline ClearanceReport run_clearance(const Scenario&, const CaptureResult&) { return {}; }
inline void add_clearance_barrier(const Scenario&, CaptureOptions&) {}

#endif

}  // namespace ffsr
