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

namespace {

/// The subject of the keys (load_subject without the file's locations).
void build_subject(Subject& s) {
  ScenarioKeys& k = s.keys;
  const EmbeddedUrdf embedded = builtin_urdf();
  s.robot.model = std::move(*ffsr::detail::model_of(k, &embedded, s.robot.report));
  warn_repairs(s.robot.report);
  CaptureProblem pb;
  ffsr::detail::start_of(k, s.robot.model, pb);
  s.robot.end_effector = s.robot.model.end_effector();
  s.robot.theta = pb.theta;
  s.robot.base = pb.base;
  s.target = ffsr::detail::target_of(k);
  s.params = {k.stiffness, k.exponent, k.restitution};  // validate names a non-finite value
  try {
    validate(s.params, "contact");
  } catch (const InputError& e) {
    throw InputError(std::string("--stiffness/--exponent/--restitution: ") + e.what());
  }
  s.law = k.model;
  s.approach_speed = ffsr::detail::finite(k.approach_speed, "approach-speed");
}

}  // namespace

Subject load_subject(const SubjectOptions& o) {
  Subject s;
  s.keys = command_scenario_keys(o.config, o.flags);
  try {  // an error of a key the file gave names the file and the key's line, as build_scenario's
    build_subject(s);
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, e.what()));
  }
  return s;
}

ContactJoints Subject::contact_joints() const {
  const JointModel m =
      all_joint_models() ? JointModel::Free : parse_joint_model(keys.contact_joints, "--contact-joints");
  return {m, per_joint_values(keys.armature, robot.model, "--armature")};
}

}  // namespace ffsr::cli
