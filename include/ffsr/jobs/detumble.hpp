// ffsr/jobs/detumble.hpp -- the job `detumble`: the grasp at the end of the approach (or of the Hertz
// contact run) at a scenario's configuration (scenario/scenario.hpp, any scope: the robot at its start
// configuration, the target; or the capture of a run of the main job, jobs/scenario_run.hpp), the target
// attached at the gripper (the stack), then the post-capture run under the scenario's limits
// (the Detumble keys); that result as JSON (`ffsr-optimize detumble --json`, the JSON of one result in
// jobs/detail/detumble_result.hpp) and its series as CSV.
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
#include "ffsr/model/attach.hpp"
#if defined(FFSR_HAVE_PLAN)
#include "ffsr/control/detumble_planner.hpp"
#endif

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
inline DetumbleState detumble_start(const Scenario& s, const BasePose& base, const Eigen::VectorXd& theta,
                                    const Target& target, DetumbleJobResult& out) {
  using detail::str;
  const Model& model = *s.model;
  const int ee = s.problem.frame;
  const CaptureProblem& pb = s.problem;
  if (s.keys.grasp_after != "contact") {
    out.grasp = grasp_at_capture(model, ee, base, theta, target, pb.approach_speed);
    return {base, theta, out.grasp.v_after, Vector3::Zero()};
  }
  try {  // one law: 'all' or an unknown name is refused naming the key
    if (pb.law == "all") throw InputError("expected one contact law with grasp-after = contact, got 'all'");
    make_contact_law(pb.law, pb.contact, 1.0);
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, str("--model: ", e.what())));
  }
  ContactGraspResult c;
  try {
    c = grasp_after_contact(model, ee, base, theta, target, pb.approach_speed, pb.contact, pb.law);
  } catch (const InputError& e) {  // the bodies do not approach
    throw InputError(located_key_message(s.keys, str("--grasp-after: the contact run: ", e.what())));
  }
  out.grasp = c.grasp;
  out.contact = std::move(c.contact);
  out.contact_impulse = c.contact_impulse;
  return {out.contact->end.base, out.contact->end.theta, out.grasp.v_after, Vector3::Zero()};
}

namespace detail {

/// grasp-after = held: the target welded to the gripper frame where it is at the start (`target`'s pose
/// at the start configuration), moving with it, so the "grasp" takes no impulse: the result's grasp
/// holds the attachment, the robot's velocity `v` before and after, the target's twist as the gripper
/// carries it, the momentum and the kinetic energy of robot and target (equal before and after).
inline GraspResult held_grasp(const Model& model, int frame, const BasePose& base,
                              const Eigen::VectorXd& theta, const Eigen::VectorXd& v, const Target& target) {
  Data data(model);
  forward_kinematics(model, data, base, theta);
  frame_jacobian(model, data, frame);
  const Pose pf = frame_pose(model, data, frame);
  const Vector6 twist = data.J * v;  // the gripper frame's [v; w] at its origin, inertial
  const Matrix3 Rt = target.rotation();
  GraspResult g;
  g.contact_point = pf.p;
  g.v_before = g.v_after = v;
  g.target_before.head<3>() = twist.head<3>() + twist.tail<3>().cross(target.position - pf.p);
  g.target_before.tail<3>() = twist.tail<3>();
  g.target_after = g.target_before;
  g.momentum_before = g.momentum_after =
      robot_momentum_about_origin(model, data, v) + target_momentum(target, g.target_before);
  const Vector3 w = g.target_before.tail<3>();
  g.energy_before = g.energy_after = kinetic_energy(model, data, v) +
                                     0.5 * target.mass * g.target_before.head<3>().squaredNorm() +
                                     0.5 * w.dot(Rt * target.inertia * Rt.transpose() * w);
  g.body.mass = target.mass;
  g.body.inertia = target.inertia;
  g.body.pose = Pose{pf.R.transpose() * (target.position - pf.p), pf.R.transpose() * Rt};
  return g;
}

/// grasp-after = held: the stack's start state at (base, theta) with the start keys' rates
/// (held_start_state) and the target welded where it is (held_grasp, into out.grasp; out.held).
/// InputError naming the key, located in the file.
inline DetumbleState held_start(const Scenario& s, const BasePose& base, const Eigen::VectorXd& theta,
                                const Target& target, DetumbleJobResult& out) {
  DetumbleState start;
  try {
    start = held_start_state(s.keys, *s.model, base, theta);
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, e.what()));
  }
  out.held = true;
  out.grasp = held_grasp(*s.model, s.problem.frame, base, theta, start.v, target);
  return start;
}

