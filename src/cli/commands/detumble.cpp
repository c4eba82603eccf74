// ffsr-optimize detumble: the grasp (after the approach or the Hertz contact), then the post-capture run
// of robot and target as one stack under the scenario's limits (the job is the library's,
// ffsr/jobs/detumble.hpp).
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/detumble.hpp"

#include <iomanip>
#include <iostream>
#include <memory>

namespace ffsr::cli {
namespace {

struct DetumbleCommandOptions {
  SubjectOptions subject;
  OutputKeys out;   ///< --json, --csv, --quiet
  std::string run;  ///< --run: plain, optimized, global or all; empty: the scenario's configuration
};

void print_detumble_table(std::ostream& out, const DetumbleJobResult& d) {
  const GraspResult& g = d.grasp;
  const DetumbleRunResult& r = d.result;
  constexpr double deg = 180.0 / M_PI;
  if (!d.run.empty()) out << "-- " << d.run << " run's capture\n";
  out << std::setprecision(4);
  if (d.contact)  // the Hertz phase before the lock
    out << "contact before the grasp " << d.contact->model << ": peak " << d.contact->f_max << " N, "
        << d.contact->contact_duration * 1e3 << " ms, impulse " << d.contact_impulse.norm()
        << " N s; the grasp locks at the separation\n";
  else
    out << "grasp start              the end of the approach (no contact phase)\n";
  out << "grasp impulse            " << g.impulse.head<3>().norm() << " N s, "
      << g.impulse.tail<3>().norm() << " N m s\n"
      << "base velocity jump       " << g.base_velocity_jump.head<3>().norm() * 1e3 << " mm/s, "
      << g.base_velocity_jump.tail<3>().norm() * deg << " deg/s\n"
      << "kinetic energy           " << g.energy_before << " J before the grasp, " << g.energy_after
      << " J after\n"
      << "base actuator            " << actuator_name(d.limits.actuator)
      << (d.options.stop_stack_spin ? " (stops the stack's spin)" : "") << "\n"
      << "time to rest             " << r.time_to_rest << " s (" << r.ticks << " ticks)\n"
      << "peak joint torque        " << r.peak_joint_torque << " N m (joint " << d.peak_joint_name << ")\n"
      << "peak gripper load        " << r.peak_gripper_force << " N, " << r.peak_gripper_moment << " N m\n"
      << "base attitude excursion  " << r.base_attitude_excursion * deg << " deg\n"
      << "peak wheel momentum      " << r.peak_wheel_momentum << " N m s\n"
      << "momentum drift           " << r.momentum_drift << " (relative)\n";
}

/// The contact law's flags act with grasp-after = contact only (the Hertz run before the grasp); the
/// file's keys of the law are the scenario's and stay.
void refuse_law_flags_without_contact(const DetumbleCommandOptions& o, const ScenarioKeys& keys) {
  if (keys.grasp_after == "contact") return;
  for (const char* name : {"model", "stiffness", "exponent", "restitution"})
    if (o.subject.flags.given(name))
      throw InputError(detail::str("--", name,
                                   ": acts on detumble only with grasp-after = contact (the Hertz contact "
                                   "run before the grasp), and this run has grasp-after = ",
                                   keys.grasp_after));
}

int run_detumble_command(const DetumbleCommandOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs = o.out.outputs();  // an output on standard output: the table goes to standard error
  const Subject subject = load_subject(o.subject);
  refuse_law_flags_without_contact(o, subject.keys);
  std::vector<DetumbleJobResult> results;
  if (o.run.empty()) {
    results.push_back(detumble(subject));
    outputs.set("--json", detumble_json(subject, results.front(), FFSR_VERSION).dump(2) + "\n");
  } else {
    const EmbeddedUrdf embedded = builtin_urdf();
    results = detumble_runs(subject, build_scenario(subject.keys, &embedded), o.run);
    outputs.set("--json", detumble_runs_json(subject, results, FFSR_VERSION).dump(2) + "\n");
  }
  if (!o.out.csv.empty()) outputs.set("--csv", detumble_series_csv(results));
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
  // the contact law acts with grasp-after = contact only (refuse_law_flags_without_contact)
  o->subject.add_to(*sub, scenario_key_names({KeyGroup::Detumble}));
  sub->add_option("--run", o->run,
                  "Start from the capture the main job plans: plain, optimized, global or all (default: the "
                  "scenario's configuration, joints-deg)");
  add_output_flags(
      *sub, o->out,
      {"Write the grasp and the post-capture run's summary as JSON to FILE",
       "Write the post-capture series (rates, gripper load, joint rates and torques) as CSV to FILE"});
  sub->callback([o, &action] { action = [o] { return run_detumble_command(*o); }; });
}

}  // namespace ffsr::cli
