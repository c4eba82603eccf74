// ffsr-optimize [--config SCENARIO.toml] [flags]: the main job. Plans the approach of the robot to
// the tumbling target twice -- plain (rho = 0) and optimized (rho of the scenario) -- and, unless
// global = false, globally; reports how much the capture configuration lowers M_ie and the maximum
// contact force (Tables 4 and 7). The scenario and the runs are the library's (ffsr/scenario/scenario.hpp,
// ffsr/jobs/scenario_run.hpp); this file turns flags into overrides and writes the outputs.
#include "support/baseline.hpp"
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "embedded.hpp"
#include "figures/figures.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/whole_capture.hpp"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

namespace ffsr::cli {

namespace {

using detail::str;

/// The main job's outputs: flags, and keys of a scenario file too (kCommandKeys; a flag overrides the
/// file, and --expect of the file is relative to it).
struct RunSettings : OutputKeys {
  std::string expect;  ///< a stored result to compare with (regression run)
  double rtol = 1e-6, atol = 1e-9;
};

const std::set<std::string> kCommandKeys = {"json",   "csv",  "plot", "plot-format",
                                            "expect", "rtol", "atol", "quiet"};

/// The main job's flags beside the scenario keys.
struct RunOptions {
  std::string config;
  ScenarioFlags flags;
  RunSettings settings;
};

/// The settings of the flags, completed by the file's command keys that no flag overrides.
RunSettings settings_of(const RunSettings& flags, const ScenarioKeys& keys, const CLI::App& app) {
  RunSettings s = flags;
  for_each_file_key(keys, app,
                    [&](const std::string& name, const std::string& text, const std::string& flag) {
                      if (s.set_from_file(name, text, flag)) {
                        if (name == "plot-format") plot::parse_format(text, flag);  // checked here: located
                        return;
                      }
                      if (name == "rtol") s.rtol = detail::number_from_text(text, flag);
                      if (name == "atol") s.atol = detail::number_from_text(text, flag);
                      if (name == "expect") {  // relative to the scenario file
                        const size_t slash = keys.file.find_last_of('/');
                        s.expect = text.empty() || text.front() == '/' || slash == std::string::npos
                                       ? text
                                       : keys.file.substr(0, slash + 1) + text;
                      }
                    });
  return s;
}

/// Top-level keys of the result that --expect does not compare: inputs, not results (the resolved
/// scenario holds paths that differ between machines; the version changes with every release; the
/// model as loaded).
const std::vector<std::string> kNotCompared = {"version", "scenario", "model_repairs", "model_load"};

/// What the outputs need before the work: the files (conflicts found first) and the baseline.
struct RunRequest {
  Outputs outputs;
  nlohmann::json expected;
  Tolerance tol;
  plot::Format plot_format{};
};

RunRequest prepare_outputs(const RunSettings& o) {
  RunRequest q;
  q.outputs = o.outputs();
  q.tol = {o.rtol, o.atol};
  if (!std::isfinite(o.rtol) || o.rtol < 0)
    throw InputError(str("--rtol: must be finite and >= 0, got ", o.rtol));
  if (!std::isfinite(o.atol) || o.atol < 0)
    throw InputError(str("--atol: must be finite and >= 0, got ", o.atol));
  if (!o.expect.empty()) q.expected = load_baseline(o.expect, "--expect");
  q.plot_format = plot::check_request(o.plot, o.plot_format);
  return q;
}

/// The three runs, with a progress line on a terminal unless --quiet.
ScenarioResult compute(Scenario& sc, const RunSettings& o) {
  sc.capture.record_series = !o.csv.empty() || !o.plot.empty();
  Progress p1{"plain"}, p2{"optimized"};
  ScenarioRunOptions run;
  run.keep_going = true;  // a plain or paper's-method row that fails is reported; the global row decides
  if (!o.quiet) {
    run.plain_progress = std::ref(p1);
    run.optimized_progress = std::ref(p2);
  }
  return run_whole_capture(sc, run);  // with a Detumble key: each run's post-capture phase
}

std::string deg_list(const Eigen::VectorXd& theta, int precision = 2) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(precision) << "[";
  for (Eigen::Index i = 0; i < theta.size(); ++i) os << (i ? ", " : "") << theta(i) * 180.0 / M_PI;
  os << "]";
  return os.str();
}

/// The runs that hold a result, in the table's order: "plain", "optimized" (unless they failed), "global".
std::vector<std::pair<const char*, const CaptureResult*>> reported_runs(const ScenarioResult& r) {
  std::vector<std::pair<const char*, const CaptureResult*>> runs;
  if (r.plain_ok()) runs.emplace_back("plain", &r.plain);
  if (r.optimized_ok()) runs.emplace_back("optimized", &r.optimized);
  if (r.global) runs.emplace_back("global", &r.global->result.run);
  return runs;
}

/// The scenario's collision shapes for the pictures; none without geometry.
std::optional<figures::SceneShapes> scene_shapes(const Scenario& sc) {
#ifdef FFSR_HAVE_GEOMETRY
  if (sc.geometry)
    return figures::SceneShapes{sc.geometry->checker->geometry().shapes,
                                sc.geometry->checker->target_shape()};
#endif
  (void)sc;
  return std::nullopt;
}

/// JSON, CSV and figures, built first and written all or nothing.
void write_outputs(const Scenario& sc, const ScenarioResult& r, const RunSettings& o, RunRequest& q,
                   const nlohmann::json& j) {
  if (!o.plot.empty()) {  // the pictures of the same result structs; the runs are one vector entry each
    std::vector<figures::CaptureRun> runs;
    if (r.plain_ok()) runs.push_back({"plain", &r.plain, sc.baseline_task});
    if (r.optimized_ok()) runs.push_back({"optimized", &r.optimized, sc.task});
    if (r.global) runs.push_back({"global", &r.global->result.run, sc.task, reconfiguration_samples(r)});
    const std::optional<figures::SceneShapes> shapes = scene_shapes(sc);
    for (figures::CaptureRun& run : runs)  // the plain run's clearance is called "baseline"
      for (const auto& [name, c] : r.clearances)
        if (name == (run.label == "plain" ? "baseline" : run.label)) run.clearance = &c;
    q.outputs.stage(plot::draw(figures::capture(*sc.model, sc.problem.frame, sc.problem.target,
                                                sc.capture.duration, runs, shapes ? &*shapes : nullptr),
                               o.plot, q.plot_format));
  }
  q.outputs.set("--json", j.dump(2) + "\n");
  q.outputs.set("--csv", o.csv.empty() ? std::string() : scenario_series_csv(sc, r));
  q.outputs.write();
}

namespace {
/// "0.0505 m": a distance with four decimals.
std::string metres4(double x) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(4) << x << " m";
  return s.str();
}
}  // namespace

