// ffsr/jobs/detail/result_json.hpp -- the result schema: the main job's result (ffsr/jobs/scenario_run.hpp)
// as JSON, the keys and values of `ffsr-optimize --json`.
#pragma once

#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/jobs/detail/base_disturbance_json.hpp"
#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/jobs/detail/scenario_series.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace ffsr {

namespace detail {

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

/// The resolved scenario (inputs, recorded for reproducibility): the source, the end-effector frame
/// and the joints as loaded, then the echo of every key of the table (ScenarioKey::echo).
inline nlohmann::json resolved_json(const Scenario& sc) {
  const Model& model = *sc.model;
  nlohmann::json j = {{"source", sc.builtin ? "built-in paper_3dof" : sc.keys.file},
                      {"end_effector", model.frame(sc.problem.frame).name},
                      {"joint_names", model.joint_names()}};
  for (const ScenarioKey& key : scenario_keys())
    if (key.echo) key.echo(sc, j);
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
  x["shooting_iterations"] = r.counters.shooting_iterations;
  x["goals_tried"] = r.counters.goals_tried;
  x["goals_out_of_limits"] = r.counters.goals_out_of_limits;
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
                 {"evaluations", r.counters.evaluations},
                 {"multibody_evaluations", r.counters.objective_evaluations},
                 {"seconds", r.counters.search_seconds}};
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
  if (g.post_capture) {  // the post-capture constraints: the figures at the capture reached
    const PostCaptureFigures& f = *g.post_capture;
    x["post_capture_constraints"] = {
        {"time_to_rest", f.time_to_rest},
        {"peak_joint_torque", f.peak_joint_torque},
        {"peak_joint", f.peak_joint >= 0 ? sc.model->joint(f.peak_joint).name : ""},
        {"peak_gripper_force", f.peak_gripper_force},
        {"peak_gripper_moment", f.peak_gripper_moment},
        {"candidates", g.post_capture_candidates},
        {"candidates_meeting_constraints", g.post_capture_admitted},
        {"reached_goals_rejected", g.result.counters.goals_not_admitted}};
  }
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

/// Shapes and clearance (the keys are echoed in "scenario" by the key table): each run's
/// "min_clearance" (overall and per kind of pair: distance m, pair, time s), the global run's goals
/// rejected by the path check.
inline void add_clearance_json(nlohmann::json& j, const ScenarioResult& r) {
  for (const auto& [name, c] : r.clearances) j[name]["min_clearance"] = clearance_json(c);
  if (r.global) j["global"]["goals_rejected_by_clearance"] = r.global->result.counters.goals_rejected;
}

}  // namespace detail

namespace detail {
// Declared here too: scenario_run.hpp includes this file after the two below, but a translation unit
// that opens with one of them reaches this file first.
inline void add_base_disturbance_json(nlohmann::json& j, const Scenario& sc, const ScenarioResult& r);
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
  // each row's keys that its run does not take (ScenarioKey::skips)
  for (const auto& [name, row] : {std::pair{"baseline", ScenarioRow::Plain},
                                  {"optimized", ScenarioRow::Optimized},
                                  {"global", ScenarioRow::Global}})
    if (j.contains(name)) j[name]["keys_not_applied"] = keys_not_applied(sc.keys, row);
  for (const DetumbleJobResult& d : r.post_capture) j[d.run]["post_capture"] = post_capture_json(sc, d);
  detail::add_base_disturbance_json(j, sc, r);
  if (sc.geometry) detail::add_clearance_json(j, r);
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
