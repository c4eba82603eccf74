// ffsr/jobs/scenario_run.hpp -- the main job of a scenario (ffsr/scenario/scenario.hpp): the plain run
// (rho = 0, the baseline task), the paper's method (the optimized run, Eq. 29-31) and the global run,
// as one result struct, and that result as JSON (the keys and values of `ffsr-optimize --json`; the
// schema is written in jobs/detail/result_json.hpp). Component ffsr::scenario. Never prints; progress
// goes to the callbacks of ScenarioRunOptions.
#pragma once

#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/detail/detumble_result.hpp"
#include "ffsr/jobs/detail/post_capture.hpp"
#include "ffsr/jobs/scenario_clearance.hpp"
#include "ffsr/optimize/branches.hpp"
#include "ffsr/optimize/pareto.hpp"
#include "ffsr/uncertainty/robust_objective.hpp"

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

// jobs/ is the layer above the scenario keys (scenario/): it runs what a scenario describes.

namespace ffsr {

/// The global run and what the outputs need beside it.
struct GlobalRun {
  GlobalCaptureResult result;
  /// the objective at the paper's-method run's capture configuration (NaN without that run)
  double paper_objective = 0;
  /// the distinct local optima of the last search (at the reached base pose), sorted by objective
  std::vector<CaptureBranch> branches;
  /// With post-capture constraints (max-time-to-rest, ...): the post-capture figures at the reached
  /// capture configuration, and the candidate runs of the search (how many met the constraints).
  std::optional<PostCaptureFigures> post_capture;
  int post_capture_candidates = 0, post_capture_admitted = 0;
};

/// The tail measure of one row over the robust-force objective's sample set, N.
struct RobustRow {
  std::string name;  ///< baseline, optimized, global
  double cvar95 = 0, p95 = 0;
};

struct ScenarioResult {
  CaptureResult plain, optimized;
  /// With ScenarioRunOptions::keep_going: the error of the plain or the optimized run when it failed
  /// (its CaptureResult is then empty and is not reported); empty when the run succeeded.
  std::string plain_failure, optimized_failure;
  bool plain_ok() const { return plain_failure.empty(); }
  bool optimized_ok() const { return optimized_failure.empty(); }
  /// The first run that succeeded (plain, optimized, global): the capture point and the approach
  /// velocity are the same in every run.
  const CaptureResult& first_run() const {
    return plain_ok() ? plain : optimized_ok() || !global ? optimized : global->result.run;
  }
  std::optional<GlobalRun> global;  ///< unless the scenario's global = false
  /// objective = robust-force: the search's sample set, its table and each row's tail measure
  std::shared_ptr<RobustForceObjective> robust;
  UncertaintySpec robust_spec;
  std::vector<RobustRow> robust_rows;
  /// with shapes (scenario/geometry.hpp, jobs/scenario_clearance.hpp): each run's smallest
  /// distances along its path
  std::vector<std::pair<std::string, ClearanceReport>> clearances;  ///< baseline, optimized, global
  /// With a Detumble key given (scenario_has_post_capture), when the main job runs as the whole capture
  /// (run_whole_capture, jobs/whole_capture.hpp): the post-capture phase of each run that holds a
  /// result, as the job `detumble --run all` runs it (jobs/detumble.hpp), in the order baseline,
  /// optimized, global (DetumbleJobResult::run); scenario_json writes each as the run's post_capture.
  std::vector<DetumbleJobResult> post_capture;
};

struct ScenarioRunOptions {
  bool record_series = false;  ///< keep the time series of every run (CaptureResult::series)
  std::function<void(double)> plain_progress, optimized_progress;  ///< fraction done, optional
  /// When the global run follows (global = true): a plain or optimized run that fails (a
  /// NumericalError: the line cannot be followed, a joint limit) is recorded in
  /// ScenarioResult::plain_failure / optimized_failure and the job goes on, so that a capture only
  /// the global run reaches (a grasp orientation that needs a reconfiguration) is still planned. The
  /// global run then has no paper's-method start; when it fails too, the error names both failures.
  /// Default: the first failure is thrown (plan_plain_and_optimized).
  bool keep_going = false;
};

/// Whether a scenario asks for the post-capture phase: it gives (file or override) a key of the
/// Detumble group (joint-torque-limit, base-actuator, rest-rate-deg, ...).
inline bool scenario_has_post_capture(const ScenarioKeys& keys) {
  for (const ScenarioKey& key : scenario_keys())
    if (key.group == KeyGroup::Detumble && keys.given.count(key.name)) return true;
  return false;
}

/// The plain and the optimized run of a scenario of scope Run (std::invalid_argument for another). A
/// NumericalError names the run ("plain run: ...").
std::pair<CaptureResult, CaptureResult> plan_plain_and_optimized(const Scenario& sc,
                                                                 const ScenarioRunOptions& options = {});

/// The seed of the robust-force objective's sample set: the table's seed + 1, so that the search's
/// samples are independent of the ones `robust` evaluates with the same table (an out-of-sample check).
inline std::uint64_t robust_objective_seed(const UncertaintySpec& spec) { return spec.seed + 1; }
/// The robust-force objective of a scenario: spec.samples samples (seed robust_objective_seed)
/// around the nominal target at T, the scenario's contact and law.
std::shared_ptr<RobustForceObjective> scenario_robust_objective(const Scenario& sc,
                                                                const UncertaintySpec& spec);

/// Plans the global run: the optimized run's task, no gain, the joint-rate limit, the paper's-method
/// capture configuration as an extra start (so the global row is never worse than it). `robust`:
/// the sample set of the robust-force objective (null otherwise). The reaching runs stop within
/// 1 % of the manifold optimum, 0.01 % for robust-force or with `tight_reaching`. Errors name the run.
GlobalRun run_global(const Scenario& sc, const CaptureResult& paper_run, GlobalObjective objective,
                     std::shared_ptr<RobustForceObjective> robust = nullptr, bool tight_reaching = false);
/// As above without a paper's-method run (it failed): no extra start, GlobalRun::paper_objective NaN.
GlobalRun run_global(const Scenario& sc, GlobalObjective objective,
                     std::shared_ptr<RobustForceObjective> robust = nullptr, bool tight_reaching = false);

/// The main job: plain, optimized and (unless global = false) global runs; robust-force reads the
/// scenario's [uncertainty] table. The scenario's scope is Run (std::invalid_argument for another).
/// The runs stop at the impact: run_whole_capture (jobs/whole_capture.hpp) adds the post-capture phase.
ScenarioResult run_scenario(const Scenario& sc, const ScenarioRunOptions& options = {});

/// The result as JSON: the resolved scenario, the model as loaded, each run, the reductions, the
/// global and the robust rows (`version` is recorded as given).
nlohmann::json scenario_json(const Scenario& sc, const ScenarioResult& r, const std::string& version);

/// The number of the global run's first samples that belong to its reconfiguration (0: none).
long reconfiguration_samples(const ScenarioResult& r);

/// The time series of every run that holds a result (CaptureResult::series: record_series on), as
/// the CSV of `ffsr-optimize --csv`: one row per sample and run (column `run`: baseline, optimized,
/// global), t, the joint angles (deg), the base pose, the end-effector, M_ie, the F_max estimate,
/// the target's pose (propagated from the start, sample to sample), the pose of every moving body
/// (body<i>, i as in the JSON's scene.bodies: its joint frame) and the phase (reconfiguration or
/// approach). A pose is x, y, z (m) and the unit quaternion qw, qx, qy, qz, in the inertial frame.
std::string scenario_series_csv(const Scenario& sc, const ScenarioResult& r);

/// Reduction of `after` against `before`, percent: 100 (before - after) / before.
inline double reduction_percent(double before, double after) { return 100.0 * (before - after) / before; }

}  // namespace ffsr

#include "ffsr/jobs/detail/scenario_run.hxx"
#include "ffsr/jobs/detail/base_disturbance_json.hpp"
#include "ffsr/jobs/detail/scenario_series.hpp"
#include "ffsr/jobs/detail/result_json.hpp"