/// detumble's body: the grasp of grasp-after at (base, theta) with `target` (held: the target welded
/// there, the start keys' rates), the stack, the run.
inline DetumbleJobResult detumble_from(const Scenario& s, const BasePose& base, const Eigen::VectorXd& theta,
                                       const Target& target) {
  using detail::str;
  DetumbleJobResult out;
  out.theta = theta;
  const Model& model = *s.model;
  try {  // an error of a key the file gave names the file and the key's line
    out.settings = detumble_settings(s.keys, model);
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, e.what()));
  }
  const int ee = s.problem.frame;
  DetumbleState start;
  try {  // a degenerate pair of bodies (a target inertia near zero): name the keys that set it
    start = holds_target(s.keys) ? held_start(s, base, theta, target, out)
                                 : detumble_start(s, base, theta, target, out);
  } catch (const NumericalError& e) {
    throw NumericalError(str(e.what(), " (--target-mass, --target-inertia: the target it grasps)"));
  }
  out.start = start;
  const Model stack = attach_body(model, model.frame(ee).name, out.grasp.body);
  const DetumbleSettings& settings = out.settings;
  try {  // an actuator that cannot stop the stack's spin: the key of the bound that is too small
    out.result = run_detumble(stack, ee, out.grasp.body, start, settings);
  } catch (const DetumbleInfeasibleError& e) {
    const bool wheels = settings.limits.actuator == BaseActuator::ReactionWheels;
    const char* key = e.bound == DetumbleBound::Actuator        ? "stop-stack-spin"
                      : e.bound == DetumbleBound::Tick          ? "detumble-tick"
                      : e.bound == DetumbleBound::WheelMomentum ? "wheel-momentum"
                      : wheels                                  ? "wheel-torque"
                                                                : "thruster-torque";
    throw InputError(located_key_message(s.keys, str("--", key, ": ", e.what())));
  }
  if (!out.result.at_rest) {
    const DetumbleSample& e = out.result.series.back();
    constexpr double deg = 180 / M_PI;
    const bool spin = settings.options.stop_stack_spin;
    throw InputError(located_key_message(
        s.keys, str("--detumble-horizon: the stack is not at rest after ", settings.run.horizon,
                    " s under these limits (largest joint rate ", e.command.joint_rate * deg,
                    " deg/s, gripper rate relative to the base ", e.command.relative_rate * deg, " deg/s",
                    spin ? str(", stack rate ", e.command.stack_rate * deg, " deg/s") : std::string(),
                    "; at rest below ", s.keys.rest_rate_deg, " deg/s): raise the ",
                    spin ? "limits, the wheels' momentum" : "joint torque limits", " or the horizon")));
  }
  out.peak_joint_name = out.result.peak_joint >= 0 ? model.joint(out.result.peak_joint).name : "";
  return out;
}

}  // namespace detail

/// The job: the grasp of detumble_start at (base, theta) (grasp_at_capture: the contact point moving at
/// the approach speed along the target's normal; or after the Hertz contact run), the stack,
/// run_detumble under the scenario's detumble_settings. InputError for bad keys, an actuator too small
/// for the horizon (run_detumble's check_detumble_feasible), or a stack not at rest at the horizon;
/// InputError naming grasp-after when the scenario's stack holds its target (held: detumble(s) starts it).
inline DetumbleJobResult detumble(const Scenario& s, const BasePose& base, const Eigen::VectorXd& theta,
                                  const Target& target) {
  detail::refuse_held(s, "a run from a capture configuration");
  return detail::detumble_from(s, base, theta, target);
}

