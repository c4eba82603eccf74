// ffsr-optimize detumble: the grasp (after the approach or the Hertz contact), then the post-capture run
// of robot and target as one stack under the scenario's limits (the job is the library's,
// ffsr/jobs/detumble.hpp).
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "figures/plot.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/detumble.hpp"

#include <iomanip>
#include <iostream>
#include <memory>

namespace ffsr::cli {
namespace {

struct DetumbleCommandOptions {
  SubjectOptions subject;
  OutputKeys out;   ///< --json, --csv, --plot, --plot-format, --quiet
  std::string run;  ///< --run: plain, optimized, global or all; empty: the scenario's configuration
  bool plan = false;  ///< --plan: the time-optimal plan from each start too
};

void print_detumble_table(std::ostream& out, const DetumbleJobResult& d) {
  const GraspResult& g = d.grasp;
  const DetumbleRunResult& r = d.result;
  constexpr double deg = 180.0 / M_PI;
  if (!d.run.empty()) out << "-- " << d.run << " run's capture\n";
  out << std::setprecision(4);
  if (d.held) {  // no grasp: the stack holds its target from the start
    out << "grasp start              held: the target welded to the gripper from the start (no grasp)\n"
        << "kinetic energy           " << g.energy_after << " J at the start\n";
  } else {
    if (d.contact)  // the Hertz phase before the lock
      out << "contact before the grasp " << d.contact->model << ": peak " << d.contact->f_max << " N, "
          << d.contact->contact_duration * 1e3 << " ms, impulse " << d.contact_impulse.norm()
          << " N s; the grasp locks at the separation\n";
    else
      out << "grasp start              the end of the approach (no contact phase)\n";
    out << "grasp impulse            " << g.impulse.head<3>().norm() << " N s, " << g.impulse.tail<3>().norm()
        << " N m s\n"
        << "base velocity jump       " << g.base_velocity_jump.head<3>().norm() * 1e3 << " mm/s, "
        << g.base_velocity_jump.tail<3>().norm() * deg << " deg/s\n"
        << "kinetic energy           " << g.energy_before << " J before the grasp, " << g.energy_after
        << " J after\n";
  }
  out << "base actuator            " << actuator_name(d.settings.limits.actuator)
      << (d.settings.options.stop_stack_spin ? " (stops the stack's spin)" : "") << "\n"
      << "time to rest             " << r.time_to_rest << " s ("
      << std::lround(r.time_to_rest / d.settings.run.tick) << " ticks)\n"
      << "held at rest             " << d.settings.run.dwell << " s: largest rate " << r.dwell_peak_rate * deg
      << " deg/s" << (r.dwell_at_rest ? " (at rest throughout)" : " (NOT at rest throughout)") << "\n"
      << "peak joint torque        " << r.peak_joint_torque << " N m (joint " << d.peak_joint_name << ")\n"
      << "peak gripper load        " << r.peak_gripper_force << " N, " << r.peak_gripper_moment << " N m\n"
      << "base attitude excursion  " << r.base_attitude_excursion * deg << " deg\n"
      << "peak wheel momentum      " << r.peak_wheel_momentum << " N m s\n"
      << "momentum drift           " << r.momentum_drift << " (relative)\n";
  if (!d.plan) return;
  const DetumblePlan& p = d.plan->plan;
  const DetumblePlanRun& pr = d.plan->run;
  out << "time-optimal plan        at rest in " << p.duration << " s (the law: " << r.time_to_rest << " s); "
      << p.intervals() << " intervals, IPOPT " << p.status << " in " << p.iterations << " iterations, "
      << p.solve_seconds << " s\n"
      << "plan re-run (CVODE)      " << (pr.at_rest ? "at rest at T" : "NOT at rest at T") << ": largest joint rate "
      << pr.end_joint_rate * deg << " deg/s, base " << pr.end_base_rate * deg << " deg/s and "
      << pr.end_base_speed * 1e3 << " mm/s; bounds " << (pr.worst_bound_excess <= 1e-9 ? "held" : "EXCEEDED")
      << " (largest excess " << pr.worst_bound_excess << "); held " << d.settings.run.dwell << " s"
      << (pr.dwell_at_rest ? " at rest" : " NOT at rest") << "\n";
}

/// The contact law's flags act with grasp-after = contact only (the Hertz run before the grasp); with
/// held no capture is made, and the flags of the capture (the target's motion, the contact point and
/// normal, the approach speed) act on nothing. The file's keys stay: the scenario serves other jobs.
void refuse_capture_flags(const DetumbleCommandOptions& o, const ScenarioKeys& keys) {
  if (keys.grasp_after != "contact")
    for (const char* name : {"model", "stiffness", "exponent", "restitution"})
      if (o.subject.flags.given(name))
        throw InputError(detail::str("--", name,
                                     ": acts on detumble only with grasp-after = contact (the Hertz contact "
                                     "run before the grasp), and this run has grasp-after = ",
                                     keys.grasp_after));
  if (!holds_target(keys)) return;
  for (const char* name :
       {"target-angular-velocity-deg", "target-velocity", "contact-offset", "normal", "approach-speed"})
    if (o.subject.flags.given(name))
      throw InputError(detail::str("--", name,
                                   ": acts on the capture, and with grasp-after = held the stack holds its "
                                   "target from the start (its motion is the start-* keys')"));
}

/// The figure of the runs: their series as recorded, the limits and the rest threshold they ran under.
plot::Figure detumble_figure(const Scenario& sc, const std::vector<DetumbleJobResult>& results) {
  figures::DetumbleSeries f;
  const DetumbleJobResult& first = results.front();
  f.joint_names = sc.model->joint_names();
  const DetumbleSettings& settings = first.settings;
  f.torque_limit.assign(settings.limits.joint_torque.data(),
                        settings.limits.joint_torque.data() + settings.limits.joint_torque.size());
  f.rest_rate = settings.options.rest_rate;
  f.stack_rate = settings.options.stop_stack_spin;
  if (settings.limits.actuator == BaseActuator::ReactionWheels)
    f.wheel_bound = settings.limits.wheel_momentum;
  for (const DetumbleJobResult& d : results) {
    figures::DetumbleSeries::Run r;
    r.label = d.run == "baseline" ? "plain" : d.run.empty() ? "joints-deg" : d.run == "baseline-plan" ? "plain-plan" : d.run;
    // the runs' colours of the main job; a plan's re-run in the next colour
    const bool plan = d.run.size() >= 4 && d.run.compare(d.run.size() - 4, 4, "plan") == 0;
    r.color = (d.run == "optimized" ? 1 : d.run == "global" ? 2 : 0) + (plan ? 3 : 0);
    for (const DetumbleSample& x : d.result.series) {
      r.t.push_back(x.t);
      r.joint_rate.push_back(x.command.joint_rate);
      r.relative_rate.push_back(x.command.relative_rate);
      r.stack_rate.push_back(x.command.stack_rate);
      r.force.push_back(x.gripper_force.norm());
      r.moment.push_back(x.gripper_moment.norm());
      r.attitude.push_back(x.base_attitude);
      r.energy.push_back(x.energy);
      r.rate.push_back(x.theta_dot);
      r.torque.push_back(x.command.tau);
      r.wheel.push_back(x.wheel_momentum);
    }
    f.runs.push_back(std::move(r));
  }
  if (first.run.empty()) {
    // three significant digits (str gives a computed number six, a short one all of them)
    f.title = detail::str("After the capture: at rest in ",
                          detail::number_with_digits(first.result.time_to_rest, 3), " s, peak joint torque ",
                          detail::number_with_digits(first.result.peak_joint_torque, 3), " N m (joint ",
                          first.peak_joint_name, ")");
  } else {
    f.title = first.run == "law" ? "After the capture: at rest in " : "After each run's capture: at rest in ";
    for (size_t i = 0; i < results.size(); ++i)
      f.title += std::string(i ? ", " : "") + detail::number_with_digits(results[i].result.time_to_rest, 3) +
                 " s (" + f.runs[i].label + ")";
  }
  return figures::detumble(f);
}

int run_detumble_command(const DetumbleCommandOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs = o.out.outputs();  // an output on standard output: the table goes to standard error
  // before the scenario is built: with held a capture flag would ask for the capture's other keys
  refuse_capture_flags(o, command_scenario_keys(o.subject.config, o.subject.flags));
  Scenario sc = load_subject(o.subject, true);  // the robot is loaded once: --run resolves the rest of it
  const plot::Format plot_format = plot::check_request(o.out.plot, o.out.plot_format);  // before the run
  if (o.plan) require_detumble_planner();  // before the runs
  std::vector<DetumbleJobResult> results;
  if (o.run.empty()) {
    results.push_back(detumble(sc));
  } else {
    detail::refuse_held(sc, "--run");  // before the main job's keys are asked for
    const EmbeddedUrdf embedded = builtin_urdf();
    resolve_run(sc, &embedded);
    results = detumble_runs(sc, o.run);
  }
  if (o.plan) detumble_plans(sc, results);
  outputs.set("--json", (o.run.empty() ? detumble_json(sc, results.front(), FFSR_VERSION)
                                       : detumble_runs_json(sc, results, FFSR_VERSION))
                                .dump(2) +
                            "\n");
  if (!o.out.plot.empty())
    outputs.stage(plot::draw({detumble_figure(sc, detail::with_plan_runs(results))}, o.out.plot, plot_format));
  if (!o.out.csv.empty()) outputs.set("--csv", detumble_series_csv(sc, results));
  outputs.write();
  for (size_t i = 0; i < results.size(); ++i) {
    if (i > 0) outputs.table() << "\n";
    print_detumble_table(outputs.table(), results[i]);
  }
  return 0;
}

}  // namespace

void register_detumble(CLI::App& app, Action& action) {
  auto o = std::make_shared<DetumbleCommandOptions>();
  CLI::App* sub = app.add_subcommand(
      "detumble", "After the capture: the grasp, then robot and target brought to rest within the limits");
  // the contact law acts with grasp-after = contact only, the capture's keys not with held
  // (refuse_capture_flags)
  o->subject.add_to(*sub, scenario_key_names({KeyGroup::Detumble}));
  sub->add_option("--run", o->run,
                  "Start from the capture the main job plans: plain, optimized, global or all (default: the "
                  "scenario's configuration, joints-deg)");
  sub->add_flag("--plan", o->plan,
               "Also plan the fastest detumble from each start (IPOPT): the plan, its controls and its re-run "
               "by CVODE in the outputs beside the law's run");
  add_output_flags(
      *sub, o->out,
      {"Write the grasp and the post-capture run's summary as JSON to FILE",
       "Write the post-capture series (rates, gripper load, joint rates, torques and angles, the base's, the "
       "target's and every body's pose) as CSV to FILE",
       "Draw the post-capture run against time (joint rates and torques, the rest test, gripper load, base "
       "attitude, wheels)"});
  sub->callback([o, &action] { action = [o] { return run_detumble_command(*o); }; });
}

}  // namespace ffsr::cli
