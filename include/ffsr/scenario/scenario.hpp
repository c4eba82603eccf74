// ffsr/scenario/scenario.hpp -- a capture scenario as a value: its keys, one TOML reader (toml++, the
// [uncertainty] table included), overrides given as text (a command line), one validation, and the
// problem it describes. Component ffsr::scenario (urdfdom, SUNDIALS, NLopt, toml++, nlohmann/json).
#pragma once

#include "ffsr/control/detumble_run.hpp"
#include "ffsr/errors.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/capture.hpp"
#include "ffsr/optimize/global.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

// A scenario file is a flat TOML table: every key of `scenario_keys()` (robot, start state, target,
// contact, tasks, planner, global run) and an optional [uncertainty] table. Messages name the file
// ("scenario FILE: missing key 'duration'") and the key as the file writes it ("scenario FILE:27:
// duration: ...") or as the flag that set it ("--duration: must be positive, got -1").
//
//   ffsr::Scenario sc = ffsr::load_scenario("robots/paper_7dof_position.toml");
//   ffsr::ScenarioResult r = ffsr::run_scenario(sc);          // scenario_run.hpp
//   nlohmann::json j = ffsr::scenario_json(sc, r, "0.1.0");   // what `ffsr-optimize --json` writes

namespace ffsr {

/// How a URDF becomes a model: the bus it is mounted on, locked joints, inertia repairs, the contact
/// point at the gripper (the keys bus-mass ... end-effector-offset).
struct ModelLoadKeys {
  double bus_mass = 0.0;
  std::vector<double> bus_inertia, bus_com, mount_xyz, mount_rpy_deg, end_effector_offset;
  std::vector<std::string> lock_joints;
  std::string inertia_repair = "none";
  double min_mass = 0.0, min_inertia = 0.0;
  std::set<std::string> given;  ///< the keys that were set (bus-mass, the mount keys, ...)
  /// The loader options; InputError naming the key on a bad value.
  UrdfOptions build(const std::string& end_effector) const;
};

/// The keys of a scenario, as read (units of the file: degrees where the key says so).
struct ScenarioKeys {
  std::string urdf, end_effector;
  ModelLoadKeys load;
  std::vector<double> joints_deg, base_position{0, 0, 0}, base_rpy_deg{0, 0, 0};
  double target_mass = 0;
  std::vector<double> target_inertia, target_position, target_rpy_deg{0, 0, 0}, target_angular_velocity_deg,
      target_velocity{0, 0, 0}, contact_offset, normal;
  std::string model;
  double stiffness = 0, exponent = 0, restitution = 0, approach_speed = 0;
  std::string task, task_axes = "xyz", baseline_task;
  std::vector<double> final_rpy_deg;
  double duration = 0, step = 0, gain = 0, feedback = 1.0, tolerance = 0, orientation_tolerance_deg = 0.5;
  std::string objective = "mass";
  bool global = true;             ///< also run the global capture optimization
  std::string seed = "1";         ///< the global search's seed (text: a bad value names the key)
  double max_joint_rate_deg = 0;  ///< 0: not set
  double max_base_rate_deg = 0;   ///< global search: largest impact base-rate jump, deg/s; 0: not set
  int global_starts = 32;
  std::string reconfigure = "auto";  ///< reconfiguration before the approach: auto, always, never
  double reconfigure_duration = 0;   ///< s; 0: not set (duration / 4, longer if the rate limit needs it)
  // joint models of the contact (algorithm/joint_models.hpp) and the multibody reference's servo
  std::string contact_joints = "free";
  std::vector<double> armature, joint_stiffness, joint_damping;

