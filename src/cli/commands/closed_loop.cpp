// ffsr-optimize closed-loop [--config SCENARIO.toml] [flags]: the capture controller
// (ffsr/control/capture_controller.hpp) in a closed loop with the robot's full dynamics and a noisy
// target estimate (ffsr/control/closed_loop.hpp), beside the open-loop plan it follows. The plan is
// the paper's method (--plan paper), the global run's servo (--plan global: the global search of the
// main job first) or the servo to a given capture configuration (--goal-joints-deg). A flag overrides
// the scenario file's key.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "figures/plot.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/scenario_run.hpp"

#include "ffsr/control/capture_controller.hpp"
#include "ffsr/control/closed_loop.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace ffsr::cli {
namespace {

using detail::str;

struct ClosedLoopCliOptions : OutputKeys {
  std::string config, plan = "paper";
  ScenarioFlags flags;
  std::vector<double> goal_joints_deg;
  ClosedLoopOptions loop;
  double attitude_noise_deg = 0, spin_noise_deg = 0;
  std::string noise_seed = "1";
  ControllerOptions controller;
};

const std::set<std::string> kClosedLoopKeys = {"json", "csv", "plot", "plot-format", "quiet"};

/// The open-loop plan and the controller that follows it.
struct Plan {
  std::string name;
  CaptureResult open;
  CaptureOptions options;
  Eigen::VectorXd goal;  ///< servo goal (empty: the paper's gradient policy)
};

Plan make_plan(const Scenario& sc, const ClosedLoopCliOptions& o) {
  Plan p;
  p.options = sc.capture;
  p.options.progress = nullptr;
  p.options.record_series = !o.plot.empty();  // the plan's joint angles beside the closed loop's
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

ClosedLoopResult simulate(const Scenario& sc, const Plan& p, const ClosedLoopOptions& o,
                          const ControllerOptions& copt) {
  if (p.goal.size() == 0) {
    auto ctrl = make_gradient_controller(sc.problem, sc.task, p.options, copt);
    return simulate_closed_loop(ctrl, o);
  }
  auto ctrl = make_servo_controller(sc.problem, sc.task, p.options, p.goal, 0.0, copt);
  return simulate_closed_loop(ctrl, o);
}

nlohmann::json result_json(const Scenario& sc, const Plan& p, const ClosedLoopOptions& o,
                           const ControllerOptions& copt, const ClosedLoopResult& r) {
  nlohmann::json j;
  j["version"] = FFSR_VERSION;
  j["scenario"] = sc.where;
  j["plan"] = p.name;
  j["options"] = {{"control_rate_hz", o.control_rate},
                  {"estimate_rate_hz", o.estimate_rate},
                  {"rate_loop_bandwidth", o.loop.bandwidth},
                  {"torque_limit", o.loop.torque_limit},
                  {"noise",
                   {{"position", o.noise.position},
                    {"attitude_deg", rad2deg(o.noise.attitude)},
                    {"velocity", o.noise.velocity},
                    {"spin_deg_per_s", rad2deg(o.noise.angular_velocity)}}},
                  {"noise_seed", o.seed}};
  j["options"]["prediction_window"] = copt.prediction_window;
  auto quaternion = [](const BasePose& b) {  // w, x, y, z, as the main job writes it
    const Eigen::Vector4d q = b.orientation.coeffs();
    return nlohmann::json{q(3), q(0), q(1), q(2)};
  };
  j["open_loop"] = {{"capture_configuration_deg", to_json(Eigen::VectorXd(p.open.theta * 180 / M_PI))},
                    {"base_position", to_json(Eigen::VectorXd(p.open.base.position))},
                    {"base_quaternion_wxyz", quaternion(p.open.base)},
                    {"capture_error", p.open.capture_distance},
                    {"integrated_effective_mass", p.open.M_ie},
                    {"f_max_closed_form", p.open.f_max_closed_form}};
  j["closed_loop"] = {{"capture_configuration_deg", to_json(Eigen::VectorXd(r.theta * 180 / M_PI))},
                      {"base_position", to_json(Eigen::VectorXd(r.base.position))},
                      {"base_quaternion_wxyz", quaternion(r.base)},
                      {"capture_error", r.capture_error},
                      {"integrated_effective_mass", r.M_ie},
                      {"f_max_closed_form", r.f_max_closed_form},
                      {"max_torque", r.max_torque},
                      {"max_tracking_lag", r.max_tracking_lag},
                      {"max_reference_error", r.max_reference_error},
                      {"base_attitude_change_deg", rad2deg(r.base_attitude_change)},
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

std::string series_csv(const ClosedLoopResult& r) {
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

void print_table(std::ostream& out, const Scenario& sc, const Plan& p, const ClosedLoopOptions& o,
                 const ClosedLoopResult& r) {
  out << "ffsr-optimize closed-loop: " << sc.where << ", plan " << p.name << ", control " << o.control_rate
      << " Hz, estimates " << o.estimate_rate << " Hz, rate loops " << o.loop.bandwidth
      << " rad/s, |tau| <= " << o.loop.torque_limit << " N m\n\n";
  out << std::left << std::setw(18) << "" << std::setw(20) << "capture error (m)" << std::setw(14)
      << "M_ie (kg)"
      << "F_max (kN)\n"
      << std::setprecision(4);
  out << std::setw(18) << "open-loop plan" << std::setw(20) << p.open.capture_distance << std::setw(14)
      << p.open.M_ie << p.open.f_max_closed_form / 1e3 << "\n";
  out << std::setw(18) << "closed loop" << std::setw(20) << r.capture_error << std::setw(14) << r.M_ie
      << r.f_max_closed_form / 1e3 << "\n";
  out << std::setw(18) << "difference" << std::setw(20) << "" << std::setw(14)
      << str(std::setprecision(3), 100 * (r.M_ie - p.open.M_ie) / p.open.M_ie, " %")
      << str(std::setprecision(3),
             100 * (r.f_max_closed_form - p.open.f_max_closed_form) / p.open.f_max_closed_form, " %")
      << "\n\n";
  out << "largest torque " << r.max_torque << " N m, largest tracking lag " << r.max_tracking_lag
      << " rad/s, largest |p_e - x_d| " << r.max_reference_error << " m\n";
  out << "base attitude change " << rad2deg(r.base_attitude_change) << " deg, largest |momentum| "
      << r.max_momentum << "\n";
  out << r.ticks << " ticks (" << r.damped_ticks << " damped, " << r.rate_limited_ticks << " rate-limited, "
      << r.saturated_ticks << " with a torque at its limit), " << r.estimates << " estimates\n";
}

/// The picture: the recorded series of the closed loop beside the open-loop plan's.
plot::Figure closed_loop_figure(const Scenario& sc, const Plan& p, const ClosedLoopOptions& o,
                                const ClosedLoopResult& r) {
  figures::ClosedLoopSeries f;
  f.joint_names = sc.model->joint_names();
  for (const ClosedLoopSample& x : r.series) {
    f.t.push_back(x.t);
    f.theta.push_back(x.theta);
    f.lag.push_back(x.command - x.theta_dot);
    f.torque.push_back(x.torque);
    f.reference_error.push_back((x.end_effector - x.reference).norm());
  }
  f.torque_limit = o.loop.torque_limit;
  f.open_loop = &p.open;
  const std::string plan = p.name == "paper" || p.name == "global" ? p.name : "servo";  // fits the title
  f.title = str("Closed loop, ", plan, " plan, control ", o.control_rate, " Hz: capture error ",
                std::setprecision(3), r.capture_error * 1e3, " mm, M#die#u ", r.M_ie, " kg (plan ",
                p.open.M_ie, ")");
  return figures::closed_loop(f);
}

/// The closed loop's flags, each error naming its flag.
void check_flags(const ClosedLoopCliOptions& o) {
  auto check = [](double x, bool zero_ok, const char* flag) {
    if (!std::isfinite(x) || x < 0 || (!zero_ok && x == 0))
      throw InputError(str(flag, ": must be ", zero_ok ? ">= 0" : "positive", " and finite, got ", x));
  };
  check(o.loop.control_rate, false, "--control-rate");
  check(o.loop.estimate_rate, false, "--estimate-rate");
  check(o.loop.noise.position, true, "--position-noise");
  check(o.attitude_noise_deg, true, "--attitude-noise-deg");
  check(o.loop.noise.velocity, true, "--velocity-noise");
  check(o.spin_noise_deg, true, "--spin-noise-deg");
  check(o.loop.loop.bandwidth, false, "--rate-loop-bandwidth");
  check(o.loop.loop.torque_limit, false, "--torque-limit");
  detail::check_closed_loop_options(o.loop);
}

int run_closed_loop(ClosedLoopCliOptions o, const CLI::App& app) {
  ScenarioKeys keys = command_scenario_keys(o.config, o.flags, kClosedLoopKeys);
  // the global run is made for --plan global (and a servo goal keeps the joint-rate limit): a key of
  // the global run given as a flag for the paper's plan is refused (check_scenario_keys)
  keys.global = o.plan == "global" || !o.goal_joints_deg.empty();
  for_each_file_key(keys, app,
                    [&](const std::string& name, const std::string& text, const std::string& flag) {
                      o.set_from_file(name, text, flag);
                    });
  set_quiet(o.quiet);  // the flag, or the file's quiet key
  // the controller follows one plan, of the scenario's task: the pose task's keys act on it only
  if (keys.task != "pose")
    for (const char* name : {"final-rpy-deg", "orientation-tolerance-deg"})
      if (keys.overridden.count(name))
        throw InputError(detail::str("--", name, ": acts on the pose task only, and this plan's task is ", keys.task));
  const Scenario sc = command_scenario(std::move(keys));
  o.loop.noise.attitude = deg2rad(o.attitude_noise_deg);
  o.loop.noise.angular_velocity = deg2rad(o.spin_noise_deg);
  o.loop.seed = parse_count(o.noise_seed, "--noise-seed");
  if (!o.csv.empty() && !(o.loop.record_every > 0)) o.loop.record_every = 1.0;
  if (!o.plot.empty() && !(o.loop.record_every > 0))  // about 1000 points per curve
    o.loop.record_every = std::max(sc.capture.duration / 1000, 1.0 / o.loop.control_rate);
  Outputs outputs = o.outputs();
  check_flags(o);  // before the planning
  const plot::Format plot_format = plot::check_request(o.plot, o.plot_format);
  if (o.controller.prediction_window < 1 || o.controller.prediction_window > 100000)
    throw InputError(str("--prediction-window: must be in 1..100000, got ", o.controller.prediction_window));
  const Plan plan = make_plan(sc, o);
  const ClosedLoopResult r = simulate(sc, plan, o.loop, o.controller);
  if (!o.plot.empty()) plot::render({closed_loop_figure(sc, plan, o.loop, r)}, o.plot, plot_format);
  outputs.set("--json", result_json(sc, plan, o.loop, o.controller, r).dump(2) + "\n");
  outputs.set("--csv", series_csv(r));
  outputs.write();
  print_table(outputs.table(), sc, plan, o.loop, r);
  return 0;
}

}  // namespace

void register_closed_loop(CLI::App& app, Action& action) {
  auto o = std::make_shared<ClosedLoopCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "closed-loop",
      "The capture controller with the robot's dynamics, joint rate loops and a noisy target estimate");
  sub->add_option("--config", o->config, "Scenario file (TOML); default: the built-in paper 3-DOF scenario")
      ->check(CLI::ExistingFile);
  // one plan (--plan), no plain run, no shapes in the controller's dynamics; the M_ie reported (the
  // plan's and the loop's) is the scenario's joint model's
  o->flags.add_groups(*sub,
                      {KeyGroup::Robot, KeyGroup::Start, KeyGroup::Target, KeyGroup::TargetPlace,
                       KeyGroup::Contact, KeyGroup::Planner, KeyGroup::Global, KeyGroup::JointModels},
                      // the plan is flown as planned: the base's attitude task of the planner is not
                      // the controller's
                      {"global", "baseline-task", "base-attitude"});
  sub->add_option("--plan", o->plan, "The plan the controller follows: paper or global")
      ->capture_default_str();
  sub->add_option("--goal-joints-deg", o->goal_joints_deg,
                  "Servo to this capture configuration instead (deg)")
      ->delimiter(',')
      ->allow_extra_args(false);
  sub->add_option("--control-rate", o->loop.control_rate, "Controller ticks, Hz")->capture_default_str();
  sub->add_option("--estimate-rate", o->loop.estimate_rate, "Target estimates, Hz")->capture_default_str();
  sub->add_option("--position-noise", o->loop.noise.position,
                  "Estimate noise on the position, m (1 sigma per axis)")
      ->capture_default_str();
  sub->add_option("--attitude-noise-deg", o->attitude_noise_deg,
                  "Estimate noise on the attitude, deg (1 sigma per axis)")
      ->capture_default_str();
  sub->add_option("--velocity-noise", o->loop.noise.velocity,
                  "Estimate noise on the velocity, m/s (1 sigma per axis)")
      ->capture_default_str();
  sub->add_option("--spin-noise-deg", o->spin_noise_deg,
                  "Estimate noise on the spin, deg/s (1 sigma per axis)")
      ->capture_default_str();
  sub->add_option("--prediction-window", o->controller.prediction_window,
                  "Capture point = mean of the predictions of the last N estimates")
      ->capture_default_str();
  sub->add_option("--noise-seed", o->noise_seed, "Seed of the estimate noise")->capture_default_str();
  sub->add_option("--rate-loop-bandwidth", o->loop.loop.bandwidth, "Joint rate loops' bandwidth, rad/s")
      ->capture_default_str();
  sub->add_option("--torque-limit", o->loop.loop.torque_limit, "Joint torque limit, N m")
      ->capture_default_str();
  add_output_flags(*sub, *o,
                   {"Write the result as JSON to FILE",
                    "Write the time series (one row per second and joint) as CSV to FILE",
                    "Draw the closed loop beside the plan (joint angles, tracking, torques, lag)"});
  sub->callback([o, sub, &action] { action = [o, sub] { return run_closed_loop(*o, *sub); }; });
}

}  // namespace ffsr::cli