/// At the scenario's start configuration (its start state, the target at t = 0): the grasp of
/// grasp-after there, or (held) the stack as it holds its target, from the start keys' rates.
inline DetumbleJobResult detumble(const Scenario& s) {
  return detail::detumble_from(s, s.problem.base, s.problem.theta, s.problem.target);
}

namespace detail {

/// The post-capture run from the capture of each of `runs` (the main job's run's name, its result) of
/// the scenario `sc` (scope Run): each run's configuration and base pose at T, the target at T.
/// InputError naming the run it started from.
inline std::vector<DetumbleJobResult> detumble_each_run(
    const Scenario& sc, const std::vector<std::pair<std::string, const CaptureResult*>>& runs) {
  const Target target = prepare_capture(sc.problem, sc.task, sc.capture).capture.target;
  std::vector<DetumbleJobResult> out;
  for (const auto& [name, run] : runs) {
    try {
      out.push_back(detumble(sc, run->base, run->theta, target));
    } catch (const InputError& e) {  // which start it was
      throw InputError(str(e.what(), " (from the ", name, " run's capture)"));
    }
    out.back().run = name;
  }
  return out;
}

}  // namespace detail

/// From the capture of the main job's runs (jobs/scenario_run.hpp) of the scenario `sc` (scope Run:
/// resolve_run completes a Configuration): `which` is plain, optimized, global or all (every run the
/// scenario has); each run's capture configuration and base pose at T, the target at T. InputError
/// naming --run, or grasp-after when the scenario's stack holds its target.
inline std::vector<DetumbleJobResult> detumble_runs(const Scenario& sc, const std::string& which) {
  using detail::str;
  detail::refuse_held(sc, "--run");
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
  return detail::detumble_each_run(sc, runs);
}

/// Whether this build has the time-optimal planner (IPOPT found when ffsr was built: FFSR_HAVE_PLAN).
inline constexpr bool kHaveDetumblePlan =
#if defined(FFSR_HAVE_PLAN)
    true;
#else
    false;
#endif

/// InputError naming --plan when this build has no time-optimal planner.
inline void require_detumble_planner() {
  if (!kHaveDetumblePlan)
    throw InputError(
        "--plan: this build of ffsr has no time-optimal planner (IPOPT was not found when it was built: "
        "install Debian's coinor-libipopt-dev and build again)");
}

/// `detumble --plan`: for each result, the time-optimal plan from its start under its settings
/// (plan_detumble: the horizon bounds T) and the plan's re-run (replay_detumble_plan, with the run's
/// tick and dwell). InputError naming --plan when this build has no planner; the planner's errors
/// (DetumblePlanError: IPOPT's status and the residual it reached) as they come.
inline void detumble_plans(const Scenario& s, std::vector<DetumbleJobResult>& results) {
#if defined(FFSR_HAVE_PLAN)
  const Model& model = *s.model;
  const int ee = s.problem.frame;
  for (DetumbleJobResult& d : results) {
    const Model stack = attach_body(model, model.frame(ee).name, d.grasp.body);
    const DetumbleSettings& st = d.settings;
    DetumblePlanJob job;
    DetumblePlanOptions po;
    po.tick = st.run.tick;  // a plan the onboard tracker can follow at the run's tick
    try {
      job.plan = plan_detumble(stack, ee, d.grasp.body, d.start, st.limits, st.options, st.run.horizon, po);
    } catch (const DetumblePlanError& e) {
      throw DetumblePlanError(detail::str("--plan: ", e.what(), d.run.empty() ? "" : " (from the " + d.run + " run's capture)"),
                              e.status, e.best_residual);
    }
    job.run = replay_detumble_plan(stack, ee, d.grasp.body, job.plan, st.limits, st.options, st.run);
    d.plan = std::move(job);
  }
#else
  (void)s;
  (void)results;
  require_detumble_planner();
#endif
}

