// ffsr/jobs/subject.hpp -- what the one-configuration jobs evaluate (inspect, contact, map): a robot
// at one configuration, the target and the contact law, built from a scenario's keys (the keys of a
// file or of a built-in scenario, then the overrides) by the library's reader (ffsr/scenario/scenario.hpp).
// Component ffsr::scenario. Never prints: the loader's repairs are handed to a callback.
#pragma once

#include "ffsr/algorithm/joint_models.hpp"
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/model/model.hpp"
#include "ffsr/model/target.hpp"
#include "ffsr/optimize/capture_problem.hpp"

#include <functional>
#include <string>
#include <utility>

namespace ffsr {

/// A robot at one configuration.
struct Robot {
  Model model;
  int end_effector = 0;
  BasePose base;
  Eigen::VectorXd theta;
  UrdfReport report;  ///< what the loader did to the file
};

/// The robot at one configuration, the target and the contact law of a scenario's keys.
struct Subject {
  ScenarioKeys keys;  ///< as resolved (the URDF path relative to the scenario file)
  Robot robot;
  Target target;              ///< at t = 0, with its spin and velocity
  ContactParams params;       ///< K, alpha, c_r, checked
  std::string law;            ///< the damping law's name as given (contact also takes 'all')
  double approach_speed = 0;  ///< m/s, finite (its sign is the job's to judge)
  /// The joint models of the contact (contact-joints, armature; algorithm/joint_models.hpp); 'all'
  /// (contact: each model in turn) gives free. InputError naming the key.
  ContactJoints contact_joints() const {
    try {  // located in the file when the file gave the key
      const JointModel m =
          all_joint_models() ? JointModel::Free : parse_joint_model(keys.contact_joints, "--contact-joints");
      return {m, per_joint_values(keys.armature, robot.model, "--armature")};
    } catch (const InputError& e) {
      throw InputError(located_key_message(keys, e.what()));
    }
  }
  bool all_joint_models() const { return keys.contact_joints == "all"; }
};

/// Builds the subject of `keys` (the robot and its start state, the bus and the loader, the target,
/// the contact law), after the check of every key (ScenarioKey::check: a file's keys for other jobs
/// too); `embedded`: the URDF of a built-in scenario (scenario/scenario.hpp). `on_load` is
/// called with the loader's report as soon as the robot is loaded (the command warns about every
/// repair there). InputError naming the key (located in the file when the file gave it) or the file,
/// ModelError from the loader.
inline Subject load_subject(ScenarioKeys keys, const EmbeddedUrdf* embedded = nullptr,
                            const std::function<void(const UrdfReport&)>& on_load = {}) {
  Subject s;
  s.keys = std::move(keys);
  try {  // an error of a key the file gave names the file and the key's line, as build_scenario's
    ScenarioKeys& k = s.keys;
    for (const ScenarioKey& key : scenario_keys())  // every key read is checked, those of other jobs too
      if (key.check) key.check(k);
    s.robot.model = std::move(*detail::model_of(k, embedded, s.robot.report));
    if (on_load) on_load(s.robot.report);
    CaptureProblem pb;
    detail::start_of(k, s.robot.model, pb);
    s.robot.end_effector = s.robot.model.end_effector();
    s.robot.theta = pb.theta;
    s.robot.base = pb.base;
    s.target = detail::target_of(k);
    s.params = {k.stiffness, k.exponent, k.restitution};  // validate names a non-finite value
    try {
      validate(s.params, "contact");
    } catch (const InputError& e) {
      throw InputError(std::string("--stiffness/--exponent/--restitution: ") + e.what());
    }
    s.law = k.model;
    s.approach_speed = detail::finite(k.approach_speed, "approach-speed");
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, e.what()));
  }
  return s;
}

}  // namespace ffsr
