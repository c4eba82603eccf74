// ffsr/jobs/detumble.hpp -- the job `detumble`: the grasp at the end of the approach of a subject
// (jobs/subject.hpp: the robot at its configuration, the target, the approach speed), the target
// attached at the gripper (the stack), then the post-capture run under the scenario's limits
// (the Detumble keys); that result as JSON (`ffsr-optimize detumble --json`) and its series as CSV.
// Component ffsr::scenario (and SUNDIALS: ffsr::cvode). Never prints.
#pragma once

#include "ffsr/algorithm/joint_models.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/jobs/subject.hpp"
#include "ffsr/model/attach.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace ffsr {

/// The job's result: the grasp, the run's summary and series, the limits it ran under.
struct DetumbleJobResult {
  std::string
      run;  ///< the main job's run it starts from (baseline, optimized, global); empty: a configuration
  Eigen::VectorXd theta;  ///< the capture configuration, rad
  GraspResult grasp;
  DetumbleRunResult result;
  DetumbleLimits limits;
  DetumbleOptions options;
  std::string peak_joint_name;  ///< the joint of the peak torque
};

/// The limits and the law's settings of a scenario's Detumble keys for `model`: joint-torque-limit
/// (one value or one per joint; when not given, the URDF's <limit effort> of every joint), the base
/// actuator and its bounds (each needed by its actuator, refused without it, from a file too),
/// rest-rate-deg, stop-stack-spin. InputError naming the key.
inline void detumble_settings(const ScenarioKeys& k, const Model& model, DetumbleLimits& l,
                              DetumbleOptions& o) {
  using detail::str;
  for (const ScenarioKey& key : scenario_keys()) {  // the Detumble keys' own checks, and where they act
    if (key.group != KeyGroup::Detumble) continue;
    if (key.check) key.check(k);
    const std::string why = key.acts && k.given.count(key.name) ? key.acts(k) : "";
    if (!why.empty()) throw InputError(str("--", key.name, ": ", why));
  }
  if (k.joint_torque_limit.empty()) {
    l.joint_torque.resize(model.n());
    for (int j = 0; j < model.n(); ++j) {
      l.joint_torque(j) = model.joint(j).effort;
      if (!(l.joint_torque(j) > 0))
        throw InputError(
            str("--joint-torque-limit: not given, and the URDF gives no <limit effort> for joint '",
                model.joint(j).name, "'"));
    }
  } else {
    l.joint_torque = per_joint_values(k.joint_torque_limit, model, "--joint-torque-limit");
  }
  const auto needed = [&k](const char* name, double value) {
    if (!k.given.count(name))
      throw InputError(str("--", name, ": needed with base-actuator = ", k.base_actuator));
    return value;
  };
  if (k.base_actuator == "reaction-wheels") {
    l.actuator = BaseActuator::ReactionWheels;
    l.wheel_torque = needed("wheel-torque", k.wheel_torque);
    l.wheel_momentum = needed("wheel-momentum", k.wheel_momentum);
  } else if (k.base_actuator == "thrusters") {
    l.actuator = BaseActuator::Thrusters;
    l.thruster_force = needed("thruster-force", k.thruster_force);
    l.thruster_torque = needed("thruster-torque", k.thruster_torque);
  }
  o.rest_rate = k.rest_rate_deg * M_PI / 180.0;
  o.stop_stack_spin = k.stop_stack_spin;
}

/// The job: grasp_at_capture at the subject's configuration (the contact point moving at the approach
/// speed along the target's normal), the stack, run_detumble. InputError for bad keys, an actuator too
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
  try {  // a degenerate pair of bodies (a target inertia near zero): name the keys that set it
    out.grasp = grasp_at_capture(r.model, ee, base, theta, target, s.approach_speed);
  } catch (const NumericalError& e) {
    throw NumericalError(str(e.what(), " (--target-mass, --target-inertia: the target it grasps)"));
  }
  const Model stack = attach_body(r.model, r.model.frame(ee).name, out.grasp.body);
  const DetumbleState start{base, theta, out.grasp.v_after, Vector3::Zero()};
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
    throw InputError(str("--detumble-horizon: the stack is not at rest after ", run.horizon,
                         " s under these limits (largest joint rate ", e.joint_rate * deg,
                         " deg/s, gripper rate relative to the base ", e.relative_rate * deg, " deg/s",
                         spin ? str(", stack rate ", e.stack_rate * deg, " deg/s") : std::string(),
                         "; at rest below ", s.keys.rest_rate_deg, " deg/s): raise the ",
                         spin ? "limits, the wheels' momentum" : "joint torque limits", " or the horizon"));
  }
  out.peak_joint_name = out.result.peak_joint >= 0 ? r.model.joint(out.result.peak_joint).name : "";
  return out;
}

