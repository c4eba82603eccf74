#include "support/subject.hpp"

#include "support/progress.hpp"

#include "embedded.hpp"

namespace ffsr::cli {

// --- the scenario of a command ----------------------------------------------------------------------

ScenarioKeys command_scenario_keys(const std::string& config, const ScenarioFlags& flags,
                                   const std::set<std::string>& command_keys) {
  ScenarioKeys keys = config.empty() ? read_scenario_text(kPaper3dofScenario, "built-in scenario")
                                     : read_scenario_file(config, command_keys);
  flags.apply(keys);
  // --urdf replaces the built-in robot: its end-effector and joint angles then come from the flags
  // alone (the library asks for --joints-deg). With --config, --urdf replaces the file's urdf key only.
  if (config.empty() && flags.given("urdf")) {
    if (!flags.given("end-effector")) keys.end_effector.clear();
    if (!flags.given("joints-deg")) {
      keys.joints_deg.clear();
      keys.given.erase("joints-deg");
    }
  }
  return keys;
}

EmbeddedUrdf builtin_urdf() { return {"paper_3dof.urdf", "built-in paper_3dof.urdf", kPaper3dofUrdf}; }

Scenario command_scenario(ScenarioKeys keys) {
  const EmbeddedUrdf embedded = builtin_urdf();
  Scenario sc = build_scenario(std::move(keys), &embedded);
  warn_repairs(sc.report);
  return sc;
}

namespace {

/// The keys of a subject (SubjectOptions): the robot and its start state, the bus and the loader, the
/// target and the contact law (the key table's groups).
const std::set<std::string>& subject_keys() {
  static const std::set<std::string> keys =
      scenario_key_names({KeyGroup::Robot, KeyGroup::Start, KeyGroup::Target, KeyGroup::Contact});
  return keys;
}

}  // namespace

void SubjectOptions::add_to(CLI::App& app, const std::set<std::string>& also, const std::set<std::string>& except) {
  app.add_option("--config", config,
                 "Scenario file (TOML) whose robot, start state, target and contact law to take; flags "
                 "override its keys (default: the built-in paper 3-DOF scenario)")
      ->check(CLI::ExistingFile);
  flags.add_to(app, [&also, &except](const std::string& name) {
    return (subject_keys().count(name) || also.count(name)) && !except.count(name);
  });
}

Scenario load_subject(const SubjectOptions& o, bool held) {
  const EmbeddedUrdf embedded = builtin_urdf();
  ScenarioKeys keys = command_scenario_keys(o.config, o.flags);
  if (!held && holds_target(keys))  // the library needs no capture then: this subcommand evaluates one
    for (const char* key : {"target-angular-velocity-deg", "contact-offset", "normal", "model", "stiffness",
                            "exponent", "restitution", "approach-speed"})
      if (!keys.given.count(key))
        throw InputError(detail::str(keys.where, ": missing key '", key,
                                     "' (grasp-after = held describes a stack that holds its target, and "
                                     "this subcommand evaluates a capture)"));
  return build_scenario(std::move(keys), &embedded, ScenarioScope::Configuration, warn_repairs);
}

}  // namespace ffsr::cli
