// ffsr/jobs/robust.hpp -- the Monte Carlo of the maximum contact force over a scenario's
// [uncertainty] table (the job of `ffsr-optimize robust`), as library types: the capture
// configurations to evaluate, the run over the samples of one shard (RobustRun), its summary
// (RobustSummary: percentiles, tail, every sample's F_max; to_json() is the command's --json) and
// the exact merge of shard summaries (merge_shards). Component ffsr::scenario. Never prints.
#pragma once

#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/objective.hpp"
#include "ffsr/uncertainty/multibody.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

// Samples depend on (seed, index) only and are common to all configurations, so a shard's summary
// keeps every sample's F_max and merge_shards concatenates them by index and recomputes the summary:
// the merged percentiles, mean and tail are those of the unsharded run, bit for bit.
//
//   ffsr::Scenario sc = ffsr::load_scenario("robots/paper_7dof_position_uncertain.toml");
//   ffsr::RobustJobOptions o;                        // exact F_max, all samples
//   ffsr::RobustRun run = ffsr::run_robust(sc, ffsr::uncertainty_spec(sc.keys),
//                                          ffsr::planned_robust_configurations(sc), o);
//   ffsr::RobustSummary s = ffsr::robust_summary(sc, run, "uncertain.toml", "0.1.0");
//   double p95 = s.configurations.front().summary.p95;

namespace ffsr {

/// Tail samples kept per configuration (the largest F_max), in a summary and across a merge.
constexpr std::size_t kRobustTail = 5;

/// A capture configuration to evaluate on every sample.
struct RobustConfiguration {
  std::string name;  ///< plain, optimized, global, robust, or given
  Eigen::VectorXd theta;
  BasePose base;
};

/// The configurations the main job plans: plain, optimized and (unless global = false) global -- for
/// objective robust-force the nominal global run (mass) beside the robust one, on the same samples.
/// `run`: progress callbacks of the plain and the optimized runs.
std::vector<RobustConfiguration> planned_robust_configurations(const Scenario& sc,
                                                               const ScenarioRunOptions& run = {});

/// The keys of robust's scenario: the global runs use seed 1 (the job's `seed` is the Monte Carlo
/// seed, uncertainty.seed; a top-level `seed` key of the file is not the global search's here).
inline void robust_global_seed(ScenarioKeys& keys) {
  keys.seed = "1";
  keys.given.erase("seed");
}

/// A capture configuration given by its joint angles (deg) and base pose (m, deg): named "given" (the
/// command's --capture-joints-deg, --capture-base-position, --capture-base-rpy-deg, which errors name).
RobustConfiguration given_robust_configuration(const Model& model, const std::vector<double>& joints_deg,
                                               const std::vector<double>& base_position = {0, 0, 0},
                                               const std::vector<double>& base_rpy_deg = {0, 0, 0});

/// The force model's name as the command spells it: closed, exact or multibody; InputError naming
/// --force-model otherwise.
ForceModel robust_force_model(const std::string& name);
const char* robust_force_model_name(ForceModel model);

struct RobustJobOptions {
  ForceModel force_model = ForceModel::Exact;
  std::uint64_t shard_k = 0, shard_n = 1;  ///< evaluate shard K of N of the samples
  int threads = 1;
  /// Work done and total (samples drawn and evaluated, per configuration), from one thread; optional.
  std::function<void(std::uint64_t, std::uint64_t)> progress;
};

/// What a run evaluated: this shard's samples and each configuration's F_max on them.
struct RobustRun {
  UncertaintySpec spec;
  RobustJobOptions options;
  std::uint64_t first = 0, end = 0;  ///< the shard's samples [first, end)
  UncertainNominal nominal;          ///< the target at T, the scenario's contact and approach speed
  std::vector<UncertainSample> samples;  ///< shard-local index
  struct Evaluated {
    RobustConfiguration configuration;
    SampleForce nominal;               ///< on the nominal sample (no spread)
    std::vector<SampleForce> forces;   ///< per sample, shard-local index
  };
  std::vector<Evaluated> configurations;
  std::uint64_t redraws = 0;  ///< samples redrawn by the physical rules
};

/// The job's options against the scenario, before anything is planned or drawn: InputError on a bad
/// shard or thread count, or on the multibody force model with a joint model other than free (it
/// simulates the joints free). run_robust calls it.
void check_robust_job(const Scenario& sc, const RobustJobOptions& options);

/// Draws the shard's samples of `spec` around the scenario's target at T and evaluates F_max of every
/// configuration on each, on options.threads threads. InputError on a bad shard or thread count.
RobustRun run_robust(const Scenario& sc, const UncertaintySpec& spec, std::vector<RobustConfiguration> configs,
                     const RobustJobOptions& options);

/// One sample of a configuration's tail: its F_max and what made it extreme.
struct RobustTailSample {
  std::uint64_t index = 0;
  SampleForce force;
  nlohmann::json extreme;     ///< the three most extreme quantities: [{quantity, score}]
  nlohmann::json parameters;  ///< the sample's parameters by name (SI units, spin deg/s)
};

/// One configuration of a summary.
struct RobustConfigurationSummary {
  std::string name;
  std::vector<double> joints_deg, base_position, base_quaternion_wxyz;
  SampleForce nominal;
  std::vector<double> f_max;             ///< every sample's F_max of the summary, by index
  std::vector<RobustTailSample> tail;    ///< the largest F_max (at most kRobustTail), largest first
  ForceSummary summary;                  ///< of f_max (finish_robust_summary)
};

/// The summary of a run or of merged shards (the JSON of `ffsr-optimize robust --json`).
struct RobustSummary {
  std::string version;
  std::string source, urdf, model;  ///< the scenario: file, robot, damping law
  double duration = 0;
  std::string force_model, law;
  std::uint64_t seed = 0, samples = 0;
  std::uint64_t shard_k = 0, shard_n = 1, first = 0, end = 0;
  std::optional<std::uint64_t> merged_from;  ///< the number of shard summaries merged
  nlohmann::json uncertainty;                ///< the [uncertainty] table as drawn
  bool stiffness_conditional = false;        ///< the percentiles' estimator (sampling.hpp)
  double stiffness_nominal = 0;
  std::vector<double> stiffness, exponent;  ///< per sample, by index (stiffness-conditional only)
  std::uint64_t redraws = 0;
  std::vector<RobustConfigurationSummary> configurations;
  /// The robust configuration against the nominal global one on the same samples (p95 ratio and,
  /// stiffness-conditional, its paired interval); absent without both.
  std::optional<PercentileRatio> robust_vs_global;

  nlohmann::json to_json() const;
  /// A summary read back (a shard's --json); InputError naming `where` when it is not one. What a
  /// summary derives from its samples is not read: finish_robust_summary (merge_shards) computes it.
  static RobustSummary from_json(const nlohmann::json& j, const std::string& where);
};

/// The summary of a run (`source`: the scenario file as given; `version` recorded as given).
RobustSummary robust_summary(const Scenario& sc, const RobustRun& run, const std::string& source,
                             const std::string& version);
/// Recomputes what a summary derives from its samples: each configuration's ForceSummary, the tails
/// (largest first, at most kRobustTail) and robust_vs_global.
void finish_robust_summary(RobustSummary& s);
/// The summary of the shards together (any order): InputError when they are not shards of one run
/// (seed, samples, laws, scenario differ), or leave gaps or overlaps.
RobustSummary merge_shards(std::vector<RobustSummary> parts);

}  // namespace ffsr

#include "ffsr/jobs/detail/robust.hxx"