namespace detail {

/// The results as the CSV and the figure show them: each run, then its plan's re-run (named "plan", or
/// "<run>-plan"), the run named "law" when it has a plan and no name.
inline std::vector<DetumbleJobResult> with_plan_runs(const std::vector<DetumbleJobResult>& results) {
  std::vector<DetumbleJobResult> out;
  for (const DetumbleJobResult& d : results) {
    out.push_back(d);
    if (!d.plan) continue;
    if (out.back().run.empty()) out.back().run = "law";
    DetumbleJobResult p = d;
    p.run = d.run.empty() ? "plan" : d.run + "-plan";
    p.result = d.plan->run;
    p.plan.reset();
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace detail

/// detumble_json (jobs/detail/detumble_result.hpp) for the scenario's robot.
inline nlohmann::json detumble_json(const Scenario& s, const DetumbleJobResult& d,
                                    const std::string& version) {
  return detumble_json(*s.model, s.problem.frame, d, version);
}

/// The results of detumble_runs as JSON: {"version", "runs": [each run's detumble_json]}.
inline nlohmann::json detumble_runs_json(const Scenario& s, const std::vector<DetumbleJobResult>& d,
                                         const std::string& version) {
  nlohmann::json j{{"version", version}, {"runs", nlohmann::json::array()}};
  for (const DetumbleJobResult& x : d) {
    nlohmann::json r = detumble_json(s, x, version);
    r.erase("version");
    j["runs"].push_back(std::move(r));
  }
  return j;
}

/// The series as the CSV of `ffsr-optimize detumble --csv`: (with runs or a plan: the run's name first,
/// a plan's re-run as its own run, detail::with_plan_runs) time,
/// the rates, the gripper load (norms), the base's rotation, the wheels' momentum (norm), the energy,
/// the law's decay rate and whether it was the passive one, the base wrench (force and moment about the
/// base origin, inertial), the wheels' momentum per base axis, each joint's rate and torque; then each joint's angle (rad), the base's pose, the target's (the gripper frame's
/// pose composed with the grasp's attachment) and every moving body's (its joint frame, numbered as the
/// main job's body<i> columns). Poses: x, y, z, qw, qx, qy, qz in the inertial frame.
inline std::string detumble_series_csv(const Scenario& s, const std::vector<DetumbleJobResult>& all) {
  const std::vector<DetumbleJobResult> results = detail::with_plan_runs(all);
  const Model& model = *s.model;
  const int gripper = s.problem.frame;
  Data data(model);
  std::ostringstream o;
  o << std::setprecision(12);
  const bool runs = !results.empty() && !results.front().run.empty();
  const int n = model.n();
  o << (runs ? "run," : "")
    << "t,joint_rate,relative_rate,stack_rate,gripper_force,gripper_moment,base_attitude,wheel_momentum,"
       "energy,decay,passive,base_force_x,base_force_y,base_force_z,base_moment_x,base_moment_y,base_moment_z,"
       "wheel_momentum_x,wheel_momentum_y,wheel_momentum_z";
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
      const DetumbleCommand& c = x.command;
      o << x.t << ',' << c.joint_rate << ',' << c.relative_rate << ',' << c.stack_rate << ','
        << x.gripper_force.norm() << ',' << x.gripper_moment.norm() << ',' << x.base_attitude << ','
        << x.wheel_momentum.norm() << ',' << x.energy << ',' << c.decay << ',' << (c.passive ? 1 : 0);
      for (int k = 0; k < 6; ++k) o << ',' << c.base_wrench(k);
      for (int k = 0; k < 3; ++k) o << ',' << x.wheel_momentum(k);
      for (int k = 0; k < n; ++k) o << ',' << x.theta_dot(k);
      for (int k = 0; k < n; ++k) o << ',' << c.tau(k);
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

}  // namespace ffsr