/// The global row's notes; `opt_run`: the paper's-method run (null when it failed).
void print_global_notes(std::ostream& out, const Scenario& sc, const GlobalRun& g,
                        const CaptureResult* opt_run) {
  const GlobalCaptureResult& r = g.result;
  const GlobalSearchCounters& n = r.counters;
  const ScenarioKeys& o = sc.keys;
  const bool mb = o.objective == "multibody-force";
  const double unit = mb || o.objective == "exact-force" || o.objective == "robust-force" ? 1e3 : 1.0;
  const char* u = unit == 1.0 ? " kg" : " kN";
  out << std::fixed << std::setprecision(3) << "global (" << o.objective << ", seed " << o.seed
      << "): reached " << r.objective / unit << u << ", manifold optimum at the reached base pose "
      << (r.search_distance_bound > 0 ? "with distances >= " + metres4(r.search_distance_bound) + " " : "")
      << r.manifold_optimum / unit << u << " (gap " << r.optimality_gap_percent << " %), "
      << n.shooting_iterations << " reaching run(s), " << n.goals_tried << " goal(s) tried"
      << (n.goals_out_of_limits > 0 ? " (" + std::to_string(n.goals_out_of_limits) + " behind a joint limit)"
                                    : "")
      << "; search: " << r.search.method << ", " << r.search.starts << " starts, " << n.evaluations
      << " evaluations" << (mb ? ", " + std::to_string(n.objective_evaluations) + " CVODE runs" : "") << ", "
      << n.search_seconds << " s\n";
  for (const RunPhase& p : r.reconfigured ? r.phases : std::vector<RunPhase>{})
    out << "global " << p.name << " phase: t = " << std::setprecision(2) << p.t_begin << " to " << p.t_end
        << " s, base attitude change " << std::setprecision(3) << p.base_attitude_change * 180.0 / M_PI
        << " deg, base position change " << p.base_position_change << " m, largest joint rate "
        << p.max_joint_rate * 180.0 / M_PI << " deg/s\n";
  if (!r.reached_manifold_optimum)
    out << "note: the better optima at the reached base pose lie on other components of the self-motion "
           "manifold; "
           "the servo reached none of them\n";
  if (mb) {
    out << "CVODE multibody F_max: ";
    if (opt_run) out << "optimization " << g.paper_objective / 1e3 << " kN, ";
    out << "global " << r.objective / 1e3 << " kN\n";
  }
  out << "largest joint rate: ";
  if (opt_run) out << "optimization " << opt_run->max_joint_rate * 180.0 / M_PI << " deg/s (not limited), ";
  out << "global " << r.run.max_joint_rate * 180.0 / M_PI << " deg/s (";
  if (o.max_joint_rate_deg > 0)
    out << "limit " << o.max_joint_rate_deg << " deg/s)\n";
  else
    out << "not limited)\n";
}