/// At the subject's configuration (its start state, the target at t = 0).
inline DetumbleJobResult detumble(const Subject& s) {
  return detumble(s, s.robot.base, s.robot.theta, s.target);
}

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
  const Target target = prepare_capture(sc.problem, sc.task, sc.capture).capture_target;
  std::vector<std::pair<std::string, CaptureResult>> runs;
  if (which == "plain" || which == "optimized") {
    auto [plain, optimized] = plan_plain_and_optimized(sc);
    runs.emplace_back(which == "plain" ? "baseline" : "optimized", which == "plain" ? plain : optimized);
  } else {
    const ScenarioResult r = run_scenario(sc);
    if (which == "all") {
      runs.emplace_back("baseline", r.plain);
      runs.emplace_back("optimized", r.optimized);
    }
    if (r.global) runs.emplace_back("global", r.global->result.run);
  }
  std::vector<DetumbleJobResult> out;
  for (const auto& [name, run] : runs) {
    try {
      out.push_back(detumble(s, run.base, run.theta, target));
    } catch (const InputError& e) {  // which start it was
      throw InputError(str(e.what(), " (from the ", name, " run's capture)"));
    }
    out.back().run = name;
  }
  return out;
}

/// The result as JSON: the keys and values of `ffsr-optimize detumble --json` (`version` as given).
inline nlohmann::json detumble_json(const Subject& s, const DetumbleJobResult& d,
                                    const std::string& version) {
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
                {"energy_after", g.energy_after}};
  // the settings as resolved (inputs, not results)
  j["parameters"] = {{"joint_torque_limit", vector_json(d.limits.joint_torque)},
                     {"base_actuator", actuator_name(d.limits.actuator)},
                     {"stop_stack_spin", d.options.stop_stack_spin},
                     {"rest_rate", d.options.rest_rate},
                     {"tick", s.keys.detumble_tick},
                     {"horizon", s.keys.detumble_horizon}};
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
/// the rates, the gripper load, the base's rotation, the wheels' momentum, the energy, then each
/// joint's rate and torque.
inline std::string detumble_series_csv(const std::vector<DetumbleJobResult>& results) {
  std::ostringstream o;
  o << std::setprecision(10);
  const bool runs = !results.empty() && !results.front().run.empty();
  const int n = results.empty() ? 0 : int(results.front().limits.joint_torque.size());
  o << (runs ? "run," : "")
    << "t,joint_rate,relative_rate,stack_rate,gripper_force,gripper_moment,base_attitude,wheel_momentum,"
       "energy";
  for (int k = 0; k < n; ++k) o << ",theta_dot_" << k + 1;
  for (int k = 0; k < n; ++k) o << ",tau_" << k + 1;
  o << "\n";
  for (const DetumbleJobResult& d : results)
    for (const DetumbleSample& x : d.result.series) {
      if (runs) o << d.run << ',';
      o << x.t << ',' << x.joint_rate << ',' << x.relative_rate << ',' << x.stack_rate << ','
        << x.gripper_force.norm() << ',' << x.gripper_moment.norm() << ',' << x.base_attitude << ','
        << x.wheel_momentum.norm() << ',' << x.energy;
      for (int k = 0; k < n; ++k) o << ',' << x.theta_dot(k);
      for (int k = 0; k < n; ++k) o << ',' << x.tau(k);
      o << "\n";
    }
  return o.str();
}

}  // namespace ffsr
