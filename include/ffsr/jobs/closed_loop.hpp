// ffsr/jobs/closed_loop.hpp -- the job `closed-loop`: the capture controller in a closed loop with the
// robot's full dynamics and a noisy target estimate (ffsr/control/closed_loop.hpp), beside the open-loop
// plan it follows: the paper's method (plan "paper"), the global run's servo (plan "global") or the servo
// to a given capture configuration (goal_joints_deg); the result as JSON (`ffsr-optimize closed-loop
// --json`) and its series as CSV (`--csv`). Component ffsr::scenario. Never prints.
#pragma once

#include "ffsr/control/capture_controller.hpp"
#include "ffsr/control/closed_loop.hpp"
#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/jobs/scenario_run.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace ffsr {

/// What the job takes beside the scenario (the command's flags, in its units).
struct ClosedLoopJobOptions {
  std::string plan = "paper";            ///< paper or global
  std::vector<double> goal_joints_deg;   ///< servo to this capture configuration instead (deg; empty: none)
  ClosedLoopOptions loop;                ///< loop.noise.attitude and angular_velocity are set from the two below
  double attitude_noise_deg = 0;         ///< estimate noise on the attitude, deg (1 sigma per axis)
  double spin_noise_deg = 0;             ///< estimate noise on the spin, deg/s (1 sigma per axis)
  ControllerOptions controller;
  bool record_plan_series = false;  ///< keep the open-loop plan's series (CaptureResult::series)
};

/// The open-loop plan and the controller that follows it.
struct ClosedLoopPlan {
  std::string name;  ///< paper, global, or "servo to --goal-joints-deg"
  CaptureResult open;
  CaptureOptions options;
  Eigen::VectorXd goal;  ///< servo goal (empty: the paper's gradient policy)
};

struct ClosedLoopJobResult {
  ClosedLoopPlan plan;
  ClosedLoopOptions loop;  ///< as run (the noise in rad)
  ControllerOptions controller;
  ClosedLoopResult result;
};

/// The options' own checks, each error naming the command's flag (--control-rate, ...). InputError.
void check_closed_loop_job(const ClosedLoopJobOptions& o);

/// The job: checks the options, plans (plan or goal), then runs the controller in the closed loop.
/// InputError naming the flag; NumericalError from the planner or the loop.
ClosedLoopJobResult closed_loop(const Scenario& sc, const ClosedLoopJobOptions& o);

/// The result as JSON: the keys and values of `ffsr-optimize closed-loop --json` (`version` as given).
nlohmann::json closed_loop_json(const Scenario& sc, const ClosedLoopJobResult& r, const std::string& version);

/// The recorded samples (ClosedLoopOptions::record_every) as the CSV of `closed-loop --csv`: one row per
/// sample and joint.
std::string closed_loop_series_csv(const ClosedLoopResult& r);

inline void check_closed_loop_job(const ClosedLoopJobOptions& o) {
  auto check = [](double x, bool zero_ok, const char* flag) {
    if (!std::isfinite(x) || x < 0 || (!zero_ok && x == 0))
      throw InputError(detail::str(flag, ": must be ", zero_ok ? ">= 0" : "positive", " and finite, got ", x));
  };
  check(o.loop.control_rate, false, "--control-rate");
  check(o.loop.estimate_rate, false, "--estimate-rate");
  check(o.loop.noise.position, true, "--position-noise");
  check(o.attitude_noise_deg, true, "--attitude-noise-deg");
  check(o.loop.noise.velocity, true, "--velocity-noise");
  check(o.spin_noise_deg, true, "--spin-noise-deg");
  check(o.loop.loop.bandwidth, false, "--rate-loop-bandwidth");
  check(o.loop.loop.torque_limit, false, "--torque-limit");
  ClosedLoopOptions loop = o.loop;
  loop.noise.attitude = o.attitude_noise_deg * M_PI / 180.0;
  loop.noise.angular_velocity = o.spin_noise_deg * M_PI / 180.0;
  detail::check_closed_loop_options(loop);
}

namespace detail {

inline ClosedLoopPlan make_closed_loop_plan(const Scenario& sc, const ClosedLoopJobOptions& o) {
  ClosedLoopPlan p;
  p.options = sc.capture;
  p.options.progress = nullptr;
  p.options.record_series = o.record_plan_series;  // the plan's joint angles beside the closed loop's
  p.options.record_every = std::max(1, static_cast<int>(sc.capture.duration / sc.capture.step / 1000));
  if (!o.goal_joints_deg.empty()) {
    if (static_cast<int>(o.goal_joints_deg.size()) != sc.model->n())
      throw InputError(str("--goal-joints-deg: got ", o.goal_joints_deg.size(), " angles, the robot has ",
                           sc.model->n(), " joints"));
    p.goal = Eigen::Map<const Eigen::VectorXd>(o.goal_joints_deg.data(), sc.model->n()) * (M_PI / 180);
    p.name = "servo to --goal-joints-deg";
  } else if (o.plan == "global") {
    const CaptureResult paper = plan_capture(sc.problem, sc.task, p.options);
    p.goal = run_global(sc, paper, sc.objective).result.run.theta;
    p.name = "global";
  } else if (o.plan == "paper") {
    p.name = "paper";
    p.open = plan_capture(sc.problem, sc.task, p.options);
    return p;
  } else {
    throw InputError(str("--plan: expected paper or global, got '", o.plan, "'"));
  }
  p.options.gain = 0.0;
  p.options.max_joint_rate = sc.keys.max_joint_rate_deg * M_PI / 180.0;
  const CaptureSetup setup = prepare_capture(sc.problem, sc.task, p.options);
  ServoPolicy servo;
  servo.theta_goal = p.goal;
  p.open = integrate_capture(sc.problem, sc.task, p.options, setup, servo);
  return p;
}

}  // namespace detail