/// robust-force: the tail measure of every row over the search's sample set.
void print_robust_note(std::ostream& out, const ScenarioResult& r) {
  if (!r.robust) return;
  out << std::fixed << std::setprecision(3) << "robust-force over " << r.robust->samples().size()
      << " samples (seed " << robust_objective_seed(r.robust_spec) << "): CVaR_95 / p95 of the exact F_max";
  for (const RobustRow& row : r.robust_rows) {
    const bool first = &row == &r.robust_rows.front();
    out << (first ? ": " : ", ") << (first ? std::string("plain") : row.name) << " " << row.cvar95 / 1e3
        << " / " << row.p95 / 1e3 << " kN";
  }
  out << "\n";
}

/// The post-capture columns (ScenarioResult::post_capture): the widths and the header.
struct PostCaptureColumns {
  const ScenarioResult& r;
  int joint = 7;  ///< the joint column: its longest name + 2
  explicit PostCaptureColumns(const ScenarioResult& result) : r(result) {
    for (const DetumbleJobResult& d : r.post_capture)
      joint = std::max(joint, int(d.peak_joint_name.size()) + 2);
  }
  void header(std::ostream& out) const {
    if (r.post_capture.empty()) return;
    out << std::setw(10) << "rest (s)" << std::setw(14) << "torque (N m)" << std::setw(joint) << "joint"
        << std::setw(11) << "force (N)" << std::setw(14) << "moment (N m)" << std::setw(16)
        << "attitude (deg)" << std::setw(16) << "wheels (N m s)";
  }
  /// The cells of the run `name` (baseline, optimized, global): time to rest, peak joint torque and its
  /// joint, peak gripper force and moment, base attitude excursion, peak wheel momentum (- without wheels).
  void cells(std::ostream& out, const std::string& name) const {
    for (const DetumbleJobResult& d : r.post_capture) {
      if (d.run != name) continue;
      const DetumbleRunResult& x = d.result;
      std::ostringstream wheels;
      wheels << std::fixed << std::setprecision(3) << x.peak_wheel_momentum;
      out << std::fixed << std::setprecision(2) << std::setw(10) << x.time_to_rest << std::setw(14)
          << x.peak_joint_torque << std::setw(joint) << d.peak_joint_name << std::setw(11)
          << x.peak_gripper_force << std::setw(14) << x.peak_gripper_moment << std::setprecision(3)
          << std::setw(16) << x.base_attitude_excursion * 180.0 / M_PI << std::setw(16)
          << (d.settings.limits.actuator == BaseActuator::ReactionWheels ? wheels.str() : "-");
    }
  }
};

