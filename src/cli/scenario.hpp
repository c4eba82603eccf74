// src/cli/scenario.hpp -- the main job's scenario, shared with the subcommands that start from it
// (robust): its keys, the problem they describe, the plain and optimized planning runs, and the
// progress line on a terminal.
#pragma once

#include "common.hpp"
#include "model_options.hpp"

#include "ffsr/optimize/capture.hpp"
#include "ffsr/optimize/global.hpp"
#include "ffsr/uncertainty/robust_objective.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ffsr::cli {

/// The keys of a scenario (each is a flag and a key of the --config file).
struct RunOptions {
  std::string config;
  std::string urdf, end_effector;
  std::vector<double> joints_deg, base_position{0, 0, 0}, base_rpy_deg{0, 0, 0};
  double target_mass = 0;
  std::vector<double> target_inertia, target_position, target_rpy_deg{0, 0, 0}, target_angular_velocity_deg,
      target_velocity{0, 0, 0}, contact_offset, normal;
  std::string model;
  double stiffness = 0, exponent = 0, restitution = 0, approach_speed = 0;
  std::string task, task_axes = "xyz", baseline_task;
  std::vector<double> final_rpy_deg;
  double duration = 0, step = 0, gain = 0, feedback = 1.0, tolerance = 0, orientation_tolerance_deg = 0.5;
  std::string objective = "mass";
  bool global = true;      ///< the third row: global capture optimization (issue 9)
  std::string seed = "1";  ///< parsed by the command, so a bad value is a one-line error naming the key
  double max_joint_rate_deg = 0;  ///< 0: not set (the global run is then not rate limited)
  int global_starts = 32;
  std::string json, csv, plot, plot_format = "png";
  std::string expect;  ///< a stored result to compare with (regression run)
  double rtol = 1e-6, atol = 1e-9;
  bool quiet = false;
  ModelLoadOptions load;  ///< bus, locks, repairs, end-effector offset (model_options.hpp)
};

/// Registers the scenario keys (everything but --config, --json, --csv, --quiet) on `app`.
void add_scenario_options(CLI::App& app, RunOptions& o);

/// A validated scenario: the robot, the capture problem, the tasks of the optimized and the plain
/// run, and the optimized run's options (the plain run uses gain 0).
struct Scenario {
  RunOptions options;  ///< as resolved (the URDF path relative to the scenario file)
  std::string where;   ///< "scenario FILE" or "built-in scenario", for messages
  bool builtin = false;
  std::unique_ptr<Model> model;
  CaptureProblem problem;  ///< problem.model points to *model
  CaptureTask task, baseline_task;
  CaptureOptions capture;
  UrdfReport report;  ///< what the loader did to the file (merged links, mimic and locked joints, repairs)
};

/// Checks the keys (a scenario file must name kRequired; `app` tells which were given) and builds
/// the problem. `urdf_on_command_line`: the URDF path is not resolved against the file's folder.
Scenario prepare_scenario(RunOptions o, const CLI::App& app, bool urdf_on_command_line);

/// The main job's two planning runs: plain (rho = 0, the baseline task) and optimized. A
/// NumericalError names the run. Progress on a terminal unless `quiet`.
std::pair<CaptureResult, CaptureResult> plan_plain_and_optimized(const Scenario& sc, bool quiet);

/// The global run (issue 9) and what the outputs need beside it.
struct GlobalRun {
  GlobalCaptureResult result;
  double paper_objective = 0;  ///< the objective at the paper's-method run's capture configuration
};
/// The objective named as the scenario key `objective` spells it (mass for an unknown name: the
/// scenario was validated before).
GlobalObjective global_objective(const std::string& name);
/// Plans the global run: the optimized run's task, no gain, the joint-rate limit, the paper's-method
/// capture configuration as an extra start (so the global row is never worse than it). `robust`:
/// the sample set of the robust-force objective (null otherwise). The reaching runs stop within
/// 1 % of the manifold optimum, 0.01 % for robust-force or with `tight_reaching`. Errors name the run.
GlobalRun run_global(const Scenario& sc, const CaptureResult& paper_run, GlobalObjective objective,
                     std::shared_ptr<RobustForceObjective> robust = nullptr, bool tight_reaching = false);

/// The [uncertainty] table of a scenario file (read with toml++; robust.cpp). InputError naming the
/// file and key.
UncertaintySpec read_uncertainty_table(const std::string& config, const std::string& where);
/// The seed of the robust-force objective's sample set: the table's seed + 1, so that the search's
/// samples are independent of the ones `robust` evaluates with the same table (an out-of-sample check).
inline std::uint64_t robust_objective_seed(const UncertaintySpec& spec) { return spec.seed + 1; }
/// The robust-force objective of a scenario: spec.samples samples (seed robust_objective_seed)
/// around the nominal target at T, the scenario's contact and law.
std::shared_ptr<RobustForceObjective> scenario_robust_objective(const Scenario& sc,
                                                                const UncertaintySpec& spec);

/// CLI11's TOML reader for the main job: drops the [uncertainty] table (read by `robust` with a
/// full TOML parser: CLI11 2.1 does not parse its inline tables), keeps every other key.
class ScenarioConfig : public CLI::ConfigTOML {
 public:
  std::vector<CLI::ConfigItem> from_config(std::istream& input) const override {
    std::vector<CLI::ConfigItem> all = CLI::ConfigTOML::from_config(input);
    std::vector<CLI::ConfigItem> kept;
    for (auto& item : all)
      if (item.parents.empty() || item.parents.front() != "uncertainty") kept.push_back(std::move(item));
    return kept;
  }
};

}  // namespace ffsr::cli
