// ffsr/io/detail/scenario_run.hxx -- bodies of ffsr/io/scenario_run.hpp.
#pragma once

namespace ffsr {

namespace detail {

/// The options of the plain (`plain` true: gain 0, the baseline task) or the optimized run.
inline CaptureOptions row_options(const Scenario& sc, const ScenarioRunOptions& options, bool plain) {
  CaptureOptions opt = sc.capture;
  opt.record_series = opt.record_series || options.record_series || sc.geometry;  // distances along the path
  if (plain) {
    opt.gain = 0.0;
    opt.progress = options.plain_progress;
  } else {
    opt.hold_base_attitude = sc.hold_base_attitude;  // the optimized run only
    opt.progress = options.optimized_progress;
  }
  add_clearance_barrier(sc, opt);  // with a clearance: both runs keep it in their null space
  return opt;
}

/// The plain or the optimized run; a NumericalError names it ("plain run: ...").
inline CaptureResult plan_row(const Scenario& sc, const ScenarioRunOptions& options, bool plain) {
  const CaptureOptions opt = row_options(sc, options, plain);
  try {
    return plan_capture(sc.problem, plain ? sc.baseline_task : sc.task, opt);
  } catch (const NumericalError& e) {
    throw NumericalError(str(plain ? "plain" : "optimized", " run: ", e.what()));
  }
}

}  // namespace detail

inline std::pair<CaptureResult, CaptureResult> plan_plain_and_optimized(const Scenario& sc,
                                                                        const ScenarioRunOptions& options) {
  CaptureResult base_run = detail::plan_row(sc, options, true);
  CaptureResult opt_run = detail::plan_row(sc, options, false);
  return {std::move(base_run), std::move(opt_run)};
}

inline std::shared_ptr<RobustForceObjective> scenario_robust_objective(const Scenario& sc,
                                                                       const UncertaintySpec& spec) {
  UncertainNominal nominal;
  nominal.target = propagate_target(sc.problem.target, sc.capture.duration);
  nominal.contact = sc.problem.contact;
  nominal.approach_speed = sc.problem.approach_speed;
  UncertaintySpec s = spec;
  s.seed = robust_objective_seed(spec);
  std::vector<UncertainSample> samples(s.samples);
  const int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  parallel_for(0, s.samples, threads, [&](std::uint64_t i) { samples[i] = draw_sample(s, nominal, i); });
  return std::make_shared<RobustForceObjective>(std::move(samples), sc.problem.law);
}

namespace detail {

/// run_global with the paper's-method run, or without it (null).
inline GlobalRun run_global(const Scenario& sc, const CaptureResult* paper_run, GlobalObjective objective,
                            std::shared_ptr<RobustForceObjective> robust, bool tight_reaching) {
  CaptureOptions opt = sc.capture;
  opt.gain = 0.0;
  opt.max_joint_rate = sc.keys.max_joint_rate_deg * M_PI / 180.0;
  opt.progress = nullptr;
  GlobalCaptureOptions g;
  g.search.seed = sc.seed;
  g.search.starts = sc.keys.global_starts;
  g.search.objective = objective;
  g.search.robust = robust;
  g.search.multibody.joint_stiffness = sc.joint_stiffness;  // joint models: the servoed multibody reference
  g.search.multibody.joint_damping = sc.joint_damping;
  g.search.multibody.armature = sc.problem.joints.armature;
  // robust-force scenarios: the reaching runs land within 0.01 % of the manifold optimum at the reached
  // base pose (the library's default, 1 %, is coarser than the difference between the robust and the
  // nominal optimum), the nominal global run beside the robust one too, so the two compare fairly
  // so do the runs with a base-rate limit: M_ie is flat at its constrained optimum while the rate is
  // not, and a run within 1 % of M_ie can sit where the rate is well above the limit
  if (tight_reaching || objective == GlobalObjective::RobustForce || sc.keys.max_base_rate_deg > 0) {
    g.gap_percent = 0.01;
    g.max_iterations = 16;
  }
  if (paper_run) g.extra_starts = {paper_run->theta};
  if (sc.keys.max_base_rate_deg > 0)  // the impact's base-rate jump as a constraint of every search
    g.search.inequalities = base_rate_inequality(sc.problem, prepare_capture(sc.problem, sc.task, opt),
                                                 sc.keys.max_base_rate_deg * M_PI / 180.0);
  g.reconfigure.mode = reconfigure_mode_of(sc.keys.reconfigure, "--reconfigure");
  g.reconfigure.duration = sc.keys.reconfigure_duration;
  opt.record_series = opt.record_series || sc.geometry;
  GlobalRun r;
  try {
    r.result = plan_global_with_clearance(sc, opt, g);  // as plan_capture_global without a clearance
  } catch (const ReconfigurationRateError& e) {
    throw InputError(str("--reconfigure-duration: a reconfiguration in ", e.duration, " s: joint '", e.joint,
                         "' needs ", std::ceil(e.needed * 18000 / M_PI) / 100,
                         " deg/s, max-joint-rate-deg is ", e.limit * 180 / M_PI));
  } catch (const InfeasibleInequalitiesError& e) {
    if (!(sc.keys.max_base_rate_deg > 0)) throw InputError(str("global run: ", e.what()));
    throw InputError(
        str("--max-base-rate-deg: no capture configuration found keeps the impact's base-rate "
            "jump within ",
            std::setprecision(6), sc.keys.max_base_rate_deg, " deg/s",
            sc.geometry ? " and the clearance" : "", " (`ffsr-optimize pareto` shows the least)"));
  } catch (const InputError& e) {
    if (std::string(e.what()).find("max joint rate") != std::string::npos)
      throw InputError(str("--max-joint-rate-deg: ", e.what()));
    throw InputError(str("global run: ", e.what()));
  } catch (const NumericalError& e) {
    throw NumericalError(str("global run: ", e.what()));
  }
  const CaptureSetup setup = prepare_capture(sc.problem, sc.task, opt);
  r.paper_objective =
      paper_run ? evaluate_capture(sc.problem, setup, paper_run->base, paper_run->theta, objective, {},
                                   robust.get())
                      .objective
                : std::numeric_limits<double>::quiet_NaN();
  r.branches = capture_branches(sc.problem, sc.task, opt, setup, r.result.search, r.result.run.base, 6,
                                std::max(1u, std::thread::hardware_concurrency()));
  return r;
}

}  // namespace detail

inline GlobalRun run_global(const Scenario& sc, const CaptureResult& paper_run, GlobalObjective objective,
                            std::shared_ptr<RobustForceObjective> robust, bool tight_reaching) {
  return detail::run_global(sc, &paper_run, objective, std::move(robust), tight_reaching);
}

inline GlobalRun run_global(const Scenario& sc, GlobalObjective objective,
                            std::shared_ptr<RobustForceObjective> robust, bool tight_reaching) {
  return detail::run_global(sc, nullptr, objective, std::move(robust), tight_reaching);
}

namespace detail {

/// The robust-force sample set of the scenario (its [uncertainty] table).
inline UncertaintySpec robust_force_spec(const Scenario& sc) {
  try {
    return uncertainty_spec(sc.keys);
  } catch (const InputError&) {
    if (!sc.keys.document || !sc.keys.document->get("uncertainty"))
      throw InputError(str("--objective: robust-force needs an [uncertainty] table in ", sc.where));
    throw;
  }
}

}  // namespace detail

inline ScenarioResult run_scenario(const Scenario& sc, const ScenarioRunOptions& options) {
  ScenarioResult r;
  if (!options.keep_going || !sc.keys.global) {
    std::tie(r.plain, r.optimized) = plan_plain_and_optimized(sc, options);
  } else {  // a failed row is recorded; the global run decides
    for (const bool plain : {true, false}) try {
        (plain ? r.plain : r.optimized) = detail::plan_row(sc, options, plain);
      } catch (const NumericalError& e) {
        (plain ? r.plain_failure : r.optimized_failure) = e.what();
      }
  }
  if (sc.geometry) {
    if (r.plain_ok()) r.clearances.emplace_back("baseline", run_clearance(sc, r.plain));
    if (r.optimized_ok()) r.clearances.emplace_back("optimized", run_clearance(sc, r.optimized));
  }
  if (!sc.keys.global) return r;
  if (sc.objective == GlobalObjective::RobustForce) {
    r.robust_spec = detail::robust_force_spec(sc);
    r.robust = scenario_robust_objective(sc, r.robust_spec);
  }
  try {
    r.global = detail::run_global(sc, r.optimized_ok() ? &r.optimized : nullptr, sc.objective, r.robust, false);
  } catch (const NumericalError& e) {
    if (r.plain_ok() && r.optimized_ok()) throw;
    throw NumericalError(detail::str(r.plain_ok() ? r.optimized_failure : r.plain_failure,
                                     "; the global run failed too: ", e.what()));
  }
  if (sc.geometry) r.clearances.emplace_back("global", run_clearance(sc, r.global->result.run));
  if (r.robust) {
    const Model& model = *sc.model;
    Data data(model);
    const std::pair<const char*, const CaptureResult*> rows[] = {
        {"baseline", r.plain_ok() ? &r.plain : nullptr},
        {"optimized", r.optimized_ok() ? &r.optimized : nullptr},
        {"global", &r.global->result.run}};
    for (const auto& [name, run] : rows) {
      if (!run) continue;
      const auto v =
          r.robust->value(robot_inverse_inertia(model, data, run->base, run->theta, sc.problem.frame));
      r.robust_rows.push_back({name, v.cvar95, v.p95});
    }
  }
  return r;
}

// --- JSON ----------------------------------------------------------------------------------------------

namespace detail {

inline nlohmann::json vector_json(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

inline nlohmann::json run_json(const CaptureResult& r, const CaptureTask& task, double gain) {
  const Eigen::Vector4d q = r.base.orientation.coeffs();
  return {{"task", task.kind == CaptureTask::Kind::Pose ? "pose" : "position"},
          {"max_joint_rate_deg", r.max_joint_rate * 180.0 / M_PI},
          {"gain", gain},
          {"capture_configuration_deg", vector_json(r.theta * (180.0 / M_PI))},
          {"integrated_effective_mass", r.M_ie},
          {"approach_velocity", r.approach_velocity},
          {"f_max_closed_form", r.f_max_closed_form},
          {"f_max_exact", r.f_max_exact},
          {"tracking_error", r.tracking_error},
          {"capture_distance", r.capture_distance},
          {"orientation_error_deg", r.orientation_error * 180.0 / M_PI},
          {"end_effector_position", vector_json(r.end_effector)},
          {"capture_point", vector_json(r.capture_point)},
          {"base_position", vector_json(r.base.position)},
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

}  // namespace detail

/// [{link, what, before, after}]: the loader's repairs.
inline nlohmann::json repairs_json(const UrdfReport& report) {
  nlohmann::json a = nlohmann::json::array();
  for (const ModelRepair& r : report.repairs) {
    nlohmann::json before = r.before.size() == 1 ? nlohmann::json(r.before[0]) : nlohmann::json(r.before);
    nlohmann::json after = r.after.size() == 1 ? nlohmann::json(r.after[0]) : nlohmann::json(r.after);
    a.push_back({{"link", r.link}, {"what", r.what}, {"before", before}, {"after", after}});
  }
  return a;
}

/// Merged links, mimic and locked joints, repairs: what the loader did to the file.
inline nlohmann::json report_json(const UrdfReport& report) {
  nlohmann::json mimic = nlohmann::json::array(), locked = nlohmann::json::array();
  for (const auto& m : report.mimics)
    mimic.push_back(
        {{"joint", m.joint}, {"leader", m.leader}, {"multiplier", m.multiplier}, {"offset", m.offset}});
  for (const auto& l : report.locked) locked.push_back({{"joint", l.first}, {"value", l.second}});
  return {{"merged_links", report.merged_links},
          {"mimic_joints", mimic},
          {"locked_joints", locked},
          {"model_repairs", repairs_json(report)}};
}

namespace detail {

/// The resolved scenario (inputs, recorded for reproducibility).
inline nlohmann::json resolved_json(const Scenario& sc) {
  const ScenarioKeys& o = sc.keys;
  const Model& model = *sc.model;
  nlohmann::json j = {{"source", sc.builtin ? "built-in paper_3dof" : o.file},
                      {"urdf", o.urdf},
                      {"end_effector", model.frame(sc.problem.frame).name},
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
  j.update(o.load.to_json());
  j["global"] = o.global;
  j["seed"] = o.seed;
  j["max-joint-rate-deg"] = o.max_joint_rate_deg;
  j["global-starts"] = o.global_starts;
  j["base-attitude"] = o.base_attitude;
  j["reconfigure"] = o.reconfigure;
  if (o.given.count("reconfigure-duration")) j["reconfigure-duration"] = o.reconfigure_duration;
  if (o.given.count("max-base-rate-deg")) j["max-base-rate-deg"] = o.max_base_rate_deg;
  if (o.contact_joints != "free") {  // joint models of the contact: absent means free (the paper's)
    j["contact-joints"] = o.contact_joints;
    j["armature"] = vector_json(sc.problem.joints.armature);
  }
  return j;
}

/// The branches (distinct local optima at the reached base pose), sorted by objective.
inline nlohmann::json branches_json(const std::vector<CaptureBranch>& branches) {
  nlohmann::json a = nlohmann::json::array();
  for (const CaptureBranch& b : branches) {
    std::vector<double> q_deg(b.theta.data(), b.theta.data() + b.theta.size());
    for (double& v : q_deg) v *= 180.0 / M_PI;
    a.push_back({{"configuration_deg", q_deg},
                 {"integrated_effective_mass", b.M_ie},
                 {"objective_value", b.objective},
                 {"orientation_error_deg", b.orientation_error * 180.0 / M_PI},
                 {"position_error", b.position_error},
                 {"reachable_without_reconfiguration",
                  b.reachable_without_reconfiguration ? nlohmann::json(*b.reachable_without_reconfiguration)
                                                      : nlohmann::json(nullptr)}});
  }
  return a;
}

/// "<prefix>mass_reduction_percent", "<prefix>force_reduction_percent" and
/// "<prefix>exact_force_reduction_percent" of `after` against `before`; null when either run failed (null).
inline void add_reductions_json(nlohmann::json& j, const std::string& prefix, const CaptureResult* before,
                                const CaptureResult* after) {
  auto reduction = [&](double CaptureResult::*value) {
    return before && after ? nlohmann::json(reduction_percent(before->*value, after->*value))
                           : nlohmann::json(nullptr);
  };
  j[prefix + "mass_reduction_percent"] = reduction(&CaptureResult::M_ie);
  j[prefix + "force_reduction_percent"] = reduction(&CaptureResult::f_max_closed_form);
  j[prefix + "exact_force_reduction_percent"] = reduction(&CaptureResult::f_max_exact);
}

/// The global row; its reductions against `base_run` (null: the plain run failed, null reductions).
inline void add_global_json(nlohmann::json& j, const Scenario& sc, const GlobalRun& g,
                            const CaptureResult* base_run) {
  const GlobalCaptureResult& r = g.result;
  nlohmann::json x = run_json(r.run, sc.task, 0.0);
  x["objective"] = sc.keys.objective;
  x["objective_value"] = r.objective;
  x["manifold_optimum"] = r.manifold_optimum;
  x["optimality_gap_percent"] = r.optimality_gap_percent;
  x["search_distance_bound"] = r.search_distance_bound;
  x["shooting_iterations"] = r.shooting_iterations;
  x["goals_tried"] = r.goals_tried;
  x["goals_out_of_limits"] = r.goals_out_of_limits;
  x["reached_manifold_optimum"] = r.reached_manifold_optimum;
  x["reconfigured"] = r.reconfigured;
  nlohmann::json phases = nlohmann::json::array();
  for (const RunPhase& p : r.phases)
    phases.push_back({{"name", p.name},
                      {"t_begin", p.t_begin},
                      {"t_end", p.t_end},
                      {"duration", p.t_end - p.t_begin},
                      {"base_attitude_change_deg", p.base_attitude_change * 180.0 / M_PI},
                      {"base_position_change_m", p.base_position_change},
                      {"max_joint_rate_deg_s", p.max_joint_rate * 180.0 / M_PI}});
  x["phases"] = phases;
  x["search"] = {{"method", r.search.method},
                 {"starts", r.search.starts},
                 {"evaluations", r.evaluations},
                 {"multibody_evaluations", r.objective_evaluations},
                 {"seconds", r.search_seconds}};
  if (sc.objective == GlobalObjective::MultibodyForce) {
    // the ranked local optima of M_ie at the reached base pose: how far the mass and force optima are apart
    nlohmann::json ranked = nlohmann::json::array();
    for (const ManifoldPoint& p : r.search.local_optima)
      if (p.objective > 0)
        ranked.push_back({{"integrated_effective_mass", p.M_ie}, {"f_max_multibody", p.objective}});
    x["search"]["ranked_local_optima"] = ranked;
    x["f_max_multibody"] = r.objective;
    if (std::isfinite(g.paper_objective)) j["optimized"]["f_max_multibody"] = g.paper_objective;
  }
  x["branches"] = branches_json(g.branches);
  j["global"] = x;
  add_reductions_json(j, "global_", base_run, &r.run);
}

/// A clearance report as JSON: the smallest distance {distance m, pair, time s, kind} with the
/// smallest of each kind of pair ("arm_target", "arm_bus", "self"; null where there is no pair).
inline nlohmann::json clearance_json(const ClearanceReport& c) {
  auto entry = [](const ClearanceReport::Entry& e) {
    if (e.pair.empty()) return nlohmann::json(nullptr);
    return nlohmann::json{{"distance", e.distance}, {"pair", e.pair}, {"time", e.time}};
  };
  nlohmann::json x = entry(c.overall);
  if (!x.is_null()) x["kind"] = c.kind;
  x["arm_target"] = entry(c.arm_target);
  x["arm_bus"] = entry(c.arm_bus);
  x["self"] = entry(c.self);
  return x;
}

/// Shapes and clearance: the keys in "scenario", each run's "min_clearance" (overall and per kind
/// of pair: distance m, pair, time s), the global run's goals rejected by the path check.
inline void add_clearance_json(nlohmann::json& j, const Scenario& sc, const ScenarioResult& r) {
  const ScenarioKeys& k = sc.keys;
  j["scenario"]["target-shape"] = k.target_shape;
  j["scenario"]["target-size"] = k.target_size;
  j["scenario"]["target-shape-offset"] = k.target_shape_offset;
  j["scenario"]["link-radius"] = k.link_radius;
  j["scenario"]["bus-box"] = k.bus_box;
  j["scenario"]["clearance"] = k.clearance;
  j["scenario"]["contact-exemption"] = k.contact_exemption;
  for (const auto& [name, c] : r.clearances) j[name]["min_clearance"] = clearance_json(c);
  if (r.global) j["global"]["goals_rejected_by_clearance"] = r.global->result.goals_rejected;
}

}  // namespace detail

namespace detail {
/// Defined in base_disturbance_json.hxx (the impact disturbance of each run).
inline void add_base_disturbance_json(nlohmann::json& j, const Scenario& sc, const ScenarioResult& r);
/// Defined in scenario_series.hxx (the bodies, shapes, capture instant and normal).
inline nlohmann::json scene_json(const Scenario& sc);
}  // namespace detail

inline nlohmann::json scenario_json(const Scenario& sc, const ScenarioResult& r, const std::string& version) {
  nlohmann::json j;
  j["version"] = version;
  j["scenario"] = detail::resolved_json(sc);
  j["model_repairs"] = repairs_json(sc.report);
  j["model_load"] = report_json(sc.report);
  j["capture_point"] = detail::vector_json(r.first_run().capture_point);
  // a run that failed (ScenarioRunOptions::keep_going): {"error": its message}, its reductions null
  j["baseline"] = r.plain_ok() ? detail::run_json(r.plain, sc.baseline_task, 0.0)
                               : nlohmann::json{{"error", r.plain_failure}};
  j["optimized"] = r.optimized_ok() ? detail::run_json(r.optimized, sc.task, sc.capture.gain)
                                    : nlohmann::json{{"error", r.optimized_failure}};
  const CaptureResult* plain = r.plain_ok() ? &r.plain : nullptr;
  detail::add_reductions_json(j, "", plain, r.optimized_ok() ? &r.optimized : nullptr);
  if (r.global) detail::add_global_json(j, sc, *r.global, plain);
  detail::add_base_disturbance_json(j, sc, r);
  if (sc.geometry) detail::add_clearance_json(j, sc, r);
  j["scene"] = detail::scene_json(sc);
  if (r.robust) {
    nlohmann::json rj = {
        {"measure", "CVaR_95 (mean of the largest 5 %) and p95 (nearest rank) of the exact F_max, N"},
        {"samples", r.robust->samples().size()},
        {"seed", robust_objective_seed(r.robust_spec)}};
    for (const RobustRow& row : r.robust_rows) rj[row.name] = {{"cvar95", row.cvar95}, {"p95", row.p95}};
    j["robust"] = rj;
  }
  return j;
}

}  // namespace ffsr