/// The legend of the post-capture columns.
void print_post_capture_note(std::ostream& out, const Scenario& sc, const ScenarioResult& r) {
  if (r.post_capture.empty()) return;
  const DetumbleJobResult& d = r.post_capture.front();
  out << std::defaultfloat << "after the capture (base actuator " << actuator_name(d.settings.limits.actuator)
      << (d.settings.options.stop_stack_spin ? ", stopping the stack's spin" : "") << ", at rest below "
      << sc.keys.rest_rate_deg
      << " deg/s):\n  rest = time to rest, torque = peak joint torque (at joint), force and moment = peak "
         "gripper load,\n  attitude = base attitude excursion, wheels = peak momentum stored in the reaction "
         "wheels (- without)\n";
}

/// The rows of the table: configuration, M_ie, F_max (closed form and exact), tracking error, and
/// with the post-capture phase its figures.
void print_rows(std::ostream& out, const Scenario& sc, const ScenarioResult& r) {
  const int w = 8 * sc.model->n() + 4;
  if (sc.problem.joints.model != JointModel::Free)  // joint models of the contact
    out << "M_ie with " << joint_model_name(sc.problem.joints.model) << " joints during the contact\n";
  out << std::left << std::setw(24) << "" << std::setw(w) << "Capture configuration (deg)" << std::right
      << std::setw(11) << "M_ie (kg)" << std::setw(14) << "F_max (kN)" << std::setw(14) << "exact (kN)"
      << std::setw(15) << "tracking (m)";
  const PostCaptureColumns post(r);
  post.header(out);
  out << "\n";
  auto row = [&](const char* label, ScenarioRow which, const CaptureResult& x,
                 const std::string& failure = {}) {
    if (!failure.empty()) {  // the message follows the table
      out << std::left << std::setw(24) << label << "failed (below)";
    } else {
      out << std::left << std::setw(24) << label << std::setw(w) << deg_list(x.theta) << std::right
          << std::fixed << std::setprecision(3) << std::setw(11) << x.M_ie << std::setw(14)
          << x.f_max_closed_form / 1e3 << std::setw(14) << x.f_max_exact / 1e3 << std::setw(15)
          << std::scientific << std::setprecision(2) << x.tracking_error << std::fixed;
      post.cells(out, which == ScenarioRow::Plain       ? "baseline"
                      : which == ScenarioRow::Optimized ? "optimized"
                                                        : "global");
    }
    const char* sep = "  not applied: ";  // the keys of the scenario this row's run does not take
    for (const std::string& key : keys_not_applied(sc.keys, which)) {
      out << sep << key;
      sep = ", ";
    }
    out << "\n";
  };
  auto reduction = [&](const char* label, const CaptureResult& x) {
    out << std::left << std::setw(24 + w) << label << std::right << std::fixed << std::setprecision(2)
        << std::setw(10) << reduction_percent(r.plain.M_ie, x.M_ie) << "%" << std::setw(13)
        << reduction_percent(r.plain.f_max_closed_form, x.f_max_closed_form) << "%" << std::setw(13)
        << reduction_percent(r.plain.f_max_exact, x.f_max_exact) << "%\n";
  };
  row("Without optimization", ScenarioRow::Plain, r.plain, r.plain_failure);
  row("With optimization", ScenarioRow::Optimized, r.optimized, r.optimized_failure);
  if (r.global) row("Global", ScenarioRow::Global, r.global->result.run);
  if (r.plain_ok() && r.optimized_ok()) reduction("Reduction (optimization)", r.optimized);
  if (r.global && r.plain_ok()) reduction("Reduction (global)", r.global->result.run);
  for (const std::string* f : {&r.plain_failure, &r.optimized_failure})
    if (!f->empty()) out << "failed: " << *f << "\n";
  if (r.global) {
    print_global_notes(out, sc, *r.global, r.optimized_ok() ? &r.optimized : nullptr);
    print_robust_note(out, r);
  }
}

