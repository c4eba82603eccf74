// ffsr/jobs/detail/detumble_result.hpp -- the result of the job `detumble` (ffsr/jobs/detumble.hpp) and
// its JSON, in a header of their own: the main job's result and JSON (ffsr/jobs/scenario_run.hpp) hold
// one per run (the post_capture object), and neither job includes the other's header for it.
#pragma once

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

/// The job's result: the grasp, the run's summary and series, the limits it ran under.
struct DetumbleJobResult {
  std::string
      run;  ///< the main job's run it starts from (baseline, optimized, global); empty: a configuration
  Eigen::VectorXd theta;  ///< the capture configuration, rad
  GraspResult grasp;
  /// grasp-after = contact: the Hertz contact run before the lock and its impulse on the gripper (N s)
  std::optional<MultibodyContactResult> contact;
  Vector3 contact_impulse = Vector3::Zero();
  DetumbleRunResult result;
  DetumbleSettings settings;  ///< what it ran under, as detumble_settings built them
  std::string peak_joint_name;  ///< the joint of the peak torque
};

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
                {"start", d.contact ? "contact" : "approach"},
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
