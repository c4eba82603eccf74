// ffsr/jobs/detumble.hpp -- the job `detumble`: the grasp at the end of the approach (or of the Hertz
// contact run) of a subject (jobs/subject.hpp: the robot at its configuration, the target), the target
// attached at the gripper (the stack), then the post-capture run under the scenario's limits
// (the Detumble keys); that result as JSON (`ffsr-optimize detumble --json`) and its series as CSV.
// Component ffsr::scenario (and SUNDIALS: ffsr::cvode). Never prints.
#pragma once

#include "ffsr/algorithm/joint_models.hpp"
#include "ffsr/control/contact_grasp.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/jobs/detail/detumble_result.hpp"
#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/jobs/detail/scenario_series.hpp"
#include "ffsr/jobs/detail/post_capture.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/jobs/subject.hpp"
#include "ffsr/model/attach.hpp"

#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>

namespace ffsr {

/// The grasp the run starts from (the key grasp-after) at the capture configuration (base, theta) with
/// the target (its position is not used: it is placed touching): approach, grasp_at_capture (the lock
/// at the end of the approach); contact, grasp_after_contact (the multibody Hertz run of the scenario's
/// contact law, the lock at its separation). Writes out.grasp, out.contact, out.contact_impulse; returns
/// the stack's start state (with contact: the configuration at the separation). InputError naming the key.
inline DetumbleState detumble_start(const Subject& s, const BasePose& base, const Eigen::VectorXd& theta,
                                    const Target& target, DetumbleJobResult& out) {
  using detail::str;
  const Robot& r = s.robot;
  const int ee = r.end_effector;
  if (s.keys.grasp_after != "contact") {
    out.grasp = grasp_at_capture(r.model, ee, base, theta, target, s.approach_speed);
    return {base, theta, out.grasp.v_after, Vector3::Zero()};
  }
  try {  // one law: 'all' or an unknown name is refused naming the key
    if (s.law == "all") throw InputError("expected one contact law with grasp-after = contact, got 'all'");
    make_contact_law(s.law, s.params, 1.0);
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, str("--model: ", e.what())));
  }
  ContactGraspResult c;
  try {
    c = grasp_after_contact(r.model, ee, base, theta, target, s.approach_speed, s.params, s.law);
  } catch (const InputError& e) {  // the bodies do not approach
    throw InputError(located_key_message(s.keys, str("--grasp-after: the contact run: ", e.what())));
  }
  out.grasp = c.grasp;
  out.contact = std::move(c.contact);
  out.contact_impulse = c.contact_impulse;
  return {out.contact->end.base, out.contact->end.theta, out.grasp.v_after, Vector3::Zero()};
}

/// The job: the grasp of detumble_start at the subject's configuration (grasp_at_capture: the contact
/// point moving at the approach speed along the target's normal; or after the Hertz contact run), the
/// stack, run_detumble. InputError for bad keys, an actuator too
/// small for the horizon (check_detumble_feasible), or a stack not at rest at the horizon.
inline DetumbleJobResult detumble(const Subject& s, const BasePose& base, const Eigen::VectorXd& theta,
                                  const Target& target) {
  using detail::str;
  DetumbleJobResult out;
  out.theta = theta;
  const Robot& r = s.robot;
  try {  // an error of a key the file gave names the file and the key's line
    detumble_settings(s.keys, r.model, out.limits, out.options);
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, e.what()));
  }
  const int ee = r.end_effector;
  DetumbleState start;
  try {  // a degenerate pair of bodies (a target inertia near zero): name the keys that set it
    start = detumble_start(s, base, theta, target, out);
  } catch (const NumericalError& e) {
    throw NumericalError(str(e.what(), " (--target-mass, --target-inertia: the target it grasps)"));
  }
  const Model stack = attach_body(r.model, r.model.frame(ee).name, out.grasp.body);
  DetumbleRunOptions run;
  run.tick = s.keys.detumble_tick;
  run.horizon = s.keys.detumble_horizon;
  try {  // an actuator that cannot stop the stack's spin: the key of the bound that is too small
    check_detumble_feasible(stack, start, out.limits, out.options, run.horizon);
  } catch (const DetumbleInfeasibleError& e) {
    const bool wheels = out.limits.actuator == BaseActuator::ReactionWheels;
    const char* key = e.bound == DetumbleBound::Actuator        ? "stop-stack-spin"
                      : e.bound == DetumbleBound::WheelMomentum ? "wheel-momentum"
                      : wheels                                  ? "wheel-torque"
                                                                : "thruster-torque";
    throw InputError(located_key_message(s.keys, str("--", key, ": ", e.what())));
  }
  out.result = run_detumble(stack, ee, out.grasp.body, start, out.limits, out.options, run);
  if (!out.result.at_rest) {
    const DetumbleSample& e = out.result.series.back();
    constexpr double deg = 180 / M_PI;
    const bool spin = out.options.stop_stack_spin;
    throw InputError(located_key_message(
        s.keys, str("--detumble-horizon: the stack is not at rest after ", run.horizon,
                    " s under these limits (largest joint rate ", e.joint_rate * deg,
                    " deg/s, gripper rate relative to the base ", e.relative_rate * deg, " deg/s",
                    spin ? str(", stack rate ", e.stack_rate * deg, " deg/s") : std::string(),
                    "; at rest below ", s.keys.rest_rate_deg, " deg/s): raise the ",
                    spin ? "limits, the wheels' momentum" : "joint torque limits", " or the horizon")));
  }
  out.peak_joint_name = out.result.peak_joint >= 0 ? r.model.joint(out.result.peak_joint).name : "";
  return out;
}

