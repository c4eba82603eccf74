// ffsr-optimize closed-loop [--config SCENARIO.toml] [flags]: the capture controller in a closed loop
// with the robot's full dynamics and a noisy target estimate, beside the open-loop plan it follows:
// the paper's method (--plan paper), the global run's servo (--plan global) or the servo to a given
// capture configuration (--goal-joints-deg). A flag overrides the scenario file's key. The job is the
// library's (ffsr/jobs/closed_loop.hpp).
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "figures/plot.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/closed_loop.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace ffsr::cli {
namespace {

using detail::str;

/// The job's options (plan, goal, loop, noise, controller) and the command's.
struct ClosedLoopCliOptions : OutputKeys, ClosedLoopJobOptions {
  std::string config;
  ScenarioFlags flags;
  std::string noise_seed = "1";
};

const std::set<std::string> kClosedLoopKeys = {"json", "csv", "plot", "plot-format", "quiet"};

void print_table(std::ostream& out, const Scenario& sc, const ClosedLoopPlan& p, const ClosedLoopOptions& o,
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
plot::Figure closed_loop_figure(const Scenario& sc, const ClosedLoopPlan& p, const ClosedLoopOptions& o,
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

int run_closed_loop(ClosedLoopCliOptions o, const CLI::App& app) {
  ScenarioKeys keys = command_scenario_keys(o.config, o.flags, kClosedLoopKeys);
  // the global run is made for --plan global (and a servo goal keeps the joint-rate limit): a key of
  // the global run given as a flag for the paper's plan is refused (check_scenario_keys)
  keys.global = o.plan == "global" || !o.goal_joints_deg.empty();
  for_each_file_key(keys, app,
                    [&](const std::string& name, const std::string& text, const std::string& flag) {
                      o.set_from_file(name, text, flag);
                      if (name == "plot-format") plot::parse_format(text, flag);  // checked here: located
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
  check_closed_loop_job(o);  // before the planning
  const plot::Format plot_format = plot::check_request(o.plot, o.plot_format);
  o.record_plan_series = !o.plot.empty();  // the plan's joint angles beside the closed loop's
  const ClosedLoopJobResult job = closed_loop(sc, o);  // checks --prediction-window, plans, runs the loop
  const ClosedLoopResult& r = job.result;
  if (!o.plot.empty())
    outputs.stage(plot::draw({closed_loop_figure(sc, job.plan, job.loop, r)}, o.plot, plot_format));
  outputs.set("--json", closed_loop_json(sc, job, FFSR_VERSION).dump(2) + "\n");
  outputs.set("--csv", closed_loop_series_csv(r));
  outputs.write();
  print_table(outputs.table(), sc, job.plan, job.loop, r);
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
