// ffsr/jobs/detail/detumble_result.hpp -- the result of the job `detumble` (ffsr/jobs/detumble.hpp) and
// its JSON, in a header of their own: the main job's result and JSON (ffsr/jobs/scenario_run.hpp) hold
// one per run (the post_capture object), and neither job includes the other's header for it.
#pragma once

#include "ffsr/control/detumble_replay.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/model/attach.hpp"
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include <cmath>
#include <optional>
#include <string>

namespace ffsr {

/// The time-optimal plan from a run's start (`detumble --plan`: control/detumble_planner.hpp) and its
/// re-run by CVODE under the plan's controls, then the law holding (replay_detumble_plan).
struct DetumblePlanJob {
  DetumblePlan plan;
  DetumblePlanRun run;
};

/// The job's result: the grasp, the run's summary and series, the limits it ran under.
struct DetumbleJobResult {
  std::string
      run;  ///< the main job's run it starts from (baseline, optimized, global); empty: a configuration
  Eigen::VectorXd theta;  ///< the capture configuration, rad
  GraspResult grasp;
  /// grasp-after = contact: the Hertz contact run before the lock and its impulse on the gripper (N s)
  std::optional<MultibodyContactResult> contact;
  Vector3 contact_impulse = Vector3::Zero();
  /// grasp-after = held: no grasp, the stack holds its target from the start (grasp: held_grasp's, no
  /// impulse)
  bool held = false;
  DetumbleRunResult result;
  DetumbleSettings settings;  ///< what it ran under, as detumble_settings built them
  std::string peak_joint_name;  ///< the joint of the peak torque
  DetumbleState start;          ///< the stack's state after the grasp, where the run starts
  std::optional<DetumblePlanJob> plan;  ///< with `detumble --plan`
};

/// The plan's object of the detumble JSON: the solver's account, the re-run's check (its rest test at
/// T, the largest excess over the bounds, the hold), the controls of each interval (joint torques; the
/// actuator's force and moment in the base frame) and the states at the nodes.
inline nlohmann::json detumble_plan_json(const DetumblePlanJob& p) {
  using detail::vector_json;
  const DetumblePlan& plan = p.plan;
  const DetumblePlanRun& r = p.run;
  nlohmann::json j{{"time_to_rest", plan.duration},
                   {"intervals", plan.intervals()},
                   {"substeps", plan.substeps},
                   {"solver_status", plan.status},
                   {"iterations", plan.iterations},
                   {"solve_seconds", plan.solve_seconds},
                   {"constraint_violation", plan.constraint_violation},
                   {"initial_guess_time_to_rest", plan.warm_start_duration},
                   {"free_intervals_time_to_rest", plan.free_duration > 0 ? nlohmann::json(plan.free_duration)
                                                                          : nlohmann::json(nullptr)}};
  j["rerun"] = {{"at_rest", r.at_rest},
                {"final_joint_rate", r.end_joint_rate},
                {"final_relative_rate", r.end_relative_rate},
                {"final_stack_rate", r.end_base_rate},
                {"final_base_speed", r.end_base_speed},
                {"worst_bound_excess", r.worst_bound_excess},
                {"peak_joint_torque", r.peak_joint_torque},
                {"peak_gripper_force", r.peak_gripper_force},
                {"peak_gripper_moment", r.peak_gripper_moment},
                {"momentum_drift", r.momentum_drift},
                {"dwell_peak_rate", r.dwell_peak_rate},
                {"dwell_at_rest", r.dwell_at_rest}};
  nlohmann::json controls = nlohmann::json::array(), nodes = nlohmann::json::array();
  const double h = plan.interval();
  for (int k = 0; k < plan.intervals(); ++k) {
    const auto i = static_cast<size_t>(k);
    controls.push_back({{"t", k * h},
                        {"tau", vector_json(plan.tau[i])},
                        {"base_force", vector_json(Eigen::VectorXd(plan.base_wrench[i].head<3>()))},
                        {"base_moment", vector_json(Eigen::VectorXd(plan.base_wrench[i].tail<3>()))}});
  }
  for (int k = 0; k <= plan.intervals(); ++k) {
    const DetumbleState& x = plan.nodes[static_cast<size_t>(k)];
    const Quaternion q = x.base.orientation;
    nodes.push_back({{"t", k * h},
                     {"theta", vector_json(x.theta)},
                     {"v", vector_json(x.v)},
                     {"base_position", vector_json(Eigen::VectorXd(x.base.position))},
                     {"base_quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
                     {"wheel_momentum", vector_json(Eigen::VectorXd(x.wheel_momentum))}});
  }
  j["controls"] = std::move(controls);
  j["nodes"] = std::move(nodes);
  return j;
}

/// The grasped target as attached at the gripper (grasp.attachment of the JSON): the gripper frame's
/// name, the target's mass and inertia (its own axes), the pose of its centre-of-mass frame in the
/// gripper frame. The target's pose at a sample is the gripper frame's pose composed with this one.
inline nlohmann::json attachment_json(const Model& model, int gripper, const AttachedBody& b) {
  using detail::vector_json;
  const Quaternion q(b.pose.R);
  nlohmann::json inertia = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) inertia.push_back(vector_json(Eigen::VectorXd(b.inertia.row(i).transpose())));
  return {{"frame", model.frame(gripper).name},
          {"mass", b.mass},
          {"inertia", inertia},
          {"position", vector_json(Eigen::VectorXd(b.pose.p))},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

/// The result as JSON: the keys and values of `ffsr-optimize detumble --json` (`version` as given) for
/// the robot `model` and its gripper frame `gripper`.
inline nlohmann::json detumble_json(const Model& model, int gripper,
                                    const DetumbleJobResult& d, const std::string& version) {
  const GraspResult& g = d.grasp;
  using detail::vector_json;
  const DetumbleRunResult& r = d.result;
  const DetumbleSample& e = r.series.back();
  nlohmann::json j;
  j["version"] = version;
  if (!d.run.empty()) j["run"] = d.run;
  j["joints_deg"] = vector_json(Eigen::VectorXd(d.theta * 180.0 / M_PI));
  j["grasp"] = {{"impulse_force", vector_json(Eigen::VectorXd(g.impulse.head<3>()))},
                {"impulse_moment", vector_json(Eigen::VectorXd(g.impulse.tail<3>()))},
                {"base_velocity_jump", vector_json(Eigen::VectorXd(g.base_velocity_jump.head<3>()))},
                {"base_angular_velocity_jump", vector_json(Eigen::VectorXd(g.base_velocity_jump.tail<3>()))},
                {"energy_before", g.energy_before},
                {"energy_after", g.energy_after},
                {"start", d.held ? "held" : d.contact ? "contact" : "approach"},
                {"attachment", attachment_json(model, gripper, g.body)}};
  if (d.contact) {  // the Hertz phase before the lock
    const MultibodyContactResult& c = *d.contact;
    j["grasp"]["contact"] = {{"model", c.model},
                             {"peak_force", c.f_max},
                             {"duration", c.contact_duration},
                             {"impulse_force", vector_json(Eigen::VectorXd(d.contact_impulse))},
                             {"approach_velocity", c.approach_velocity},
                             {"separation_velocity", c.separation_velocity},
                             {"energy_start", c.energy_start},
                             {"energy_end", c.energy_end}};
  }
  // the settings as resolved (inputs, not results)
  const DetumbleSettings& s = d.settings;
  j["parameters"] = {{"joint_torque_limit", vector_json(s.limits.joint_torque)},
                     {"base_actuator", actuator_name(s.limits.actuator)},
                     {"stop_stack_spin", s.options.stop_stack_spin},
                     {"rest_rate", s.options.rest_rate},
                     {"tick", s.run.tick},
                     {"horizon", s.run.horizon},
                     {"dwell", s.run.dwell},
                     {"max_decay", s.options.max_decay},
                     {"max_base_decay", s.options.max_base_decay}};
  const auto limit = [](double x) { return std::isinf(x) ? nlohmann::json() : nlohmann::json(x); };  // null: none
  j["parameters"]["gripper_force_limit"] = limit(s.limits.gripper_force);
  j["parameters"]["gripper_moment_limit"] = limit(s.limits.gripper_moment);
  j["status"] = status_name(e.command.status);
  j["at_rest"] = r.at_rest;
  j["time_to_rest"] = r.time_to_rest;
  j["peak_joint_torque"] = r.peak_joint_torque;
  j["peak_joint"] = d.peak_joint_name;
  j["peak_gripper_force"] = r.peak_gripper_force;
  j["peak_gripper_moment"] = r.peak_gripper_moment;
  j["base_attitude_excursion"] = r.base_attitude_excursion;
  j["peak_wheel_momentum"] = r.peak_wheel_momentum;
  j["momentum_drift"] = r.momentum_drift;
  j["energy_start"] = r.energy_start;
  j["energy_end"] = r.energy_end;
  j["final_joint_rate"] = e.command.joint_rate;
  j["final_relative_rate"] = e.command.relative_rate;
  j["final_stack_rate"] = e.command.stack_rate;
  j["dwell_peak_rate"] = r.dwell_peak_rate;
  j["dwell_at_rest"] = r.dwell_at_rest;
  j["ticks"] = r.ticks;
  if (d.plan) j["plan"] = detumble_plan_json(*d.plan);
  return j;
}

/// One run's `post_capture` object of the main job's JSON: the run's `detumble --json` (detumble_json)
/// without `version` and `run`.
inline nlohmann::json post_capture_json(const Scenario& sc, const DetumbleJobResult& d) {
  nlohmann::json j = detumble_json(*sc.model, sc.problem.frame, d, "");
  j.erase("version");
  j.erase("run");
  return j;
}

}  // namespace ffsr