/// At the subject's configuration (its start state, the target at t = 0).
inline DetumbleJobResult detumble(const Subject& s) {
  return detumble(s, s.robot.base, s.robot.theta, s.target);
}

namespace detail {

/// The post-capture run from the capture of each of `runs` (the main job's run's name, its result) of
/// the scenario `sc` built from the subject's keys: each run's configuration and base pose at T, the
/// target at T. InputError naming the run it started from.
inline std::vector<DetumbleJobResult> detumble_each_run(
    const Subject& s, const Scenario& sc,
    const std::vector<std::pair<std::string, const CaptureResult*>>& runs) {
  const Target target = prepare_capture(sc.problem, sc.task, sc.capture).capture.target;
  std::vector<DetumbleJobResult> out;
  for (const auto& [name, run] : runs) {
    try {
      out.push_back(detumble(s, run->base, run->theta, target));
    } catch (const InputError& e) {  // which start it was
      throw InputError(str(e.what(), " (from the ", name, " run's capture)"));
    }
    out.back().run = name;
  }
  return out;
}

}  // namespace detail

/// From the capture of the main job's runs (jobs/scenario_run.hpp) of the scenario `sc` (built from
/// the subject's keys): `which` is plain, optimized, global or all (every run the scenario has); each
/// run's capture configuration and base pose at T, the target at T. InputError naming --run.
inline std::vector<DetumbleJobResult> detumble_runs(const Subject& s, const Scenario& sc,
                                                    const std::string& which) {
  using detail::str;
  if (which != "plain" && which != "optimized" && which != "global" && which != "all")
    throw InputError(str("--run: expected plain, optimized, global or all, got '", which, "'"));
  if (which == "global" && !sc.keys.global)
    throw InputError("--run: global asks for the global run, and this scenario has none (global = false)");
  std::pair<CaptureResult, CaptureResult> rows;
  ScenarioResult r;
  std::vector<std::pair<std::string, const CaptureResult*>> runs;
  if (which == "plain" || which == "optimized") {
    rows = plan_plain_and_optimized(sc);
    runs.emplace_back(which == "plain" ? "baseline" : "optimized",
                      which == "plain" ? &rows.first : &rows.second);
  } else {
    r = run_scenario(sc);
    if (which == "all") {
      runs.emplace_back("baseline", &r.plain);
      runs.emplace_back("optimized", &r.optimized);
    }
    if (r.global) runs.emplace_back("global", &r.global->result.run);
  }
  return detail::detumble_each_run(s, sc, runs);
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
/// the scenario's keys `keys`, the robot `model` and its gripper frame `gripper`.
inline nlohmann::json detumble_json(const ScenarioKeys& keys, const Model& model, int gripper,
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
  j["parameters"] = {{"joint_torque_limit", vector_json(d.limits.joint_torque)},
                     {"base_actuator", actuator_name(d.limits.actuator)},
                     {"stop_stack_spin", d.options.stop_stack_spin},
                     {"rest_rate", d.options.rest_rate},
                     {"tick", keys.detumble_tick},
                     {"horizon", keys.detumble_horizon}};
  j["status"] = status_name(e.status);
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
  j["final_joint_rate"] = e.joint_rate;
  j["final_relative_rate"] = e.relative_rate;
  j["final_stack_rate"] = e.stack_rate;
  j["ticks"] = r.ticks;
  return j;
}

/// As above, for the subject's keys.
inline nlohmann::json detumble_json(const Subject& s, const DetumbleJobResult& d,
                                    const std::string& version) {
  return detumble_json(s.keys, s.robot.model, s.robot.end_effector, d, version);
}

/// The results of detumble_runs as JSON: {"version", "runs": [each run's detumble_json]}.
inline nlohmann::json detumble_runs_json(const Subject& s, const std::vector<DetumbleJobResult>& d,
                                         const std::string& version) {
  nlohmann::json j{{"version", version}, {"runs", nlohmann::json::array()}};
  for (const DetumbleJobResult& x : d) {
    nlohmann::json r = detumble_json(s, x, version);
    r.erase("version");
    j["runs"].push_back(std::move(r));
  }
  return j;
}

/// The series as the CSV of `ffsr-optimize detumble --csv`: (with runs: the run's name first) time,
/// the rates, the gripper load, the base's rotation, the wheels' momentum, the energy, each joint's
/// rate and torque; then each joint's angle (rad), the base's pose, the target's (the gripper frame's
/// pose composed with the grasp's attachment) and every moving body's (its joint frame, numbered as the
/// main job's body<i> columns). Poses: x, y, z, qw, qx, qy, qz in the inertial frame.
inline std::string detumble_series_csv(const Subject& s, const std::vector<DetumbleJobResult>& results) {
  const Model& model = s.robot.model;
  const int gripper = s.robot.end_effector;
  Data data(model);
  std::ostringstream o;
  o << std::setprecision(12);
  const bool runs = !results.empty() && !results.front().run.empty();
  const int n = model.n();
  o << (runs ? "run," : "")
    << "t,joint_rate,relative_rate,stack_rate,gripper_force,gripper_moment,base_attitude,wheel_momentum,"
       "energy";
  for (int k = 0; k < n; ++k) o << ",theta_dot_" << k + 1;
  for (int k = 0; k < n; ++k) o << ",tau_" << k + 1;
  for (int k = 0; k < n; ++k) o << ",theta_" << k + 1;
  detail::pose_header(o, "base");
  detail::pose_header(o, "target");
  for (int b = 1; b < model.nb(); ++b) detail::pose_header(o, "body" + std::to_string(b));
  o << "\n";
  for (const DetumbleJobResult& d : results)
    for (const DetumbleSample& x : d.result.series) {
      if (runs) o << d.run << ',';
      o << x.t << ',' << x.joint_rate << ',' << x.relative_rate << ',' << x.stack_rate << ','
        << x.gripper_force.norm() << ',' << x.gripper_moment.norm() << ',' << x.base_attitude << ','
        << x.wheel_momentum.norm() << ',' << x.energy;
      for (int k = 0; k < n; ++k) o << ',' << x.theta_dot(k);
      for (int k = 0; k < n; ++k) o << ',' << x.tau(k);
      for (int k = 0; k < n; ++k) o << ',' << x.theta(k);
      detail::pose_csv(o, x.base.position, x.base.orientation.normalized());
      forward_kinematics(model, data, x.base, x.theta);
      const Pose target = frame_pose(model, data, gripper) * d.grasp.body.pose;
      detail::pose_csv(o, target.p, Quaternion(target.R).normalized());
      for (int b = 1; b < model.nb(); ++b) {
        const auto k = static_cast<size_t>(b);
        detail::pose_csv(o, data.p[k], Quaternion(data.R[k]));
      }
      o << "\n";
    }
  return o.str();
}

/// The subject of a scenario (its keys, robot as loaded, start state, target, contact law), without
/// loading the robot again: what the detumble job reads of it.
inline Subject subject_of_scenario(const Scenario& sc) {
  Subject s;
  s.keys = sc.keys;
  s.robot.model = *sc.model;
  s.robot.end_effector = sc.problem.frame;
  s.robot.base = sc.problem.base;
  s.robot.theta = sc.problem.theta;
  s.robot.report = sc.report;
  s.target = sc.problem.target;
  s.params = sc.problem.contact;
  s.law = sc.problem.law;
  s.approach_speed = sc.problem.approach_speed;
  return s;
}

inline std::vector<DetumbleJobResult> post_capture_runs(const Scenario& sc, const ScenarioResult& r) {
  std::vector<std::pair<std::string, const CaptureResult*>> runs;  // a failed row has no capture
  if (r.plain_ok()) runs.emplace_back("baseline", &r.plain);
  if (r.optimized_ok()) runs.emplace_back("optimized", &r.optimized);
  if (r.global) runs.emplace_back("global", &r.global->result.run);
  return detail::detumble_each_run(subject_of_scenario(sc), sc, runs);
}

inline nlohmann::json post_capture_json(const Scenario& sc, const DetumbleJobResult& d) {
  nlohmann::json j = detumble_json(sc.keys, *sc.model, sc.problem.frame, d, "");
  j.erase("version");
  j.erase("run");
  return j;
}

}  // namespace ffsr
