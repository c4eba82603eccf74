// ffsr-optimize robust --config SCENARIO.toml [flags]: Monte Carlo of the maximum contact force over
// what is not known about the target (the scenario's [uncertainty] table), for the capture
// configurations of the main job or one given with --capture-joints-deg. The job, its summary and
// the exact merge of shards (--merge) are the library's (ffsr/jobs/robust.hpp); this file turns flags
// into the job's options and prints the summary.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "figures/plot.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/robust.hpp"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

// The scenario file (its keys and its [uncertainty] table) is read by the library's one reader
// (ffsr/scenario/scenario.hpp); a flag overrides a key of the file.

namespace ffsr::cli {
namespace {

using detail::str;

struct RobustOptions : OutputKeys {
  ScenarioFlags flags;  ///< the scenario keys as flags (a flag overrides the file)
  std::string config;
  std::string force_model = "exact";
  std::string samples, seed, shard = "0/1";
  int threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<double> capture_joints_deg, capture_base_position{0, 0, 0}, capture_base_rpy_deg{0, 0, 0};
  std::vector<std::string> merge;
};

/// The figure's series of a summary (every configuration's F_max).
figures::RobustSeries robust_series(const RobustSummary& s) {
  figures::RobustSeries r;
  r.title = str("F_max over ", s.samples, " samples (", s.force_model, " model, seed ", s.seed, ")");
  r.stiffness_conditional = s.stiffness_conditional;
  for (const RobustConfigurationSummary& c : s.configurations) r.configurations.push_back({c.name, c.f_max, c.summary.p95});
  return r;
}

std::string extremes_text(const nlohmann::json& ex) {
  std::ostringstream os;
  os << std::showpos << std::fixed << std::setprecision(2);
  for (std::size_t k = 0; k < ex.size(); ++k)
    os << (k ? ", " : "") << ex[k]["quantity"].get<std::string>() << " " << ex[k]["score"].get<double>();
  return os.str();
}

/// The terminal table of a summary (a run or a merge: the same struct), from its JSON.
void print_summary(const nlohmann::json& j, std::ostream& out) {
  out << std::left << std::setw(14) << "configuration" << std::right << std::setw(12) << "nominal M_ie"
      << std::setw(11) << "nominal F" << std::setw(10) << "mean" << std::setw(10) << "std" << std::setw(10)
      << "p50" << std::setw(10) << "p95" << std::setw(10) << "p99" << std::setw(10) << "max"
      << "\n";
  out << std::left << std::setw(14) << "" << std::right << std::setw(12) << "(kg)" << std::setw(11) << "(kN)"
      << std::setw(60) << "F_max over the samples (kN)"
      << "\n";
  for (const auto& c : j["configurations"]) {
    const auto& s = c["summary"];
    out << std::left << std::setw(14) << c["name"].get<std::string>() << std::right << std::fixed
        << std::setprecision(3) << std::setw(12) << c["nominal"]["M_ie"].get<double>() << std::setw(11)
        << c["nominal"]["f_max"].get<double>() / 1e3;
    for (const char* k : {"mean", "std", "p50", "p95", "p99", "max"})
      out << std::setw(10) << s[k].get<double>() / 1e3;
    out << "\n";
  }
  const bool conditional = j.value("estimator", "order-statistics") == "stiffness-conditional";
  if (conditional) {
    // the percentiles above are the stiffness-conditional ones; the order statistics beside them
    out << "p50, p95, p99: the law's percentiles conditional on the stiffness (the single-body F_max scales "
           "as"
        << " K^(1/(alpha+1)); README); mean, std, max: the samples'."
        << "\norder statistics of the same samples, p95 (kN):";
    const char* sep = " ";
    for (const auto& c : j["configurations"]) {
      out << sep << c["name"].get<std::string>() << " " << std::fixed << std::setprecision(3)
          << c["summary"]["order_statistics"]["p95"].get<double>() / 1e3;
      sep = ", ";
    }
    out << "\n";
  }
  // how well the samples pin the 95th percentile of the law down
  out << "95 % confidence interval of the 95th percentile ("
      << (conditional ? "conditional on the stiffness, delta method" : "order statistics, distribution-free")
      << "), kN:";
  const char* sep = "\n  ";
  for (const auto& c : j["configurations"]) {
    const auto& ci = c["summary"]["p95_ci95"];
    auto bound = [&ci](const char* key, const char* none) {
      std::ostringstream os;
      if (!ci.contains(key))
        os << none;
      else
        os << std::fixed << std::setprecision(3) << ci[key].get<double>() / 1e3;
      return os.str();
    };
    out << sep << c["name"].get<std::string>() << " [" << bound("lo", "-") << ", "
        << bound("hi", "none: too few samples") << "]";
    sep = ", ";
  }
  out << "\n";
  if (j.contains("robust_vs_global")) {
    const auto& r = j["robust_vs_global"];
    auto pct = [](double ratio) {
      std::ostringstream os;
      os << std::showpos << std::fixed << std::setprecision(2) << 100.0 * (ratio - 1.0) << " %";
      return os.str();
    };
    out << "robust against global on the same samples: p95 " << pct(r["p95_ratio"].get<double>());
    if (r.contains("p95_ratio_ci95"))
      out << ", 95 % interval [" << pct(r["p95_ratio_ci95"]["lo"].get<double>()) << ", "
          << pct(r["p95_ratio_ci95"]["hi"].get<double>()) << "] (paired)";
    out << "\n";
  }
  for (const auto& c : j["configurations"]) {
    out << "\nlargest F_max, " << c["name"].get<std::string>()
        << " (score: z for normal laws, ln(x/x0)/sigma, "
        << "[-1, 1] in a uniform range, angle/half-angle in the cone):\n";
    for (const auto& t : c["tail"])
      out << "  sample " << std::setw(7) << t["index"].get<std::uint64_t>() << "  F_max " << std::fixed
          << std::setprecision(3) << t["f_max"].get<double>() / 1e3 << " kN  M_ie " << t["M_ie"].get<double>()
          << " kg  delta_dot " << std::setprecision(4) << t["approach_velocity"].get<double>()
          << " m/s  extreme: " << extremes_text(t["extreme"]) << "\n";
  }
}


/// The summaries of --merge, merged (the library's merge_shards), with the figure and the table.
int run_merge(const RobustOptions& o) {
  const plot::Format plot_format = plot::check_request(o.plot, o.plot_format);
  if (!o.csv.empty()) throw InputError("--csv: --merge has no samples to write (the shards' --csv have them)");
  Outputs outputs;  // the table goes to standard error when the JSON goes to standard output
  outputs.add("--json", o.json);
  std::vector<RobustSummary> parts;
  for (const auto& path : o.merge) {
    std::ifstream in(path);
    if (!in) throw InputError(str("--merge: cannot read '", path, "'"));
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      throw InputError(str("--merge: '", path, "' is not JSON: ", e.what()));
    }
    parts.push_back(RobustSummary::from_json(j, str("--merge: '", path, "'")));
  }
  const std::size_t count = parts.size();
  const RobustSummary m = merge_shards(std::move(parts));
  const nlohmann::json j = m.to_json();
  outputs.set("--json", j.dump(1) + "\n");
  std::vector<std::string> drawn;
  if (!o.plot.empty())
    drawn = outputs.stage(plot::draw({figures::robust(robust_series(m))}, o.plot, plot_format));
  outputs.write();
  std::ostream& out = outputs.table();
  out << "ffsr-optimize " << FFSR_VERSION << " robust: merged " << count << " shard summaries, " << m.end
      << " samples (seed " << m.seed << ", " << m.force_model << " F_max)\n\n";
  print_summary(j, out);
  for (const std::string& f : drawn) out << "wrote " << f << "\n";
  return 0;
}

/// The scenario of the run: the file's keys, the flags as overrides. A top-level `seed` key of the file
/// is not the global search's seed here (--seed is the Monte Carlo seed): the global runs use seed 1.
Scenario robust_scenario(ScenarioKeys keys, const RobustOptions& o) {
  o.flags.apply(keys);
  refuse_shapes_without_clearance(keys, "robust");
  robust_global_seed(keys);
  return command_scenario(std::move(keys));
}

/// The [uncertainty] table with the flags' samples and seed, and the job's options (force model,
/// shard, threads).
std::pair<UncertaintySpec, RobustJobOptions> parse_robust(const RobustOptions& o, const ScenarioKeys& keys) {
  std::optional<std::uint64_t> samples_flag, seed_flag;
  if (!o.samples.empty()) samples_flag = parse_count(o.samples, "--samples");
  if (!o.seed.empty()) seed_flag = parse_count(o.seed, "--seed");
  if (samples_flag && *samples_flag < 1) throw InputError("--samples: must be at least 1, got 0");
  const UncertaintySpec spec = uncertainty_spec(keys, samples_flag, seed_flag);
  RobustJobOptions job;
  job.force_model = robust_force_model(o.force_model);
  const Shard shard = parse_shard(o.shard);
  job.shard_k = shard.k;
  job.shard_n = shard.n;
  if (o.threads < 1 || o.threads > 1024)
    throw InputError(str("--threads: must be in [1, 1024], got ", o.threads));
  job.threads = o.threads;
  return {spec, job};
}

/// One row per sample and configuration.
std::string robust_csv(const RobustRun& run) {
  std::ostringstream c;
  c << std::setprecision(12)
    << "configuration,sample,target_mass,Ixx,Iyy,Izz,Ixy,Ixz,Iyz,offset_x,offset_y,offset_z,normal_x,"
       "normal_y,"
       "normal_z,spin_x_deg,spin_y_deg,spin_z_deg,velocity_x,velocity_y,velocity_z,approach_speed,"
       "stiffness,"
       "exponent,restitution,robot_offset_x,robot_offset_y,robot_offset_z,M_ie,delta_dot,F_max\n";
  for (const auto& cf : run.configurations)
    for (std::uint64_t i = 0; i < run.samples.size(); ++i) {
      const UncertainSample& s = run.samples[i];
      const Matrix3& I = s.target.inertia;
      const Vector3 w = s.target.angular_velocity * (180.0 / M_PI);
      c << cf.configuration.name << "," << run.first + i << "," << s.target.mass << "," << I(0, 0) << ","
        << I(1, 1) << "," << I(2, 2) << "," << I(0, 1) << "," << I(0, 2) << "," << I(1, 2);
      for (const Vector3* v : {&s.target.contact_offset, &s.target.normal, &w, &s.target.velocity})
        c << "," << (*v)(0) << "," << (*v)(1) << "," << (*v)(2);
      c << "," << s.approach_speed << "," << s.contact.K << "," << s.contact.alpha << "," << s.contact.c_r
        << "," << s.robot_offset(0) << "," << s.robot_offset(1) << "," << s.robot_offset(2) << ","
        << cf.forces[i].M_ie << "," << cf.forces[i].approach_velocity << "," << cf.forces[i].f_max << "\n";
    }
  return c.str();
}

/// JSON, CSV and the figure, written all or nothing, then the table.
int report_robust(const Scenario& sc, const RobustRun& run, const RobustOptions& o, Outputs& outputs,
                  plot::Format plot_format) {
  const RobustSummary summary = robust_summary(sc, run, o.config, FFSR_VERSION);
  const nlohmann::json j = summary.to_json();
  if (!o.json.empty()) outputs.set("--json", j.dump(1) + "\n");
  if (!o.csv.empty()) outputs.set("--csv", robust_csv(run));
  std::vector<std::string> drawn;
  if (!o.plot.empty())
    drawn = outputs.stage(plot::draw({figures::robust(robust_series(summary))}, o.plot, plot_format));
  outputs.write();
  std::ostream& out = outputs.table();
  out << "ffsr-optimize " << FFSR_VERSION << " robust: " << sc.where << " (" << sc.model->n() << " joints, "
      << sc.problem.law << ", " << o.force_model << " F_max)\n"
      << run.spec.samples << " samples, seed " << run.spec.seed << "; this run: samples " << run.first << " to "
      << run.end << " (shard " << run.options.shard_k << "/" << run.options.shard_n << "), " << run.redraws
      << " redraws by the physical rules\n\n";
  print_summary(j, out);
  for (const std::string& f : drawn) out << "wrote " << f << "\n";
  return 0;
}

/// robust's own keys, also allowed in a scenario file (a flag overrides the file).
const std::set<std::string> kRobustKeys = {"force-model", "samples", "shard",       "threads", "json",
                                           "csv",         "plot",    "plot-format", "quiet"};

/// The flags, completed by the file's robust keys that no flag overrides.
RobustOptions with_file_keys(const RobustOptions& flags, const ScenarioKeys& keys, const CLI::App& app) {
  RobustOptions o = flags;
  for_each_file_key(keys, app,
                    [&](const std::string& name, const std::string& text, const std::string& flag) {
                      // checked here, where an error is located in the file
                      if (o.set_from_file(name, text, flag)) {
                        if (name == "plot-format") plot::parse_format(text, flag);
                        return;
                      }
                      if (name == "force-model") robust_force_model(o.force_model = text);
                      if (name == "samples") parse_count(o.samples = text, flag);
                      if (name == "shard") parse_shard(o.shard = text);
                      if (name == "threads")
                        o.threads = static_cast<int>(detail::integer_from_text(text, flag));
                    });
  return o;
}

int run_robust(const RobustOptions& flags, const CLI::App& app) {
  set_quiet(flags.quiet);
  if (!flags.merge.empty()) return run_merge(flags);
  if (flags.config.empty()) throw InputError("robust: --config SCENARIO.toml is required (or --merge FILES)");
  ScenarioKeys keys = read_scenario_file(flags.config, kRobustKeys);
  const RobustOptions o = with_file_keys(flags, keys, app);
  set_quiet(o.quiet);  // the flag, or the file's quiet key
  Outputs outputs = o.outputs();  // checked first (two outputs on standard output); the table goes to stderr then
  const plot::Format plot_format = plot::check_request(o.plot, o.plot_format);
  auto [spec, job] = parse_robust(o, keys);
  const Scenario sc = robust_scenario(std::move(keys), o);
  check_robust_job(sc, job);  // before the planning
  Progress p1{"plain"}, p2{"optimized"}, progress("robust", o.quiet, "evaluations");
  ScenarioRunOptions planning;
  if (!o.quiet) {
    planning.plain_progress = std::ref(p1);
    planning.optimized_progress = std::ref(p2);
  }
  std::vector<RobustConfiguration> configs = o.capture_joints_deg.empty()
                                                 ? planned_robust_configurations(sc, planning)
                                                 : std::vector<RobustConfiguration>{given_robust_configuration(
                                                       *sc.model, o.capture_joints_deg, o.capture_base_position,
                                                       o.capture_base_rpy_deg)};
  job.progress = [&progress](std::uint64_t done, std::uint64_t total) { progress(done, total); };
  const RobustRun run = run_robust(sc, spec, std::move(configs), job);
  return report_robust(sc, run, o, outputs, plot_format);
}

}  // namespace