/// The impact disturbance of the base of each run (single-body impulse, algorithm/base_disturbance.hpp).
void print_base_jump(std::ostream& out, const Scenario& sc, const ScenarioResult& r) {
  Data data(*sc.model);
  auto rate = [&](const CaptureResult& run) {
    return detail::run_base_disturbance(sc, data, run).angular_rate() * 180.0 / M_PI;
  };
  const auto flags = out.flags();
  const auto precision = out.precision();
  out << std::scientific << std::setprecision(3) << "base angular rate jump at the impact:";
  const char* sep = " ";
  for (const auto& [name, run] : reported_runs(r)) {
    out << sep << name << " " << rate(*run) << " deg/s";
    sep = ", ";
  }
  if (r.global && sc.keys.max_base_rate_deg > 0)
    out << std::defaultfloat << " (searched within max-base-rate-deg " << sc.keys.max_base_rate_deg << ")";
  out << "\n";
  if (r.global && r.global->post_capture) {  // the post-capture constraints
    const PostCaptureFigures& f = *r.global->post_capture;
    out << std::defaultfloat << std::setprecision(4)
        << "global run after the capture (detumble run): rest in " << f.time_to_rest
        << " s, peak joint torque " << f.peak_joint_torque << " N m (" << sc.model->joint(f.peak_joint).name
        << "), peak gripper force " << f.peak_gripper_force << " N, moment " << f.peak_gripper_moment
        << " N m; " << r.global->post_capture_admitted << " of " << r.global->post_capture_candidates
        << " candidate runs met " << post_capture_constraints(sc.keys).flags() << "\n";
  }
  out.flags(flags);
  out.precision(precision);
}

/// With shapes: each run's smallest distance along its path and the pair (docs/geometry.md).
void print_clearance(std::ostream& out, const Scenario& sc, const ScenarioResult& r) {
  if (r.clearances.empty()) return;
  out << std::fixed << std::setprecision(4) << "smallest distance along the path (clearance "
      << sc.keys.clearance << " m, last " << sc.keys.contact_exemption
      << " m of the arm before the contact point exempt at the target):";
  for (const auto& [name, c] : r.clearances)
    out << (name == "baseline" ? " plain " : ", " + name + " ") << c.overall.distance << " m ("
        << c.overall.pair << ", t = " << std::setprecision(1) << c.overall.time << " s)"
        << std::setprecision(4);
  out << "\n";
  for (const auto& [name, c] : r.clearances)  // the global run is rejected instead (below)
    if (name != "global" && sc.keys.clearance > 0 && c.overall.distance < sc.keys.clearance - 1e-6)
      out << "clearance: the " << (name == "baseline" ? "plain" : name)
          << " run comes closer than the clearance (the clearance barrier could not keep it with the freedom "
             "its task leaves): "
          << c.overall.pair << " " << c.overall.distance << " m at t = " << std::setprecision(1)
          << c.overall.time << " s\n"
          << std::setprecision(4);
  if (r.global && r.global->result.counters.goals_rejected > 0)
    out << "clearance: " << r.global->result.counters.goals_rejected
        << " reached goal(s) rejected along the path; last: " << r.global->result.counters.rejection << "\n";
}

