// ffsr-optimize [--config SCENARIO.toml] [flags]: the main job. Plans the approach of the robot to
// the tumbling target twice -- plain (rho = 0) and optimized (rho of the scenario) -- and reports
// how much the capture configuration lowers M_ie and the maximum contact force (Tables 4 and 7).
#include "baseline.hpp"
#include "common.hpp"
#include "embedded.hpp"
#include "figures.hpp"
#include "scenario.hpp"
#include "subcommands.hpp"

#include "ffsr/io/urdf.hpp"
#include "ffsr/optimize/capture.hpp"
#include "ffsr/optimize/global.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

namespace ffsr::cli {
namespace {

using detail::str;

/// Keys a scenario file must name (the others have defaults).
const char* const kRequired[] = {"urdf",
                                 "joints-deg",
                                 "target-mass",
                                 "target-inertia",
                                 "target-position",
                                 "target-angular-velocity-deg",
                                 "contact-offset",
                                 "normal",
                                 "model",
                                 "stiffness",
                                 "exponent",
                                 "restitution",
                                 "approach-speed",
                                 "task",
                                 "duration",
                                 "step",
                                 "gain",
                                 "tolerance"};

Vector3 vec3(const std::vector<double>& v, const char* key) {
  if (v.size() != 3) throw InputError(str("--", key, ": expected 3 numbers, got ", v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(str("--", key, ": values must be finite, got ", x));
  return {v[0], v[1], v[2]};
}

double finite(double x, const char* key) {
  if (!std::isfinite(x)) throw InputError(str("--", key, ": must be finite, got ", x));
  return x;
}

CaptureTask parse_task(const std::string& kind, const std::string& axes, const std::vector<double>& final_rpy,
                       const char* key) {
  CaptureTask t;
  if (kind == "position") {
    t.kind = CaptureTask::Kind::Position;
    if (axes.empty() || axes.find_first_not_of("xyz") != std::string::npos)
      throw InputError(str("--task-axes: expected letters from 'xyz' (for example 'xy'), got '", axes, "'"));
    t.axes = {axes.find('x') != std::string::npos, axes.find('y') != std::string::npos,
              axes.find('z') != std::string::npos};
  } else if (kind == "pose") {
    t.kind = CaptureTask::Kind::Pose;
    if (!final_rpy.empty())
      t.final_orientation = rotation_from_rpy(vec3(final_rpy, "final-rpy-deg") * (M_PI / 180.0));
  } else {
    throw InputError(str("--", key, ": unknown task '", kind, "'; expected 'position' or 'pose'"));
  }
  return t;
}

std::string deg_list(const Eigen::VectorXd& theta, int precision = 2) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(precision) << "[";
  for (Eigen::Index i = 0; i < theta.size(); ++i) os << (i ? ", " : "") << theta(i) * 180.0 / M_PI;
  os << "]";
  return os.str();
}

/// --seed as a non-negative integer (a string key, so that a bad value gets a one-line error naming it).
std::uint64_t parse_seed(const std::string& sd) {
  if (sd.empty() || sd.size() > 19 || sd.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(str("--seed: expected a non-negative integer (at most 19 digits), got '", sd, "'"));
  return std::stoull(sd);
}

nlohmann::json result_json(const CaptureResult& r, const CaptureTask& task, double gain) {
  const Eigen::Vector4d q = r.base.orientation.coeffs();
  return {{"task", task.kind == CaptureTask::Kind::Pose ? "pose" : "position"},
          {"max_joint_rate_deg", r.max_joint_rate * 180.0 / M_PI},
          {"gain", gain},
          {"capture_configuration_deg", to_json(Eigen::VectorXd(r.theta * (180.0 / M_PI)))},
          {"integrated_effective_mass", r.M_ie},
          {"approach_velocity", r.approach_velocity},
          {"f_max_closed_form", r.f_max_closed_form},
          {"f_max_exact", r.f_max_exact},
          {"tracking_error", r.tracking_error},
          {"capture_distance", r.capture_distance},
          {"orientation_error_deg", r.orientation_error * 180.0 / M_PI},
          {"end_effector_position", to_json(Eigen::VectorXd(r.end_effector))},
          {"capture_point", to_json(Eigen::VectorXd(r.capture_point))},
          {"base_position", to_json(Eigen::VectorXd(r.base.position))},
          {"base_quaternion_wxyz", {q(3), q(0), q(1), q(2)}},
          {"base_position_drift", r.base_position_drift},
          {"base_attitude_drift_deg", r.base_attitude_drift * 180.0 / M_PI},
          {"max_total_momentum", r.max_momentum},
          {"max_center_of_mass_drift", r.max_com_drift},
          {"max_tracking_error", r.max_tracking_error},
          {"min_singular_value", r.min_singular_value},
          {"damped_evaluations", r.damped_steps},
          {"steps", r.steps}};
}

/// Which keys came from the command line: they are not resolved against the scenario's folder.
struct FromCommandLine {
  bool urdf = false, expect = false;
};

/// Top-level keys of the result that --expect does not compare: inputs, not results (the resolved
/// scenario holds paths that differ between machines; the version changes with every release).
// model_repairs and model_load describe the model as loaded (inputs too), not results
const std::vector<std::string> kNotCompared = {"version", "scenario", "model_repairs", "model_load"};

}  // namespace

Scenario prepare_scenario(RunOptions o, const CLI::App& app, bool urdf_on_command_line) {
  // --- the scenario: a file, or the built-in default (the paper's 3-DOF robot) -----------------
  const bool builtin = o.config.empty();
  const std::string where = builtin ? std::string("built-in scenario") : "scenario " + o.config;
  if (!builtin) {
    for (const char* key : kRequired)
      if (app.get_option(std::string("--") + key)->count() == 0)
        throw InputError(str(where, ": missing key '", key, "'"));
  }
  // a path in a scenario file is relative to the file
  auto next_to_config = [&](const std::string& path, bool on_command_line) {
    if (builtin || on_command_line || path.empty() || path.front() == '/') return path;
    const size_t slash = o.config.find_last_of('/');
    return slash == std::string::npos ? path : o.config.substr(0, slash + 1) + path;
  };
  UrdfReport report;
  auto model_ptr = std::make_unique<Model>([&] {
    if (builtin && !urdf_on_command_line && o.urdf == "paper_3dof.urdf")
      return model_from_urdf_string(kPaper3dofUrdf, "built-in paper_3dof.urdf", o.load.build(o.end_effector),
                                    &report);
    o.urdf = next_to_config(o.urdf, urdf_on_command_line);
    return model_from_urdf_file(o.urdf, o.load.build(o.end_effector), &report);
  }());
  warn_repairs(report);
  const Model& model = *model_ptr;

  CaptureProblem pb;
  pb.model = &model;
  pb.frame = model.end_effector();
  if (static_cast<int>(o.joints_deg.size()) != model.n())
    throw InputError(joint_count_error(o.joints_deg.size(), model, ""));
  pb.theta = Eigen::Map<const Eigen::VectorXd>(o.joints_deg.data(), model.n()) * (M_PI / 180.0);
  for (double x : o.joints_deg) finite(x, "joints-deg");
  pb.base.position = vec3(o.base_position, "base-position");
  pb.base.orientation = Quaternion(rotation_from_rpy(vec3(o.base_rpy_deg, "base-rpy-deg") * (M_PI / 180.0)));
  Target& t = pb.target;
  t.mass = finite(o.target_mass, "target-mass");
  if (o.target_inertia.size() != 3 && o.target_inertia.size() != 6)
    throw InputError(str("--target-inertia: expected 3 or 6 numbers, got ", o.target_inertia.size()));
  {
    std::ostringstream s;
    for (size_t i = 0; i < o.target_inertia.size(); ++i)
      s << (i ? "," : "") << std::setprecision(17) << o.target_inertia[i];
    t.inertia = parse_inertia(s.str(), "--target-inertia");
  }
  t.position = vec3(o.target_position, "target-position");
  t.attitude = Quaternion(rotation_from_rpy(vec3(o.target_rpy_deg, "target-rpy-deg") * (M_PI / 180.0)));
  t.angular_velocity = vec3(o.target_angular_velocity_deg, "target-angular-velocity-deg") * (M_PI / 180.0);
  t.velocity = vec3(o.target_velocity, "target-velocity");
  t.contact_offset = vec3(o.contact_offset, "contact-offset");
  const Vector3 nrm = vec3(o.normal, "normal");
  if (nrm.norm() < 1e-12) throw InputError("--normal: the contact normal must be a non-zero vector");
  t.normal = nrm.normalized();
  try {
    t.validate("target");
  } catch (const InputError& e) {
    throw InputError(str("--target-mass/--target-inertia: ", e.what()));
  }
  pb.contact = {finite(o.stiffness, "stiffness"), finite(o.exponent, "exponent"),
                finite(o.restitution, "restitution")};
  try {
    validate(pb.contact, "contact");
  } catch (const InputError& e) {
    throw InputError(str("--stiffness/--exponent/--restitution: ", e.what()));
  }
  try {
    make_contact_law(o.model, pb.contact, 1.0);  // an unknown --model lists the laws
  } catch (const InputError& e) {
    throw InputError(str("--model: ", e.what()));
  }
  pb.law = o.model;
  pb.approach_speed = finite(o.approach_speed, "approach-speed");
  if (pb.approach_speed <= 0)
    throw InputError(str("--approach-speed: must be positive, got ", pb.approach_speed));

  const CaptureTask task = parse_task(o.task, o.task_axes, o.final_rpy_deg, "task");
  const CaptureTask baseline_task =
      o.baseline_task.empty() ? task
                              : parse_task(o.baseline_task, o.task_axes, o.final_rpy_deg, "baseline-task");
  CaptureOptions opt;
  opt.duration = finite(o.duration, "duration");
  opt.step = finite(o.step, "step");
  opt.gain = finite(o.gain, "gain");
  opt.feedback = finite(o.feedback, "feedback");
  opt.tolerance = finite(o.tolerance, "tolerance");
  opt.orientation_tolerance = finite(o.orientation_tolerance_deg, "orientation-tolerance-deg") * M_PI / 180.0;
  if (o.duration <= 0) throw InputError(str("--duration: must be positive, got ", o.duration));
  if (o.step <= 0 || o.step > o.duration)
    throw InputError(str("--step: must be in (0, duration], got ", o.step));
  if (o.tolerance <= 0) throw InputError(str("--tolerance: must be positive, got ", o.tolerance));
  // multibody-force has no gradient: the paper's method descends M_ie, the global search ranks by the CVODE peak
  // multibody-force and robust-force have no gradient the paper's method could use: it descends M_ie
  if (o.objective == "mass" || o.objective == "multibody-force" || o.objective == "robust-force")
    opt.objective = CaptureObjective::IntegratedEffectiveMass;
  else if (o.objective == "exact-force")
    opt.objective = CaptureObjective::ExactMaxForce;
  else
    throw InputError(str("--objective: unknown objective '", o.objective,
                         "'; expected 'mass', 'exact-force', 'multibody-force' or 'robust-force'"));
  if (o.objective == "robust-force" && o.config.empty())
    throw InputError(
        "--objective: robust-force needs a scenario file (--config) with an [uncertainty] table");
  parse_seed(o.seed);
  if (o.global_starts < 1) throw InputError(str("--global-starts: must be >= 1, got ", o.global_starts));
  if (app.get_option("--max-joint-rate-deg")->count() > 0 &&
      !(finite(o.max_joint_rate_deg, "max-joint-rate-deg") > 0))
    throw InputError(str("--max-joint-rate-deg: must be positive, got ", o.max_joint_rate_deg));
  if (opt.gain != 0.0 && task.rows() >= model.n())
    throw InputError(str("--gain: the ", o.task, " task has ", task.rows(), " rows and the robot ", model.n(),
                         " joints: no null space to optimize in (set gain = 0 or constrain fewer axes)"));
  Scenario sc{std::move(o), where,         builtin, std::move(model_ptr), pb,
              task,         baseline_task, opt,     std::move(report)};
  sc.problem.model = sc.model.get();
  return sc;
}

std::pair<CaptureResult, CaptureResult> plan_plain_and_optimized(const Scenario& sc, bool quiet) {
  CaptureOptions opt = sc.capture;
  CaptureOptions plain = opt;
  plain.gain = 0.0;
  Progress p1{"plain"}, p2{"optimized"};
  if (!quiet) {
    plain.progress = std::ref(p1);
    opt.progress = std::ref(p2);
  }
  auto labelled = [](const char* label, auto&& f) {
    try {
      return f();
    } catch (const NumericalError& e) {
      throw NumericalError(str(label, " run: ", e.what()));
    }
  };
  CaptureResult base_run =
      labelled("plain", [&] { return plan_capture(sc.problem, sc.baseline_task, plain); });
  CaptureResult opt_run = labelled("optimized", [&] { return plan_capture(sc.problem, sc.task, opt); });
  return {std::move(base_run), std::move(opt_run)};
}

GlobalObjective global_objective(const std::string& name) {
  return name == "exact-force"       ? GlobalObjective::ExactForce
         : name == "multibody-force" ? GlobalObjective::MultibodyForce
         : name == "robust-force"    ? GlobalObjective::RobustForce
                                     : GlobalObjective::Mass;
}

GlobalRun run_global(const Scenario& sc, const CaptureResult& paper_run, GlobalObjective objective,
                     std::shared_ptr<RobustForceObjective> robust, bool tight_reaching) {
  const RunOptions& o = sc.options;
  CaptureOptions opt = sc.capture;
  opt.gain = 0.0;
  opt.max_joint_rate = o.max_joint_rate_deg * M_PI / 180.0;
  opt.progress = nullptr;
  opt.record_series = sc.capture.record_series;
  GlobalCaptureOptions g;
  g.search.seed = parse_seed(o.seed);
  g.search.starts = o.global_starts;
  g.search.objective = objective;
  g.search.robust = robust;
  // robust-force scenarios: the reaching runs land within 0.01 % of the manifold optimum at the reached
  // base pose (the library's default, 1 %, is coarser than the difference between the robust and the
  // nominal optimum), the nominal global run beside the robust one too, so the two compare fairly
  if (tight_reaching || objective == GlobalObjective::RobustForce) {
    g.gap_percent = 0.01;
    g.max_iterations = 16;
  }
  g.extra_starts = {paper_run.theta};
  GlobalRun r;
  try {
    r.result = plan_capture_global(sc.problem, sc.task, opt, g);
  } catch (const InputError& e) {
    if (std::string(e.what()).find("max joint rate") != std::string::npos)
      throw InputError(str("--max-joint-rate-deg: ", e.what()));
    throw InputError(str("global run: ", e.what()));
  } catch (const NumericalError& e) {
    throw NumericalError(str("global run: ", e.what()));
  }
  const CaptureSetup setup = prepare_capture(sc.problem, sc.task, opt);
  r.paper_objective =
      evaluate_capture(sc.problem, setup, paper_run.base, paper_run.theta, objective, {}, robust.get())
          .objective;
  return r;
}

namespace {

void add_global_json(nlohmann::json& j, const GlobalRun& g, const CaptureResult& base_run,
                     const CaptureTask& task, const RunOptions& o) {
  const GlobalCaptureResult& r = g.result;
  nlohmann::json x = result_json(r.run, task, 0.0);
  x["objective"] = o.objective;
  x["objective_value"] = r.objective;
  x["manifold_optimum"] = r.manifold_optimum;
  x["optimality_gap_percent"] = r.optimality_gap_percent;
  x["shooting_iterations"] = r.shooting_iterations;
  x["goals_tried"] = r.goals_tried;
  x["goals_out_of_limits"] = r.goals_out_of_limits;
  x["reached_manifold_optimum"] = r.reached_manifold_optimum;
  x["search"] = {{"method", r.search.method},
                 {"starts", r.search.starts},
                 {"evaluations", r.evaluations},
                 {"multibody_evaluations", r.objective_evaluations},
                 {"seconds", r.search_seconds}};
  if (o.objective == "multibody-force") {
    // the ranked local optima of M_ie at the reached base pose: how far the mass and force optima are apart
    nlohmann::json ranked = nlohmann::json::array();
    for (const ManifoldPoint& p : r.search.local_optima)
      if (p.objective > 0)
        ranked.push_back({{"integrated_effective_mass", p.M_ie}, {"f_max_multibody", p.objective}});
    x["search"]["ranked_local_optima"] = ranked;
    x["f_max_multibody"] = r.objective;
    j["optimized"]["f_max_multibody"] = g.paper_objective;
  }
  j["global"] = x;
  j["global_mass_reduction_percent"] = 100.0 * (base_run.M_ie - r.run.M_ie) / base_run.M_ie;
  j["global_force_reduction_percent"] =
      100.0 * (base_run.f_max_closed_form - r.run.f_max_closed_form) / base_run.f_max_closed_form;
  j["global_exact_force_reduction_percent"] =
      100.0 * (base_run.f_max_exact - r.run.f_max_exact) / base_run.f_max_exact;
}

void print_global_notes(std::ostream& out, const GlobalRun& g, const CaptureResult& opt_run,
                        const RunOptions& o) {
  const GlobalCaptureResult& r = g.result;
  const bool mb = o.objective == "multibody-force";
  const double unit = mb || o.objective == "exact-force" || o.objective == "robust-force" ? 1e3 : 1.0;
  const char* u = unit == 1.0 ? " kg" : " kN";
  out << std::fixed << std::setprecision(3) << "global (" << o.objective << ", seed " << o.seed
      << "): reached " << r.objective / unit << u << ", manifold optimum at the reached base pose "
      << r.manifold_optimum / unit << u << " (gap " << r.optimality_gap_percent << " %), "
      << r.shooting_iterations << " reaching run(s), " << r.goals_tried << " goal(s) tried"
      << (r.goals_out_of_limits > 0 ? " (" + std::to_string(r.goals_out_of_limits) + " behind a joint limit)"
                                    : "")
      << "; search: " << r.search.method << ", " << r.search.starts << " starts, " << r.evaluations
      << " evaluations" << (mb ? ", " + std::to_string(r.objective_evaluations) + " CVODE runs" : "") << ", "
      << r.search_seconds << " s\n";
  if (!r.reached_manifold_optimum)
    out << "note: the better optima at the reached base pose lie on other components of the self-motion "
           "manifold; "
           "the servo reached none of them\n";
  if (mb)
    out << "CVODE multibody F_max: optimization " << g.paper_objective / 1e3 << " kN, global "
        << r.objective / 1e3 << " kN\n";
  out << "largest joint rate: optimization " << opt_run.max_joint_rate * 180.0 / M_PI
      << " deg/s (not limited), global " << r.run.max_joint_rate * 180.0 / M_PI << " deg/s ("
      << (o.max_joint_rate_deg > 0 ? "limit " + std::to_string(o.max_joint_rate_deg) + " deg/s"
                                   : std::string("not limited"))
      << ")\n";
}

int run_scenario(RunOptions options, const CLI::App& app, FromCommandLine cli) {
  const bool expect_builtin = options.config.empty();
  const std::string config_path = options.config;
  // a path in a scenario file is relative to the file
  auto next_to_config = [&](const std::string& path, bool on_command_line) {
    if (expect_builtin || on_command_line || path.empty() || path.front() == '/') return path;
    const size_t slash = config_path.find_last_of('/');
    return slash == std::string::npos ? path : config_path.substr(0, slash + 1) + path;
  };
  Scenario sc = prepare_scenario(std::move(options), app, cli.urdf);
  RunOptions& o = sc.options;
  // outputs and baseline first: a conflict or an unreadable baseline is found before the work
  Outputs outputs;
  outputs.add("--json", o.json);
  outputs.add("--csv", o.csv);
  nlohmann::json expected;
  Tolerance tol{o.rtol, o.atol};
  if (!std::isfinite(o.rtol) || o.rtol < 0)
    throw InputError(str("--rtol: must be finite and >= 0, got ", o.rtol));
  if (!std::isfinite(o.atol) || o.atol < 0)
    throw InputError(str("--atol: must be finite and >= 0, got ", o.atol));
  if (!o.expect.empty()) {
    o.expect = next_to_config(o.expect, cli.expect);
    expected = load_baseline(o.expect, "--expect");
  }
  const Model& model = *sc.model;
  const CaptureProblem& pb = sc.problem;
  const CaptureTask& task = sc.task;
  const CaptureTask& baseline_task = sc.baseline_task;
  const CaptureOptions& opt = sc.capture;
  const bool builtin = sc.builtin;
  const std::string& where = sc.where;
  const bool want_series = !o.csv.empty();
  const plot::Format plot_format = plot::check_request(o.plot, o.plot_format);
  sc.capture.record_series = want_series || !o.plot.empty();

  // --- the two runs ------------------------------------------------------------------------------
  const auto [base_run, opt_run] = plan_plain_and_optimized(sc, o.quiet);
  const double mass_red = 100.0 * (base_run.M_ie - opt_run.M_ie) / base_run.M_ie;
  const double force_red =
      100.0 * (base_run.f_max_closed_form - opt_run.f_max_closed_form) / base_run.f_max_closed_form;
  const double exact_red = 100.0 * (base_run.f_max_exact - opt_run.f_max_exact) / base_run.f_max_exact;
  std::optional<GlobalRun> global;
  std::shared_ptr<RobustForceObjective> robust;  // robust-force: the search's sample set
  UncertaintySpec robust_spec;
  if (o.global) {
    const GlobalObjective gobj = global_objective(o.objective);
    if (gobj == GlobalObjective::RobustForce) {
      robust_spec = read_uncertainty_table(o.config, where);
      robust = scenario_robust_objective(sc, robust_spec);
    }
    global = run_global(sc, opt_run, gobj, robust);
  }

  // --- outputs: all built first, then written atomically ------------------------------------------
  nlohmann::json j;
  j["version"] = FFSR_VERSION;
  j["scenario"] = {{"source", builtin ? "built-in paper_3dof" : o.config},
                   {"urdf", o.urdf},
                   {"end_effector", model.frame(pb.frame).name},
                   {"joint_names", model.joint_names()},
                   {"joints-deg", o.joints_deg},
                   {"base-position", o.base_position},
                   {"base-rpy-deg", o.base_rpy_deg},
                   {"target-mass", o.target_mass},
                   {"target-inertia", o.target_inertia},
                   {"target-position", o.target_position},
                   {"target-rpy-deg", o.target_rpy_deg},
                   {"target-angular-velocity-deg", o.target_angular_velocity_deg},
                   {"target-velocity", o.target_velocity},
                   {"contact-offset", o.contact_offset},
                   {"normal", o.normal},
                   {"model", o.model},
                   {"stiffness", o.stiffness},
                   {"exponent", o.exponent},
                   {"restitution", o.restitution},
                   {"approach-speed", o.approach_speed},
                   {"task", o.task},
                   {"task-axes", o.task_axes},
                   {"baseline-task", o.baseline_task.empty() ? o.task : o.baseline_task},
                   {"duration", o.duration},
                   {"step", o.step},
                   {"gain", o.gain},
                   {"feedback", o.feedback},
                   {"tolerance", o.tolerance},
                   {"objective", o.objective}};
  j["scenario"].update(o.load.to_json());
  j["model_repairs"] = repairs_json(sc.report);
  j["model_load"] = report_json(sc.report);  // merged links, mimic and locked joints, repairs
  j["capture_point"] = to_json(Eigen::VectorXd(base_run.capture_point));
  j["baseline"] = result_json(base_run, baseline_task, 0.0);
  j["optimized"] = result_json(opt_run, task, opt.gain);
  j["mass_reduction_percent"] = mass_red;
  j["force_reduction_percent"] = force_red;
  j["exact_force_reduction_percent"] = exact_red;
  j["scenario"]["global"] = o.global;
  j["scenario"]["seed"] = o.seed;
  j["scenario"]["max-joint-rate-deg"] = o.max_joint_rate_deg;
  j["scenario"]["global-starts"] = o.global_starts;
  if (global) add_global_json(j, *global, base_run, task, o);
  // robust-force: the tail measure of every row over the search's sample set; the nominal values are
  // the rows themselves, so the price of robustness is visible
  std::string robust_note;
  if (robust) {
    Data data(model);
    nlohmann::json rj = {
        {"measure", "CVaR_95 (mean of the largest 5 %) and p95 (nearest rank) of the exact F_max, N"},
        {"samples", robust->samples().size()},
        {"seed", robust_objective_seed(robust_spec)}};
    std::ostringstream note;
    note << std::fixed << std::setprecision(3) << "robust-force over " << robust->samples().size()
         << " samples (seed " << robust_objective_seed(robust_spec) << "): CVaR_95 / p95 of the exact F_max";
    const std::pair<const char*, const CaptureResult*> rows[] = {
        {"baseline", &base_run}, {"optimized", &opt_run}, {"global", &global->result.run}};
    for (const auto& [name, r] : rows) {
      const auto v = robust->value(robot_inverse_inertia(model, data, r->base, r->theta, pb.frame));
      rj[name] = {{"cvar95", v.cvar95}, {"p95", v.p95}};
      note << (r == &base_run ? ": " : ", ") << (r == &base_run ? "plain" : name) << " " << v.cvar95 / 1e3
           << " / " << v.p95 / 1e3 << " kN";
    }
    j["robust"] = rj;
    robust_note = note.str() + "\n";
  }

  std::string csv;
  if (want_series) {
    std::ostringstream c;
    c << std::setprecision(12) << "run,t";
    for (const auto& name : model.joint_names()) c << "," << name << "_deg";
    c << ",base_x,base_y,base_z,base_qw,base_qx,base_qy,base_qz,ee_x,ee_y,ee_z,M_ie,F_max_estimate\n";
    std::vector<const CaptureResult*> runs{&base_run, &opt_run};
    if (global) runs.push_back(&global->result.run);
    for (const auto* run : runs) {
      for (const CaptureSample& s : run->series) {
        c << (run == &base_run ? "baseline" : run == &opt_run ? "optimized" : "global") << "," << s.t;
        for (Eigen::Index i = 0; i < s.theta.size(); ++i) c << "," << s.theta(i) * 180.0 / M_PI;
        const auto& q = s.base.orientation;
        c << "," << s.base.position.x() << "," << s.base.position.y() << "," << s.base.position.z() << ","
          << q.w() << "," << q.x() << "," << q.y() << "," << q.z() << "," << s.end_effector.x() << ","
          << s.end_effector.y() << "," << s.end_effector.z() << "," << s.M_ie << "," << s.f_max_estimate
          << "\n";
      }
    }
    csv = c.str();
  }
  if (!o.plot.empty()) {  // the pictures of the same result structs; the runs are one vector entry each
    std::vector<figures::CaptureRun> runs{{"plain", &base_run, baseline_task}, {"optimized", &opt_run, task}};
    if (global) runs.push_back({"global", &global->result.run, task});
    plot::render(figures::capture(model, pb.frame, pb.target, opt.duration, runs), o.plot, plot_format);
  }
  outputs.set("--json", j.dump(2) + "\n");
  outputs.set("--csv", csv);
  outputs.write();  // all or nothing: no partial output

  std::ostream& out = outputs.table();  // standard error when --json or --csv is '-'
  out << "ffsr-optimize " << FFSR_VERSION << ": " << where << " (" << model.n() << " joints, " << o.model
      << ", T = " << o.duration << " s, step " << o.step << " s, rho = " << opt.gain << ")\n\n";
  const int w = 8 * model.n() + 4;
  out << std::left << std::setw(24) << "" << std::setw(w) << "Capture configuration (deg)" << std::right
      << std::setw(11) << "M_ie (kg)" << std::setw(14) << "F_max (kN)" << std::setw(14) << "exact (kN)"
      << std::setw(15) << "tracking (m)"
      << "\n";
  auto row = [&](const char* label, const CaptureResult& r) {
    out << std::left << std::setw(24) << label << std::setw(w) << deg_list(r.theta) << std::right
        << std::fixed << std::setprecision(3) << std::setw(11) << r.M_ie << std::setw(14)
        << r.f_max_closed_form / 1e3 << std::setw(14) << r.f_max_exact / 1e3 << std::setw(15)
        << std::scientific << std::setprecision(2) << r.tracking_error << std::fixed << "\n";
  };
  row("Without optimization", base_run);
  row("With optimization", opt_run);
  if (global) row("Global", global->result.run);
  out << std::left << std::setw(24 + w) << "Reduction (optimization)" << std::right << std::fixed
      << std::setprecision(2) << std::setw(10) << mass_red << "%" << std::setw(13) << force_red << "%"
      << std::setw(13) << exact_red << "%\n";
  if (global) {
    const CaptureResult& g = global->result.run;
    out << std::left << std::setw(24 + w) << "Reduction (global)" << std::right << std::setw(10)
        << 100.0 * (base_run.M_ie - g.M_ie) / base_run.M_ie << "%" << std::setw(13)
        << 100.0 * (base_run.f_max_closed_form - g.f_max_closed_form) / base_run.f_max_closed_form << "%"
        << std::setw(13) << 100.0 * (base_run.f_max_exact - g.f_max_exact) / base_run.f_max_exact << "%\n";
    print_global_notes(out, *global, opt_run, o);
    out << robust_note;
  }
  out << "\n";
  out << std::setprecision(4) << "capture point ["
      << base_run.capture_point.transpose().format(Eigen::IOFormat(4, 0, ", "))
      << "] m, approach velocity delta_dot^- = " << base_run.approach_velocity << " m/s\n"
      << "base drift: plain " << base_run.base_position_drift * 1e3 << " mm / "
      << base_run.base_attitude_drift * 180.0 / M_PI << " deg, optimized "
      << opt_run.base_position_drift * 1e3 << " mm / " << opt_run.base_attitude_drift * 180.0 / M_PI
      << " deg\n"
      << "tasks: plain " << (baseline_task.kind == CaptureTask::Kind::Pose ? "pose" : "position")
      << ", optimized " << (task.kind == CaptureTask::Kind::Pose ? "pose" : "position")
      << "; F_max: Eq. 24 closed form; exact: peak of the single-body model (Eq. 16)\n";
  if (base_run.damped_steps + opt_run.damped_steps > 0)
    out << "note: near a singularity the pseudo-inverse was damped in "
        << base_run.damped_steps + opt_run.damped_steps << " evaluations (smallest singular value "
        << std::min(base_run.min_singular_value, opt_run.min_singular_value) << ")\n";

  // --- regression run: every number of the result against the stored one -------------------------
  if (!o.expect.empty()) {
    const auto moved = compare_results(expected, j, tol, kNotCompared);
    if (!moved.empty()) {
      for (const auto& line : moved) std::cerr << line << "\n";
      std::cerr << "ffsr-optimize: error: --expect " << o.expect << ": " << moved.size()
                << (moved.size() == 1 ? " value differs" : " values differ") << " from the baseline (rtol "
                << tol.rtol << ", atol " << tol.atol << "; regenerate it with --json FILE)\n";
      return kExitRegression;
    }
  }
  return 0;
}

}  // namespace

void add_scenario_options(CLI::App& app, RunOptions& o) {
  auto vec = [&](const char* name, std::vector<double>& v, const char* help) {
    return app.add_option(name, v, help)->delimiter(',')->allow_extra_args(false);
  };
  app.add_option("--urdf", o.urdf, "Robot URDF (relative to the scenario file)");
  app.add_option("--end-effector", o.end_effector, "End-effector frame (default: the single leaf link)");
  o.load.add_to(app);  // bus, mount, locked joints, inertia repairs, end-effector offset (issue 11)
  vec("--joints-deg", o.joints_deg, "Initial joint angles, deg");
  vec("--base-position", o.base_position, "Initial base position, m");
  vec("--base-rpy-deg", o.base_rpy_deg, "Initial base attitude (roll, pitch, yaw), deg");
  app.add_option("--target-mass", o.target_mass, "Target mass, kg");
  vec("--target-inertia", o.target_inertia,
      "Target inertia: Ixx,Iyy,Izz[,Ixy,Ixz,Iyz], kg m^2 (target frame)");
  vec("--target-position", o.target_position, "Target centre of mass at t = 0, m");
  vec("--target-rpy-deg", o.target_rpy_deg, "Target attitude at t = 0, deg");
  vec("--target-angular-velocity-deg", o.target_angular_velocity_deg, "Target spin (target frame), deg/s");
  vec("--target-velocity", o.target_velocity, "Target linear velocity, m/s");
  vec("--contact-offset", o.contact_offset,
      "r_tp: contact point from the target centre of mass (target frame), m");
  vec("--normal", o.normal, "u_n: contact normal (target frame)");
  app.add_option("--model", o.model, "Hysteresis damping law (Table 1)");
  app.add_option("--stiffness", o.stiffness, "K, N/m^alpha");
  app.add_option("--exponent", o.exponent, "alpha");
  app.add_option("--restitution", o.restitution, "c_r, 0 < c_r <= 1");
  app.add_option("--approach-speed", o.approach_speed,
                 "End-effector speed along the normal at the capture, m/s");
  app.add_option("--task", o.task, "Optimized run's task: position or pose");
  app.add_option("--task-axes", o.task_axes, "Position task: constrained inertial axes, e.g. xy")
      ->capture_default_str();
  app.add_option("--baseline-task", o.baseline_task, "Plain run's task (default: the optimized run's)");
  vec("--final-rpy-deg", o.final_rpy_deg,
      "Pose task: final end-effector orientation (default: hold the initial)");
  app.add_option("--duration", o.duration, "Task time T, s");
  app.add_option("--step", o.step, "RK4 step, s");
  app.add_option("--gain", o.gain, "rho of Eq. 30 (< 0 lowers the objective)");
  app.add_option("--feedback", o.feedback, "Tracking feedback gain, 1/s")->capture_default_str();
  app.add_option("--tolerance", o.tolerance, "Required capture-point accuracy, m");
  app.add_option("--orientation-tolerance-deg", o.orientation_tolerance_deg,
                 "Pose task: required orientation accuracy, deg")
      ->capture_default_str();
  app.add_option(
         "--objective", o.objective,
         "mass (M_ie, the paper's), exact-force, or multibody-force (CVODE peak; global search only, the "
         "paper's method then descends M_ie)")
      ->capture_default_str();
  app.add_option("--global", o.global, "Also run the global capture optimization (true/false)")
      ->capture_default_str();
  if (!app.get_option_no_throw("--seed"))  // robust registers its own (Monte Carlo) --seed first
    app.add_option("--seed", o.seed, "Seed of the global search's random starts (non-negative integer)")
        ->capture_default_str();
  app.add_option(
      "--max-joint-rate-deg", o.max_joint_rate_deg,
      "Global run: largest joint rate, deg/s (> 0; default: not limited; the paper's method is not limited)");
  app.add_option("--global-starts", o.global_starts, "Global search: random starts (>= 1)")
      ->capture_default_str();
}

void register_run(CLI::App& app, Action& action, int argc, char** argv) {
  auto o = std::make_shared<RunOptions>();
  FromCommandLine from_cli;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--urdf" || a.rfind("--urdf=", 0) == 0) from_cli.urdf = true;
    if (a == "--expect" || a.rfind("--expect=", 0) == 0) from_cli.expect = true;
    if (a == "inspect" || a == "contact" || a == "xi" || a == "map" || a == "robust") break;
  }
  app.set_config(
      "--config", "",
      "Scenario file (TOML); every key is also a flag. Default: the built-in paper 3-DOF scenario");
  app.config_formatter(std::make_shared<ScenarioConfig>());  // [uncertainty] is the robust command's
  app.get_config_ptr()->check(CLI::ExistingFile);
  app.allow_config_extras(CLI::config_extras_mode::error);  // an unknown key in a scenario is an error
  add_scenario_options(app, *o);
  app.add_option("--json", o->json,
                 "Write the result (with the resolved scenario and the version) to this JSON file ('-': "
                 "standard output)");
  app.add_option("--csv", o->csv,
                 "Write the time series of both runs to this CSV file ('-': standard output)");
  app.add_option("--expect", o->expect,
                 "Regression run: compare every number of the result with this stored --json result; exit 4 "
                 "when one moved (relative to the scenario file)");
  app.add_option("--rtol", o->rtol, "--expect: relative tolerance")->capture_default_str();
  app.add_option("--atol", o->atol, "--expect: absolute floor for values near zero")->capture_default_str();
  app.add_option("--plot", o->plot,
                 "Draw the capture process and time histories into this (existing) folder");
  app.add_option("--plot-format", o->plot_format, "Figure format: png, svg or pdf")->capture_default_str();
  app.add_flag("--quiet", o->quiet, "No progress line");
  app.callback([o, &app, &action, from_cli] {
    if (!app.get_subcommands().empty()) return;
    action = [o, &app, from_cli] {
      if (o->config.empty()) {
        // the built-in default scenario fills every key not given on the command line
        std::istringstream in(kPaper3dofScenario);
        for (const CLI::ConfigItem& item : CLI::ConfigTOML().from_config(in)) {
          CLI::Option* opt = app.get_option_no_throw("--" + item.name);
          if (opt && opt->count() == 0) {
            opt->add_result(item.inputs);
            opt->run_callback();
          }
        }
      }
      return run_scenario(*o, app, from_cli);
    };
  });
  app.get_config_ptr()->each([o](const std::string& s) { o->config = s; });
}

}  // namespace ffsr::cli