  std::string file;                  ///< the scenario file; empty: a built-in scenario
  std::string where;                 ///< "scenario FILE" or "built-in scenario", for messages
  std::set<std::string> given;       ///< keys set by the file or an override
  std::set<std::string> overridden;  ///< keys set by an override (paths not resolved against the file)
  /// True once build_scenario has joined `urdf` to the scenario file's folder: building a scenario
  /// again from these keys (a variant of it) does not join it a second time.
  bool urdf_resolved = false;
  std::map<std::string, std::string> extra;     ///< keys of the caller (read_scenario_file), as text
  std::shared_ptr<const toml::table> document;  ///< the file as read (its [uncertainty] table)
  // the spacecraft's side: the reaction-null-space approach
  std::string base_attitude = "free";  ///< free or hold (the optimized run keeps w_0 = 0)
  // shapes and clearance (scenario/geometry.hpp)
  std::string target_shape;  ///< box, sphere, cylinder; empty: none
  std::vector<double> target_size, target_shape_offset, link_radius{0.05}, bus_box;
  double clearance = 0, contact_exemption = 0.2;
  // the post-capture phase (the detumble job, control/detumble_run.hpp)
  std::vector<double> joint_torque_limit;  ///< N m per joint (one for all); empty: the URDF's effort
  std::string base_actuator = "none";      ///< none, reaction-wheels or thrusters
  double wheel_torque = 0, wheel_momentum = 0, thruster_force = 0, thruster_torque = 0;
  double gripper_force_limit = 0, gripper_moment_limit = 0;  ///< N, N m; 0: not given (not limited)
  double rest_rate_deg = 0.05, detumble_horizon = 120, detumble_tick = 0.01, detumble_dwell = 5;
  double detumble_max_decay = 20, detumble_max_base_decay = 2;  ///< 1/s (DetumbleOptions)
  bool stop_stack_spin = false;
  /// the grasp's start: approach, contact (the Hertz run first), or held (the stack holds its target
  /// from the start state: no capture)
  std::string grasp_after = "approach";
  /// grasp-after = held: the stack's rates at the start (joints deg/s; the base origin's velocity m/s
  /// and the base's angular velocity deg/s, inertial axes); empty: zero
  std::vector<double> start_joint_rates_deg, start_base_velocity, start_base_angular_velocity_deg;
  // the global search's post-capture constraints (jobs/detail/post_capture.hpp); 0: not set
  double max_time_to_rest = 0, max_peak_joint_torque = 0, max_gripper_force = 0, max_gripper_moment = 0;
};

/// The post-capture run's settings of the Detumble keys (joint-torque-limit ... grasp-after) for `model`
/// (the robot; the stack has the same joints), the one conversion of those keys: joint-torque-limit
/// (one value or one per joint; when not given, the URDF's <limit effort> of every joint), the base
/// actuator and its bounds (each needed by its actuator, refused where it does not act, from a file
/// too), rest-rate-deg, stop-stack-spin, detumble-tick, detumble-horizon. Each key's value is checked
/// once, by the key table (ScenarioKey::check, when the scenario is built). InputError naming the key.
DetumbleSettings detumble_settings(const ScenarioKeys& keys, const Model& model);

/// grasp-after = held: the stack holds its target from the start, and no capture is made (the keys of
/// the capture, the target's motion, contact point and normal, the contact law and the approach speed,
/// are not needed then: a file may give them for its other jobs).
bool holds_target(const ScenarioKeys& keys);

/// The held stack's start state (grasp-after = held), the one conversion of the start keys: the base
/// pose and joint angles `base`, `theta` (the scenario's start configuration), the generalized velocity
/// [v0; w0; theta_dot] of start-base-velocity (m/s), start-base-angular-velocity-deg and
/// start-joint-rates-deg (one per joint of `model`; each zero when not given), no wheel momentum.
/// InputError naming the key.
DetumbleState held_start_state(const ScenarioKeys& keys, const Model& model, const BasePose& base,
                               const Eigen::VectorXd& theta);

/// The kind of a key's value: one parser each, from a TOML node and from text.
enum class KeyKind { Text, Texts, Number, Numbers, Integer, Boolean };

/// What part of the scenario a key describes (the sections of docs/scenario-keys.md). A subcommand
/// takes the keys of the groups it evaluates: inspect, contact and map the subject (Robot, Start,
/// Target, Contact), the main job all of them.
enum class KeyGroup {
  Robot,        ///< the URDF, its end-effector and how it is loaded (bus, locks, repairs)
  Start,        ///< the start state: joint angles, base pose
  Target,       ///< the target's mass, inertia, attitude, motion, contact point and normal
  TargetPlace,  ///< where the target is (target-position): the capture point, distances
  Contact,      ///< the contact law and the approach speed
  Planner,      ///< the plain and the paper's-method runs: tasks, time, step, gains
  Global,       ///< the global capture optimization
  JointModels,  ///< the joints during the contact and the multibody reference's servo
  Shapes,       ///< collision shapes and the clearance
  Detumble,     ///< the post-capture phase: joint torque limits, base actuator, rest, horizon, tick
  PostCapture,  ///< the global search's constraints on the post-capture phase (time to rest, loads)
};

struct Scenario;

/// The rows of the main job (jobs/scenario_run.hpp): the plain run (rho = 0, baseline-task), the
/// paper's method (the optimized run) and the global run.
enum class ScenarioRow { Plain, Optimized, Global };
/// A set of rows: the rows a key does not act on (ScenarioKey::skips).
struct ScenarioRows {
  bool plain = false, optimized = false, global = false;
  bool has(ScenarioRow r) const {
    return r == ScenarioRow::Plain ? plain : r == ScenarioRow::Optimized ? optimized : global;
  }
};

/// One key of a scenario, everything about it in one entry: its name (as in the file; the flag is
/// "--" + name), kind, help text, group, whether a file must give it, how it is set, its own check
/// and its echo in the result's resolved scenario. The setters and the check throw InputError naming
/// the key: from_toml as written in the file ("name: ..."), from_text and the check as a flag
/// ("--name: ...", located_key_message renames a key the file gave). Checks that involve several
/// keys or the robot are made where the problem is built (build_scenario).
struct ScenarioKey {
  std::string name;
  KeyKind kind;
  std::string help;
  std::string default_text;  ///< shown in a command's help; empty: none shown
  std::function<void(ScenarioKeys&, const toml::node&)> from_toml;
  std::function<void(ScenarioKeys&, const std::string&)> from_text;  ///< lists: comma-separated
  KeyGroup group = KeyGroup::Planner;
  bool required = false;  ///< a scenario file must give it (required_scenario_keys)
  /// The key's own check (a range, a name among the known ones); null: none beyond its kind.
  std::function<void(const ScenarioKeys&)> check;
  /// Writes the key into the resolved scenario of the result (the "scenario" object of
  /// scenario_json); null: the key is not echoed.
  std::function<void(const Scenario&, nlohmann::json&)> echo;
  /// Where the key acts: "" when it changes the run these keys describe, else why it does not ("acts
  /// on the global run only, and this run has none (global = false)"); null: everywhere. A key given
  /// as an override (a flag, a keyword) where it does not act is refused (check_scenario_keys); a
  /// scenario file may hold it, since a file serves several jobs.
  std::function<std::string(const ScenarioKeys&)> acts;
  /// The rows of the main job whose run does not take the key as set (given the other keys: a mode
  /// of the optimized run, a key of the other task, a key of the global run); null: every row takes
  /// it. The plain row is the run without optimization: the keys that make the optimization (task,
  /// baseline-task, gain, objective) are not counted as skipping a row. keys_not_applied lists them.
  std::function<ScenarioRows(const ScenarioKeys&)> skips;