void register_robust(CLI::App& app, Action& action) {
  auto o = std::make_shared<RobustOptions>();
  CLI::App* sub = app.add_subcommand(
      "robust",
      "Monte Carlo of F_max over the scenario's [uncertainty] table, for the planned capture configurations");
  sub->add_option("--config", o->config, "Scenario file (TOML) with an [uncertainty] table")
      ->check(CLI::ExistingFile);
  // before the scenario's keys: here --seed is the Monte Carlo seed, not the global search's
  // (ScenarioFlags leaves an existing --seed alone; robust_scenario sets the global search's to 1)
  sub->add_option("--seed", o->seed, "Seed, a non-negative integer (overrides uncertainty.seed)");
  // the samples' Lambda^-1 is the joint model's (contact-joints, armature); the multibody force model
  // runs with the library's default servo, so the multibody reference's servo keys are not taken
  o->flags.add_groups(*sub,
                      {KeyGroup::Robot, KeyGroup::Start, KeyGroup::Target, KeyGroup::TargetPlace,
                       KeyGroup::Contact, KeyGroup::Planner, KeyGroup::Global, KeyGroup::JointModels,
                       KeyGroup::Shapes},
                      {"joint-stiffness", "joint-damping"});
  sub->add_option("--force-model", o->force_model,
                  "F_max per sample: closed (Eq. 24), exact (Eq. 16) or multibody (CVODE)")
      ->capture_default_str();
  sub->add_option("--samples", o->samples, "Number of samples (overrides uncertainty.samples)");
  sub->add_option("--threads", o->threads, "Worker threads")->capture_default_str();
  sub->add_option("--shard", o->shard, "Evaluate only shard K of N (K = 0..N-1) of the samples")
      ->capture_default_str();
  sub->add_option("--capture-joints-deg", o->capture_joints_deg,
                  "Evaluate this capture configuration instead of planning (deg; --joints-deg is the "
                  "scenario's start)")
      ->delimiter(',')
      ->allow_extra_args(false);
  sub->add_option("--capture-base-position", o->capture_base_position,
                  "Base position of that configuration, m")
      ->delimiter(',')
      ->allow_extra_args(false);
  sub->add_option("--capture-base-rpy-deg", o->capture_base_rpy_deg,
                  "Base attitude of that configuration, deg")
      ->delimiter(',')
      ->allow_extra_args(false);
  sub->add_option("--merge", o->merge,
                  "Merge these shard summaries (JSON files of --json) exactly; no scenario needed");
  add_output_flags(*sub, *o,
                   {"Write the summary (with every sample's F_max, for merging) as JSON to FILE",
                    "Write one row per sample and configuration as CSV to FILE",
                    "Draw the CDF and the histogram of F_max per configuration (robust.png)"});
  sub->callback([o, sub, &action] { action = [o, sub] { return run_robust(*o, *sub); }; });
}

}  // namespace ffsr::cli
