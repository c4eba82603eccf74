// ffsr/scenario/detail/keys.hpp -- the key table of ffsr/scenario/scenario.hpp (every key in one entry:
// name, kind, help, group, required, check, echo; the constructor of an entry is key_entry.hpp, the
// post-capture phase's entries detumble_keys.hpp); the file's reader over it is reader.hpp.
// Adding a key is one entry here (or in detumble_keys.hpp), its member in ScenarioKeys and its line in
// docs/scenario-keys.md.
#pragma once

#include "ffsr/scenario/scenario.hpp"
#include "ffsr/scenario/detail/detumble_keys.hpp"
#include "ffsr/scenario/detail/key_entry.hpp"
#include "ffsr/scenario/detail/values.hpp"

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

namespace ffsr {
namespace detail {

// --- the keys ------------------------------------------------------------------------------------

/// The robot: its URDF, the bus it is mounted on, the loader's repairs and the contact point.
inline void add_robot_keys(std::vector<ScenarioKey>& keys) {
  using G = KeyGroup;
  using K = ScenarioKeys;
  using L = ModelLoadKeys;
  keys.push_back(FFSR_KEY("urdf", urdf, "Robot URDF (relative to the scenario file)").in(G::Robot).needed());
  keys.push_back(FFSR_KEY("end-effector", end_effector, "End-effector frame (default: the single leaf link)")
                     .in(G::Robot)
                     .echoed(echo_given("end-effector", &K::end_effector)));
  keys.push_back(FFSR_KEY("bus-mass", load.bus_mass,
                          "Mount the URDF on a spacecraft bus of this mass, kg (the bus is the base)")
                     .in(G::Robot)
                     .echoed([](const Scenario& sc, nlohmann::json& j) {
                       if (sc.keys.load.given.count("bus-mass")) j["bus-mass"] = sc.keys.load.bus_mass;
                     }));
  keys.push_back(
      FFSR_KEY("bus-inertia", load.bus_inertia,
               "Bus inertia about its centre of mass (bus frame): Ixx,Iyy,Izz[,Ixy,Ixz,Iyz], kg m^2")
          .in(G::Robot)
          .echoed(echo_bus("bus-inertia", &L::bus_inertia, false)));
  keys.push_back(FFSR_KEY("bus-com", load.bus_com, "Bus centre of mass in the bus frame, m (default 0,0,0)")
                     .in(G::Robot)
                     .echoed(echo_bus("bus-com", &L::bus_com)));
  keys.push_back(FFSR_KEY("mount-xyz", load.mount_xyz,
                          "Position of the URDF's root link in the bus frame, m (default 0,0,0)")
                     .in(G::Robot)
                     .echoed(echo_bus("mount-xyz", &L::mount_xyz)));
  keys.push_back(
      FFSR_KEY("mount-rpy-deg", load.mount_rpy_deg,
               "Attitude of the URDF's root link in the bus frame, roll,pitch,yaw deg (default 0,0,0)")
          .in(G::Robot)
          .echoed(echo_bus("mount-rpy-deg", &L::mount_rpy_deg)));
  keys.push_back(FFSR_KEY("lock-joints", load.lock_joints,
                          "Joints frozen at a value, name=value (rad or m), comma-separated")
                     .in(G::Robot));
  keys.push_back(FFSR_KEY("inertia-repair", load.inertia_repair,
                          "Inertias breaking the triangle inequality: none (error) or balance", "none")
                     .in(G::Robot));
  keys.push_back(
      FFSR_KEY("min-mass", load.min_mass, "Links lighter than this get this mass, kg (0: off)", "0")
          .in(G::Robot));
  keys.push_back(FFSR_KEY("min-inertia", load.min_inertia,
                          "Principal moments below this are raised to it, kg m^2 (0: off)", "0")
                     .in(G::Robot));
  keys.push_back(FFSR_KEY("end-effector-offset", load.end_effector_offset,
                          "Contact point in the end-effector frame, m (x,y,z)")
                     .in(G::Robot)
                     .echoed([](const Scenario& sc, nlohmann::json& j) {
                       const auto& v = sc.keys.load.end_effector_offset;
                       if (!v.empty()) j["end-effector-offset"] = v;
                     }));
}

/// The robot's start state, the target and the contact law.
inline void add_state_and_contact_keys(std::vector<ScenarioKey>& keys) {
  using G = KeyGroup;
  using K = ScenarioKeys;
  keys.push_back(FFSR_KEY("joints-deg", joints_deg, "Initial joint angles, deg").in(G::Start).needed());
  keys.push_back(FFSR_KEY("base-position", base_position, "Initial base position, m").in(G::Start));
  keys.push_back(
      FFSR_KEY("base-rpy-deg", base_rpy_deg, "Initial base attitude (roll, pitch, yaw), deg").in(G::Start));
  keys.push_back(FFSR_KEY("target-mass", target_mass, "Target mass, kg").in(G::Target).needed());
  keys.push_back(FFSR_KEY("target-inertia", target_inertia,
                          "Target inertia: Ixx,Iyy,Izz[,Ixy,Ixz,Iyz], kg m^2 (target frame)")
                     .in(G::Target)
                     .needed());
  keys.push_back(FFSR_KEY("target-position", target_position, "Target centre of mass at t = 0, m")
                     .in(G::TargetPlace)
                     .needed());
  keys.push_back(FFSR_KEY("target-rpy-deg", target_rpy_deg, "Target attitude at t = 0, deg").in(G::Target));
  keys.push_back(FFSR_KEY("target-angular-velocity-deg", target_angular_velocity_deg,
                          "Target spin (target frame), deg/s")
                     .in(G::Target)
                     .needed());
  keys.push_back(FFSR_KEY("target-velocity", target_velocity, "Target linear velocity, m/s").in(G::Target));
  keys.push_back(FFSR_KEY("contact-offset", contact_offset,
                          "r_tp: contact point from the target centre of mass (target frame), m")
                     .in(G::Target)
                     .needed());
  keys.push_back(FFSR_KEY("normal", normal, "u_n: contact normal (target frame)").in(G::Target).needed());
  keys.push_back(FFSR_KEY("model", model, "Hysteresis damping law (Table 1)").in(G::Contact).needed());
  keys.push_back(FFSR_KEY("stiffness", stiffness, "K, N/m^alpha").in(G::Contact).needed());
  keys.push_back(FFSR_KEY("exponent", exponent, "alpha").in(G::Contact).needed());
  keys.push_back(FFSR_KEY("restitution", restitution, "c_r, 0 < c_r <= 1").in(G::Contact).needed());
  // positive for every job that reads it (the main job's bound, also inspect's, detumble's, ...)
  keys.push_back(
      FFSR_KEY("approach-speed", approach_speed, "End-effector speed along the normal at the capture, m/s")
          .in(G::Contact)
          .needed()
          .checked([](const K& k) { check_positive_if_given(k, "approach-speed", k.approach_speed); }));
}

/// The robot, its start state, the target and the contact law: what inspect, contact and map evaluate.
inline void add_subject_keys(std::vector<ScenarioKey>& keys) {
  add_robot_keys(keys);
  add_state_and_contact_keys(keys);
}

/// The plain and the paper's-method runs.
inline void add_planner_keys(std::vector<ScenarioKey>& keys) {
  using K = ScenarioKeys;
  keys.push_back(FFSR_KEY("task", task, "Optimized run's task: position or pose").needed());
  keys.push_back(FFSR_KEY("task-axes", task_axes, "Position task: constrained inertial axes, e.g. xy", "xyz")
                     .acting(on_the_task("position"))
                     .skipping(skips_other_task("position")));
  keys.push_back(FFSR_KEY("baseline-task", baseline_task, "Plain run's task (default: the optimized run's)")
                     .echoed([](const Scenario& sc, nlohmann::json& j) {
                       j["baseline-task"] =
                           sc.keys.baseline_task.empty() ? sc.keys.task : sc.keys.baseline_task;
                     }));
  keys.push_back(FFSR_KEY("final-rpy-deg", final_rpy_deg,
                          "Pose task: final end-effector orientation (default: hold the initial)")
                     .echoed(echo_given("final-rpy-deg", &K::final_rpy_deg))
                     .acting(on_the_task("pose"))
                     .skipping(skips_other_task("pose")));
  keys.push_back(FFSR_KEY("duration", duration, "Task time T, s").needed());
  keys.push_back(FFSR_KEY("step", step, "RK4 step, s").needed());
  keys.push_back(FFSR_KEY("gain", gain, "rho of Eq. 30 (< 0 lowers the objective)").needed());
  keys.push_back(FFSR_KEY("feedback", feedback, "Tracking feedback gain, 1/s", "1"));
  keys.push_back(FFSR_KEY("tolerance", tolerance, "Required capture-point accuracy, m").needed());
  keys.push_back(FFSR_KEY("orientation-tolerance-deg", orientation_tolerance_deg,
                          "Pose task: required orientation accuracy, deg", "0.5")
                     .acting(on_the_task("pose"))
                     .skipping(skips_other_task("pose")));
  keys.push_back(
      FFSR_KEY(
          "objective", objective,
          "mass (M_ie, the paper's), exact-force, or multibody-force (CVODE peak; global search only, the "
          "paper's method then descends M_ie)",
          "mass")
          .skipping(skips_of_objective));
  // the spacecraft's side: the reaction-null-space approach
  keys.push_back(
      FFSR_KEY("base-attitude", base_attitude,
               "Optimized run: free, or hold (the base's angular velocity stays zero; the objective "
               "uses the freedom left)",
               "free")
          .skipping(skips_of_base_attitude));
}

/// The global capture optimization and the reconfiguration before its approach (optimize/reconfigure.hpp).
inline void add_global_keys(std::vector<ScenarioKey>& keys) {
  using G = KeyGroup;
  using K = ScenarioKeys;
  keys.push_back(FFSR_KEY("global", global, "Also run the global capture optimization (true/false)", "true")
                     .in(G::Global));
  keys.push_back(
      FFSR_KEY("seed", seed, "Seed of the global search's random starts (non-negative integer)", "1")
          .in(G::Global)
          .checked([](const K& k) { seed_of(k.seed); }));
  keys.push_back(
      FFSR_KEY("max-joint-rate-deg", max_joint_rate_deg,
               "Global run: largest joint rate, deg/s (> 0; default: not limited; the paper's method is "
               "not limited)")
          .in(G::Global)
          .checked(
              [](const K& k) { check_positive_if_given(k, "max-joint-rate-deg", k.max_joint_rate_deg); }));
  keys.push_back(FFSR_KEY("global-starts", global_starts, "Global search: random starts (>= 1)", "32")
                     .in(G::Global)
                     .checked([](const K& k) {
                       if (k.global_starts < 1)
                         throw InputError(str("--global-starts: must be >= 1, got ", k.global_starts));
                     }));
  keys.push_back(
      FFSR_KEY(
          "max-base-rate-deg", max_base_rate_deg,
          "Global search: largest jump of the base's angular velocity at the impact, deg/s (a constraint; "
          "> 0; default: not limited; `pareto` shows the trade-off against M_ie)")
          .in(G::Global)
          .checked([](const K& k) { check_positive_if_given(k, "max-base-rate-deg", k.max_base_rate_deg); })
          .echoed(echo_given("max-base-rate-deg", &K::max_base_rate_deg)));
  keys.push_back(
      FFSR_KEY("reconfigure", reconfigure,
               "Global run: reconfigure the arm before the approach: auto (only when the best capture "
               "configuration is not reached otherwise), always or never",
               "auto")
          .in(G::Global)
          .checked([](const K& k) { reconfigure_mode_of(k.reconfigure, "--reconfigure"); }));
  keys.push_back(
      FFSR_KEY("reconfigure-duration", reconfigure_duration,
               "Global run: time of the reconfiguration, s, 0 < t < duration (default: duration / 4, longer "
               "if max-joint-rate-deg needs it)")
          .in(G::Global)
          .checked([](const K& k) {
            if (k.given.count("reconfigure-duration") &&
                !(finite(k.reconfigure_duration, "reconfigure-duration") > 0 &&
                  k.reconfigure_duration < k.duration))
              throw InputError(str("--reconfigure-duration: must lie in (0, duration = ", k.duration,
                                   ") s, got ", k.reconfigure_duration));
          })
          .echoed(echo_given("reconfigure-duration", &K::reconfigure_duration)));
}

/// The joints during the contact (algorithm/joint_models.hpp) and the multibody reference's servo;
/// shapes and clearance (scenario/geometry.hpp, docs/geometry.md).
inline void add_joint_and_shape_keys(std::vector<ScenarioKey>& keys) {
  using G = KeyGroup;
  using K = ScenarioKeys;
  // joint models: absent from the echo means free (the paper's); the armature as resolved per joint
  keys.push_back(
      FFSR_KEY("contact-joints", contact_joints,
               "The joints during the contact: free (the paper's), locked (one rigid body) or armature "
               "(free with the armature's reflected rotor inertia)",
               "free")
          .in(G::JointModels)
          .echoed([](const Scenario& sc, nlohmann::json& j) {
            if (sc.keys.contact_joints != "free") j["contact-joints"] = sc.keys.contact_joints;
          }));
  keys.push_back(
      FFSR_KEY("armature", armature,
               "Reflected rotor inertia per joint, kg m^2 (kg for prismatic): one value or one per joint",
               "0")
          .in(G::JointModels)
          .echoed([](const Scenario& sc, nlohmann::json& j) {
            if (sc.keys.contact_joints != "free")
              j["armature"] = joint_values_json(sc.problem.joints.armature);
          }));
  keys.push_back(
      FFSR_KEY("joint-stiffness", joint_stiffness,
               "Multibody reference: joint PD stiffness holding the pre-contact rates, N m/rad (one or "
               "per joint)",
               "0")
          .in(G::JointModels)
          .echoed([](const Scenario& sc, nlohmann::json& j) {
            if (sc.keys.given.count("joint-stiffness"))
              j["joint-stiffness"] = joint_values_json(sc.joint_stiffness);
          })
          .acting(on_the_multibody_reference)
          .skipping(skips_but_multibody_reference));
  keys.push_back(FFSR_KEY("joint-damping", joint_damping,
                          "Multibody reference: joint PD damping, N m s/rad (one or per joint)", "0")
                     .in(G::JointModels)
                     .echoed([](const Scenario& sc, nlohmann::json& j) {
                       if (sc.keys.given.count("joint-damping"))
                         j["joint-damping"] = joint_values_json(sc.joint_damping);
                     })
                     .acting(on_the_multibody_reference)
                     .skipping(skips_but_multibody_reference));
  keys.push_back(FFSR_KEY("target-shape", target_shape,
                          "Target's collision shape: box, sphere or cylinder (default: none)")
                     .in(G::Shapes)
                     .echoed(echo_shape("target-shape", &K::target_shape)));
  keys.push_back(
      FFSR_KEY("target-size", target_size,
               "Target shape's size, m: box edge lengths; sphere radius; cylinder radius, length (along z)")
          .in(G::Shapes)
          .echoed(echo_shape("target-size", &K::target_size)));
  keys.push_back(FFSR_KEY("target-shape-offset", target_shape_offset,
                          "Target shape's centre in the target frame, m", "0,0,0")
                     .in(G::Shapes)
                     .echoed(echo_shape("target-shape-offset", &K::target_shape_offset)));
  keys.push_back(
      FFSR_KEY("link-radius", link_radius,
               "Capsule radius of links without URDF collision primitives, m (one, or one per moving body)",
               "0.05")
          .in(G::Shapes)
          .echoed(echo_shape("link-radius", &K::link_radius)));
  keys.push_back(
      FFSR_KEY("bus-box", bus_box,
               "The bus as a box centred on the base frame (edge lengths, m), when the URDF's base has no "
               "collision primitive")
          .in(G::Shapes)
          .echoed(echo_shape("bus-box", &K::bus_box)));
  keys.push_back(FFSR_KEY("clearance", clearance,
                          "Least distance the global run keeps between arm, bus and target, m (0: none)", "0")
                     .in(G::Shapes)
                     .echoed(echo_shape("clearance", &K::clearance)));
  keys.push_back(
      FFSR_KEY("contact-exemption", contact_exemption,
               "Length of the arm before the contact point (along the links' centre lines) not checked "
               "against the target, m",
               "0.2")
          .in(G::Shapes)
          .echoed(echo_shape("contact-exemption", &K::contact_exemption)));
}

#undef FFSR_KEY  // defined in key_entry.hpp for this table and detumble_keys.hpp

/// The table, in the order a command lists the keys (the flags of `ffsr-optimize --help`).
inline std::vector<ScenarioKey> build_scenario_keys() {
  std::vector<ScenarioKey> keys;
  add_subject_keys(keys);
  add_planner_keys(keys);
  add_global_keys(keys);
  add_joint_and_shape_keys(keys);
  add_detumble_keys(keys);
  add_detumble_run_keys(keys);
  add_post_capture_keys(keys);
  // every key of the global run but the switch acts on that run only
  for (ScenarioKey& key : keys)
    if (key.group == KeyGroup::Global && key.name != "global")
      key.acting(on_the_global_run).skipping(skips_but_global);
  return keys;
}

/// Levenshtein distance (insertions, deletions, substitutions).
inline size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// The name of `names` nearest to `name`, or "" when none is within a third of its length (at least 1).
inline std::string nearest_name(const std::string& name, const std::vector<std::string>& names) {
  std::string best;
  size_t best_d = std::max<size_t>(1, name.size() / 3) + 1;
  for (const std::string& n : names) {
    const size_t d = edit_distance(name, n);
    if (d < best_d) {
      best = n;
      best_d = d;
    }
  }
  return best;
}

}  // namespace detail

inline const std::vector<ScenarioKey>& scenario_keys() {
  static const std::vector<ScenarioKey> keys = detail::build_scenario_keys();
  return keys;
}

inline const ScenarioKey* find_scenario_key(const std::string& name) {
  for (const ScenarioKey& k : scenario_keys())
    if (k.name == name) return &k;
  return nullptr;
}

inline std::vector<std::string> keys_not_applied(const ScenarioKeys& keys, ScenarioRow row) {
  std::vector<std::string> out;
  for (const ScenarioKey& k : scenario_keys())
    if (k.skips && keys.given.count(k.name) && k.skips(keys).has(row)) out.push_back(k.name);
  return out;
}

inline const std::vector<std::string>& required_scenario_keys() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const ScenarioKey& k : scenario_keys())
      if (k.required) out.push_back(k.name);
    return out;
  }();
  return names;
}

inline std::set<std::string> scenario_key_names(std::initializer_list<KeyGroup> groups) {
  std::set<std::string> out;
  for (const ScenarioKey& k : scenario_keys())
    if (std::find(groups.begin(), groups.end(), k.group) != groups.end()) out.insert(k.name);
  return out;
}

inline std::string nearest_scenario_key(const std::string& name) {
  std::vector<std::string> names;
  for (const ScenarioKey& k : scenario_keys()) names.push_back(k.name);
  return detail::nearest_name(name, names);
}

}  // namespace ffsr