  // building the table: key(...).in(KeyGroup::Robot).needed().checked(f).echoed(f).acting(f)
  ScenarioKey& in(KeyGroup g) {
    group = g;
    return *this;
  }
  ScenarioKey& needed() {
    required = true;
    return *this;
  }
  ScenarioKey& checked(std::function<void(const ScenarioKeys&)> f) {
    check = std::move(f);
    return *this;
  }
  ScenarioKey& echoed(std::function<void(const Scenario&, nlohmann::json&)> f) {
    echo = std::move(f);
    return *this;
  }
  ScenarioKey& acting(std::function<std::string(const ScenarioKeys&)> f) {
    acts = std::move(f);
    return *this;
  }
  ScenarioKey& skipping(std::function<ScenarioRows(const ScenarioKeys&)> f) {
    skips = std::move(f);
    return *this;
  }
};

/// Every key, in the order a command lists them.
const std::vector<ScenarioKey>& scenario_keys();
/// The key named `name`, or null.
const ScenarioKey* find_scenario_key(const std::string& name);

/// The keys the scenario sets (ScenarioKeys::given) that the run of `row` does not take
/// (ScenarioKey::skips), in the table's order: what a row's note says does not apply to it.
std::vector<std::string> keys_not_applied(const ScenarioKeys& keys, ScenarioRow row);

/// Keys a scenario file must name (the others have defaults): the table's required keys.
const std::vector<std::string>& required_scenario_keys();
/// The names of the keys of `groups`, in the table's order.
std::set<std::string> scenario_key_names(std::initializer_list<KeyGroup> groups);
/// The known key nearest to `name` by edit distance (for "did you mean"), or "" when none is close
/// (more than a third of the name's letters apart).
std::string nearest_scenario_key(const std::string& name);

/// Reads a scenario file: every key and the [uncertainty] table (kept, parsed by uncertainty_spec).
/// `extra_keys`: further keys the caller allows (a command's output keys), kept as text in
/// ScenarioKeys::extra (a list joined with commas). InputError "scenario FILE: unknown key 'k'",
/// "scenario FILE:LINE: <TOML error>", or naming the key.
ScenarioKeys read_scenario_file(const std::string& path, const std::set<std::string>& extra_keys = {});
/// The same from text (`where` names it in messages; `file` is empty: a built-in scenario).
ScenarioKeys read_scenario_text(const std::string& text, const std::string& where,
                                const std::string& file = "", const std::set<std::string>& extra_keys = {});
/// Sets key `name` from text, as an override (a flag overrides the file). InputError naming the key.
void override_scenario_key(ScenarioKeys& keys, const std::string& name, const std::string& text);
/// Runs every key's own check (ScenarioKey::check; build_scenario does). InputError naming the key.
void check_scenario_keys(const ScenarioKeys& keys);
/// The line of key `name` in the scenario file (0: not in the file, or overridden by a flag).
long scenario_key_line(const ScenarioKeys& keys, const std::string& name);
/// A message that starts with a key's flag ("--duration: ..."), located in the file when the file
/// gave that key, which it then names as written there: "scenario FILE:LINE: duration: ...".
/// Unchanged otherwise.
std::string located_key_message(const ScenarioKeys& keys, const std::string& message);

struct SceneGeometry;  // scenario/geometry.hpp

/// How much of the problem build_scenario resolves.
enum class ScenarioScope {
  /// The whole problem of the main job (jobs/scenario_run.hpp): a file names the required keys, the
  /// contact law is one law at a positive approach speed, the tasks, options, shapes are built.
  Run,
  /// The robot at its start configuration, the target and the contact law, what the one-configuration
  /// jobs evaluate (inspect, contact, map, detumble): every key's own check first, the keys only the main
  /// job needs are not required, the law is kept as given (contact takes 'all'), the approach speed
  /// only finite (its sign is the job's to judge). The rest of a Run scenario is left at its defaults.
  Configuration,
};

/// A validated scenario: the robot, the capture problem, the tasks of the optimized and the plain
/// run, the optimized run's options (the plain run uses gain 0) and the global run's settings. With
/// ScenarioScope::Configuration: the robot, its start state, the target and the contact law only
/// (model, problem.frame, problem.base, problem.theta, problem.target, problem.contact, problem.law,
/// problem.approach_speed, report, keys).
struct Scenario {
  ScenarioKeys keys;  ///< as resolved (the URDF path relative to the scenario file)
  std::string where;  ///< "scenario FILE" or "built-in scenario"
  bool builtin = false;
  ScenarioScope scope = ScenarioScope::Run;  ///< what is resolved (resolve_run completes a Configuration)
  std::unique_ptr<Model> model;
  CaptureProblem problem;  ///< problem.model points to *model
  CaptureTask task, baseline_task;
  CaptureOptions capture;
  UrdfReport report;                                  ///< what the loader did to the file
  GlobalObjective objective = GlobalObjective::Mass;  ///< the global run's objective
  std::uint64_t seed = 1;                             ///< the global search's seed
  bool hold_base_attitude =
      false;  ///< base-attitude = hold: the optimized run's CaptureOptions::hold_base_attitude
  /// Multibody reference: per-joint PD gains holding the pre-contact rates (N m/rad, N m s/rad; size n).
  Eigen::VectorXd joint_stiffness, joint_damping;
  std::shared_ptr<const SceneGeometry> geometry;  ///< shapes and clearance; null: none given
  /// The joint models of the contact (contact-joints, armature; algorithm/joint_models.hpp); 'all'
  /// (contact: each model in turn) gives free. InputError naming the key (located in the file when the
  /// file gave it).
  ContactJoints contact_joints() const;
  /// contact-joints = all: the job contact evaluates each joint model in turn.
  bool all_joint_models() const { return keys.contact_joints == "all"; }
};

/// A URDF given as text for a built-in scenario whose `urdf` key names it (not read from disk).
struct EmbeddedUrdf {
  std::string name;    ///< the value of the urdf key it stands for ("paper_3dof.urdf")
  std::string source;  ///< how messages name it
  std::string xml;
};

/// Called with the loader's report as soon as the robot is loaded (a command warns about every repair).
using UrdfReportCallback = std::function<void(const UrdfReport&)>;

/// Checks the keys and builds the problem of `scope`; a URDF path of the file is relative to the file.
/// Run: a file must name required_scenario_keys(). Configuration: every key's own check
/// (ScenarioKey::check: a file's keys for other jobs too) before the robot is loaded. `on_load`: called
/// with the loader's report (Configuration only). InputError naming the file or the key (located in the
/// file when the file gave it); ModelError from the loader.
Scenario build_scenario(ScenarioKeys keys, const EmbeddedUrdf* embedded = nullptr,
                        ScenarioScope scope = ScenarioScope::Run, const UrdfReportCallback& on_load = {});
/// Resolves the rest of a Configuration scenario for the main job (the required keys, the contact law
/// and speed, tasks, options, shapes) without loading the robot again, as build_scenario(Run) would;
/// nothing to do for a Run scenario. InputError naming the file or the key.
void resolve_run(Scenario& sc, const EmbeddedUrdf* embedded = nullptr);
/// read_scenario_file + build_scenario.
Scenario load_scenario(const std::string& path);

/// The [uncertainty] table of the scenario (read with the file). InputError naming the key
/// ("uncertainty.spin.std: ...") or "WHERE: no [uncertainty] table". `samples`, `seed`: overrides
/// (the table's values are still checked).
UncertaintySpec uncertainty_spec(const ScenarioKeys& keys, std::optional<std::uint64_t> samples = {},
                                 std::optional<std::uint64_t> seed = {});

}  // namespace ffsr

#include "ffsr/scenario/geometry.hpp"
#include "ffsr/scenario/detail/values.hpp"
#include "ffsr/scenario/detail/keys.hpp"
#include "ffsr/scenario/detail/reader.hpp"
#include "ffsr/scenario/detail/scenario.hxx"
#include "ffsr/scenario/detail/uncertainty_table.hpp"