void print_table(std::ostream& out, const Scenario& sc, const ScenarioResult& r) {
  out << "ffsr-optimize " << FFSR_VERSION << ": " << sc.where << " (" << sc.model->n() << " joints, "
      << sc.keys.model << ", T = " << sc.capture.duration << " s, step " << sc.capture.step
      << " s, rho = " << sc.capture.gain << ")\n\n";
  print_rows(out, sc, r);
  out << "\n";
  const CaptureResult& first = r.first_run();
  out << std::setprecision(4) << "capture point ["
      << first.capture_point.transpose().format(Eigen::IOFormat(4, 0, ", "))
      << "] m, approach velocity delta_dot^- = " << first.approach_velocity << " m/s\n";
  const char* sep = "base drift: ";  // of the plain and optimized runs that hold a result
  for (const auto& [name, run] : reported_runs(r)) {
    if (std::string(name) == "global") continue;
    out << sep << name << " " << run->base_position_drift * 1e3 << " mm / "
        << run->base_attitude_drift * 180.0 / M_PI << " deg";
    sep = ", ";
  }
  if (r.plain_ok() || r.optimized_ok()) out << "\n";
  print_base_jump(out, sc, r);
  out << "tasks: plain " << (sc.baseline_task.kind == CaptureTask::Kind::Pose ? "pose" : "position")
      << ", optimized " << (sc.task.kind == CaptureTask::Kind::Pose ? "pose" : "position")
      << "; F_max: Eq. 24 closed form; exact: peak of the single-body model (Eq. 16)\n";
  print_post_capture_note(out, sc, r);
  // a failed run's CaptureResult is empty: no damped evaluations, and its smallest singular value (0)
  // is not one
  const long damped = r.plain.damped_steps + r.optimized.damped_steps;
  if (damped > 0)
    out << "note: near a singularity the pseudo-inverse was damped in " << damped
        << " evaluations (smallest singular value "
        << std::min(r.plain_ok() ? r.plain.min_singular_value : INFINITY,
                    r.optimized_ok() ? r.optimized.min_singular_value : INFINITY)
        << ")\n";
  print_clearance(out, sc, r);
}

/// Regression run: every number of the result against the stored one; exit 4 when one moved.
int check_expected(const RunSettings& o, const RunRequest& q, const nlohmann::json& j) {
  if (o.expect.empty()) return 0;
  const auto moved = compare_results(q.expected, j, q.tol, kNotCompared);
  if (moved.empty()) return 0;
  for (const auto& line : moved) std::cerr << line << "\n";
  std::cerr << "ffsr-optimize: error: --expect " << o.expect << ": " << moved.size()
            << (moved.size() == 1 ? " value differs" : " values differ") << " from the baseline (rtol "
            << q.tol.rtol << ", atol " << q.tol.atol << "; regenerate it with --json FILE)\n";
  return kExitRegression;
}

int report(const Scenario& sc, const ScenarioResult& r, const RunSettings& o, RunRequest& q) {
  const nlohmann::json j = scenario_json(sc, r, FFSR_VERSION);
  write_outputs(sc, r, o, q, j);
  print_table(q.outputs.table(), sc, r);  // standard error when --json or --csv is '-'
  return check_expected(o, q, j);
}

int run_main(const RunOptions& o, const CLI::App& app) {
  ScenarioKeys keys = command_scenario_keys(o.config, o.flags, kCommandKeys);
  const RunSettings settings = settings_of(o.settings, keys, app);
  set_quiet(settings.quiet);  // the flag, or the file's quiet key
  Scenario sc = command_scenario(std::move(keys));
  RunRequest request =
      prepare_outputs(settings);  // a conflict or an unreadable baseline is found before the work
  const ScenarioResult result = compute(sc, settings);
  return report(sc, result, settings, request);
}

}  // namespace

void register_run(CLI::App& app, Action& action) {
  auto o = std::make_shared<RunOptions>();
  app.add_option("--config", o->config,
                 "Scenario file (TOML); every key is also a flag. Default: the built-in paper 3-DOF scenario")
      ->check(CLI::ExistingFile);
  // every key: the Detumble keys add each run's post-capture phase (run_whole_capture)
  o->flags.add_to(app);
  add_output_flags(
      app, o->settings,
      {"Write the result (with the resolved scenario and the version) as JSON to FILE",
       "Write the time series of the runs as CSV to FILE", "Draw the capture process and time histories"});
  app.add_option("--expect", o->settings.expect,
                 "Regression run: compare every number of the result with this stored --json result; exit 4 "
                 "when one moved (relative to the scenario file)");
  app.add_option("--rtol", o->settings.rtol, "--expect: relative tolerance")->capture_default_str();
  app.add_option("--atol", o->settings.atol, "--expect: absolute floor for values near zero")
      ->capture_default_str();
  app.callback([o, &app, &action] {
    if (app.get_subcommands().empty()) action = [o, &app] { return run_main(*o, app); };
  });
}

}  // namespace ffsr::cli