inline ClosedLoopJobResult closed_loop(const Scenario& sc, const ClosedLoopJobOptions& o) {
  check_closed_loop_job(o);
  if (o.controller.prediction_window < 1 || o.controller.prediction_window > 100000)
    throw InputError(
        detail::str("--prediction-window: must be in 1..100000, got ", o.controller.prediction_window));
  ClosedLoopJobResult r;
  r.loop = o.loop;
  r.loop.noise.attitude = o.attitude_noise_deg * M_PI / 180.0;
  r.loop.noise.angular_velocity = o.spin_noise_deg * M_PI / 180.0;
  r.controller = o.controller;
  r.plan = detail::make_closed_loop_plan(sc, o);
  const ClosedLoopPlan& p = r.plan;
  if (p.goal.size() == 0) {
    auto ctrl = make_gradient_controller(sc.problem, sc.task, p.options, r.controller);
    r.result = simulate_closed_loop(ctrl, r.loop);
  } else {
    auto ctrl = make_servo_controller(sc.problem, sc.task, p.options, p.goal, 0.0, r.controller);
    r.result = simulate_closed_loop(ctrl, r.loop);
  }
  return r;
}

inline nlohmann::json closed_loop_json(const Scenario& sc, const ClosedLoopJobResult& job,
                                       const std::string& version) {
  using detail::vector_json;
  const ClosedLoopPlan& p = job.plan;
  const ClosedLoopOptions& o = job.loop;
  const ClosedLoopResult& r = job.result;
  nlohmann::json j;
  j["version"] = version;
  j["scenario"] = sc.where;
  j["plan"] = p.name;
  j["options"] = {{"control_rate_hz", o.control_rate},
                  {"estimate_rate_hz", o.estimate_rate},
                  {"rate_loop_bandwidth", o.loop.bandwidth},
                  {"torque_limit", o.loop.torque_limit},
                  {"noise",
                   {{"position", o.noise.position},
                    {"attitude_deg", o.noise.attitude * 180.0 / M_PI},
                    {"velocity", o.noise.velocity},
                    {"spin_deg_per_s", o.noise.angular_velocity * 180.0 / M_PI}}},
                  {"noise_seed", o.seed}};
  j["options"]["prediction_window"] = job.controller.prediction_window;
  auto quaternion = [](const BasePose& b) {  // w, x, y, z, as the main job writes it
    const Eigen::Vector4d q = b.orientation.coeffs();
    return nlohmann::json{q(3), q(0), q(1), q(2)};
  };
  j["open_loop"] = {{"capture_configuration_deg", vector_json(Eigen::VectorXd(p.open.theta * 180 / M_PI))},
                    {"base_position", vector_json(Eigen::VectorXd(p.open.base.position))},
                    {"base_quaternion_wxyz", quaternion(p.open.base)},
                    {"capture_error", p.open.capture_distance},
                    {"integrated_effective_mass", p.open.M_ie},
                    {"f_max_closed_form", p.open.f_max_closed_form}};
  j["closed_loop"] = {{"capture_configuration_deg", vector_json(Eigen::VectorXd(r.theta * 180 / M_PI))},
                      {"base_position", vector_json(Eigen::VectorXd(r.base.position))},
                      {"base_quaternion_wxyz", quaternion(r.base)},
                      {"capture_error", r.capture_error},
                      {"integrated_effective_mass", r.M_ie},
                      {"f_max_closed_form", r.f_max_closed_form},
                      {"max_torque", r.max_torque},
                      {"max_tracking_lag", r.max_tracking_lag},
                      {"max_reference_error", r.max_reference_error},
                      {"base_attitude_change_deg", r.base_attitude_change * 180.0 / M_PI},
                      {"base_position_change", r.base_position_change},
                      {"max_momentum", r.max_momentum},
                      {"ticks", r.ticks},
                      {"estimates", r.estimates},
                      {"damped_ticks", r.damped_ticks},
                      {"rate_limited_ticks", r.rate_limited_ticks},
                      {"saturated_ticks", r.saturated_ticks},
                      {"integrator_steps", r.integrator_steps}};
  j["mass_difference_percent"] = 100 * (r.M_ie - p.open.M_ie) / p.open.M_ie;
  return j;
}

inline std::string closed_loop_series_csv(const ClosedLoopResult& r) {
  std::ostringstream s;
  s << std::setprecision(10)
    << "t,joint,theta,theta_dot,command,torque,ee_x,ee_y,ee_z,ref_x,ref_y,ref_z,momentum\n";
  for (const ClosedLoopSample& x : r.series)
    for (Eigen::Index k = 0; k < x.theta.size(); ++k)
      s << x.t << ',' << k + 1 << ',' << x.theta(k) << ',' << x.theta_dot(k) << ',' << x.command(k) << ','
        << x.torque(k) << ',' << x.end_effector.x() << ',' << x.end_effector.y() << ',' << x.end_effector.z()
        << ',' << x.reference.x() << ',' << x.reference.y() << ',' << x.reference.z() << ',' << x.momentum
        << '\n';
  return s.str();
}

}  // namespace ffsr
