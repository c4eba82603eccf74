// ffsr/scenario/detail/scenario.hxx -- bodies of ffsr/scenario/scenario.hpp: the model's load keys and the
// validation that builds the problem. The value parsers are in values.hpp, the key table and
// the reader in keys.hpp, the [uncertainty] table in uncertainty_table.hpp.
#pragma once

namespace ffsr {

// --- the model's load keys -----------------------------------------------------------------------------

namespace detail {

/// The symmetric inertia matrix of Ixx,Iyy,Izz or Ixx,Iyy,Izz,Ixy,Ixz,Iyz (the order of the
/// inertia keys; 3 or 6 values, checked by the caller).
inline Matrix3 inertia_from_components(const std::vector<double>& I) {
  Matrix3 m = Matrix3::Zero();
  m.diagonal() << I[0], I[1], I[2];
  if (I.size() == 6) {
    m(0, 1) = m(1, 0) = I[3];
    m(0, 2) = m(2, 0) = I[4];
    m(1, 2) = m(2, 1) = I[5];
  }
  return m;
}

/// The contact normal of a target (normalized; a zero vector is refused under `--normal`) and the
/// target's own checks, whose message is prefixed with `label` (the keys the checks speak of).
inline void finish_target(Target& t, const Vector3& normal, const char* label) {
  if (normal.norm() < 1e-12) throw InputError("--normal: the contact normal must be a non-zero vector");
  t.normal = normal.normalized();
  try {
    t.validate("target");
  } catch (const InputError& e) {
    throw InputError(str(label, ": ", e.what()));
  }
}

inline Vector3 vec3_or_zero(const std::vector<double>& v, const char* key) {
  if (v.empty()) return Vector3::Zero();
  if (v.size() != 3) throw InputError(str(key, ": expected 3 numbers, got ", v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(str(key, ": values must be finite, got ", x));
  return {v[0], v[1], v[2]};
}

inline Bus bus_of(const ModelLoadKeys& k) {
  if (!std::isfinite(k.bus_mass) || k.bus_mass <= 0)
    throw InputError(str("--bus-mass: must be positive and finite, got ", k.bus_mass));
  if (k.bus_inertia.size() != 3 && k.bus_inertia.size() != 6)
    throw InputError(
        str("--bus-inertia: expected 3 or 6 numbers with --bus-mass, got ", k.bus_inertia.size()));
  Bus bus;
  bus.mass = k.bus_mass;
  for (double x : k.bus_inertia)
    if (!std::isfinite(x)) throw InputError(str("--bus-inertia: values must be finite, got ", x));
  bus.inertia = inertia_from_components(k.bus_inertia);
  bus.com = vec3_or_zero(k.bus_com, "--bus-com");
  bus.mount = Pose::from_xyz_rpy(vec3_or_zero(k.mount_xyz, "--mount-xyz"),
                                 vec3_or_zero(k.mount_rpy_deg, "--mount-rpy-deg") * (M_PI / 180.0));
  return bus;
}

inline std::pair<std::string, double> lock_of(const std::string& item) {
  const size_t eq = item.rfind('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
    throw InputError(str("--lock-joints: '", item, "' is not name=value"));
  const std::string value = item.substr(eq + 1);
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(value.c_str(), &end);
  if (end != value.c_str() + value.size() || !std::isfinite(x) || errno == ERANGE)
    throw InputError(str("--lock-joints: '", item, "': the value is not a finite number"));
  return {item.substr(0, eq), x};
}

}  // namespace detail

inline UrdfOptions ModelLoadKeys::build(const std::string& end_effector) const {
  using detail::str;
  UrdfOptions u;
  u.end_effector = end_effector;
  const bool has_bus = given.count("bus-mass") > 0;
  for (const char* key : {"bus-inertia", "bus-com", "mount-xyz", "mount-rpy-deg"})
    if (given.count(key) && !has_bus)
      throw InputError(str("--", key, ": needs --bus-mass (the mount keys describe a spacecraft bus)"));
  if (has_bus) u.bus = detail::bus_of(*this);
  for (const std::string& item : lock_joints) u.locks.push_back(detail::lock_of(item));
  try {
    u.inertia_repair = parse_inertia_repair(inertia_repair);
  } catch (const InputError& e) {
    throw InputError(str("--", e.what()));
  }
  if (!std::isfinite(min_mass) || min_mass < 0)
    throw InputError(str("--min-mass: must be >= 0, got ", min_mass));
  if (!std::isfinite(min_inertia) || min_inertia < 0)
    throw InputError(str("--min-inertia: must be >= 0, got ", min_inertia));
  u.min_mass = min_mass;
  u.min_inertia = min_inertia;
  if (!end_effector_offset.empty()) {
    if (end_effector_offset.size() != 3)
      throw InputError(
          str("--end-effector-offset: expected 3 finite numbers, got ", end_effector_offset.size()));
    u.end_effector_offset = detail::vec3_or_zero(end_effector_offset, "--end-effector-offset");
  }
  return u;
}

// --- the post-capture run's settings ---------------------------------------------------------------------

inline DetumbleSettings detumble_settings(const ScenarioKeys& k, const Model& model) {
  using detail::str;
  for (const ScenarioKey& key : scenario_keys()) {  // a Detumble key given where it does not act
    if (key.group != KeyGroup::Detumble || !key.acts || !k.given.count(key.name)) continue;
    const std::string why = key.acts(k);
    if (!why.empty()) throw InputError(str("--", key.name, ": ", why));
  }
  DetumbleSettings s;
  DetumbleLimits& l = s.limits;
  if (k.joint_torque_limit.empty()) {
    l.joint_torque.resize(model.n());
    for (int j = 0; j < model.n(); ++j) {
      l.joint_torque(j) = model.joint(j).effort;
      if (!(l.joint_torque(j) > 0))
        throw InputError(
            str("--joint-torque-limit: not given, and the URDF gives no <limit effort> for joint '",
                model.joint(j).name, "'"));
    }
  } else {
    l.joint_torque = per_joint_values(k.joint_torque_limit, model, "--joint-torque-limit");
  }
  const auto needed = [&k](const char* name, double value) {
    if (!k.given.count(name))
      throw InputError(str("--", name, ": needed with base-actuator = ", k.base_actuator));
    return value;
  };
  const std::optional<BaseActuator> actuator = find_base_actuator(k.base_actuator);  // its parsing
  if (!actuator)  // keys the table has not checked
    throw InputError(
        str("--base-actuator: expected ", base_actuator_names(), ", got '", k.base_actuator, "'"));
  l.actuator = *actuator;
  if (l.actuator == BaseActuator::ReactionWheels) {
    l.wheel_torque = needed("wheel-torque", k.wheel_torque);
    l.wheel_momentum = needed("wheel-momentum", k.wheel_momentum);
  } else if (l.actuator == BaseActuator::Thrusters) {
    l.thruster_force = needed("thruster-force", k.thruster_force);
    l.thruster_torque = needed("thruster-torque", k.thruster_torque);
  }
  if (k.given.count("gripper-force-limit")) l.gripper_force = k.gripper_force_limit;
  if (k.given.count("gripper-moment-limit")) l.gripper_moment = k.gripper_moment_limit;
  s.options.rest_rate = k.rest_rate_deg * M_PI / 180.0;
  s.options.stop_stack_spin = k.stop_stack_spin;
  s.options.max_decay = k.detumble_max_decay;
  s.options.max_base_decay = k.detumble_max_base_decay;
  s.run.tick = k.detumble_tick;
  s.run.horizon = k.detumble_horizon;
  s.run.dwell = k.detumble_dwell;
  return s;
}

inline bool holds_target(const ScenarioKeys& k) { return k.grasp_after == "held"; }

inline DetumbleState held_start_state(const ScenarioKeys& k, const Model& model, const BasePose& base,
                                      const Eigen::VectorXd& theta) {
  using detail::str;
  // each value is checked by its key (finite; three for the base's): the joints' count needs the robot
  DetumbleState s{base, theta, Eigen::VectorXd::Zero(model.nv()), Vector3::Zero()};
  constexpr double rad = M_PI / 180.0;
  if (k.given.count("start-base-velocity"))
    s.v.head<3>() = detail::vec3_or_zero(k.start_base_velocity, "--start-base-velocity");
  if (k.given.count("start-base-angular-velocity-deg"))
    s.v.segment<3>(3) =
        detail::vec3_or_zero(k.start_base_angular_velocity_deg, "--start-base-angular-velocity-deg") * rad;
  if (!k.given.count("start-joint-rates-deg")) return s;
  const std::vector<double>& rates = k.start_joint_rates_deg;
  if (rates.size() != static_cast<size_t>(model.n())) {
    std::string names;
    for (const auto& name : model.joint_names()) names += (names.empty() ? "" : ", ") + name;
    throw InputError(str("--start-joint-rates-deg: got ", rates.size(), " rates, the robot has ", model.n(),
                         " joints (", names, ")"));
  }
  s.v.tail(model.n()) = Eigen::Map<const Eigen::VectorXd>(rates.data(), model.n()) * rad;
  return s;
}

// --- validation ------------------------------------------------------------------------------------------

namespace detail {

inline Vector3 vec3(const std::vector<double>& v, const char* key) {
  if (v.size() != 3) throw InputError(str("--", key, ": expected 3 numbers, got ", v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(str("--", key, ": values must be finite, got ", x));
  return {v[0], v[1], v[2]};
}

inline Matrix3 rpy_deg(const std::vector<double>& v, const char* key) {
  return rotation_from_rpy(vec3(v, key) * (M_PI / 180.0));
}

inline CaptureTask task_of(const std::string& kind, const ScenarioKeys& k, const char* key) {
  CaptureTask t;
  const std::string& axes = k.task_axes;
  if (kind == "position") {
    t.kind = CaptureTask::Kind::Position;
    if (axes.empty() || axes.find_first_not_of("xyz") != std::string::npos)
      throw InputError(str("--task-axes: expected letters from 'xyz' (for example 'xy'), got '", axes, "'"));
    t.axes = {axes.find('x') != std::string::npos, axes.find('y') != std::string::npos,
              axes.find('z') != std::string::npos};
  } else if (kind == "pose") {
    t.kind = CaptureTask::Kind::Pose;
    if (!k.final_rpy_deg.empty()) t.final_orientation = rpy_deg(k.final_rpy_deg, "final-rpy-deg");
  } else {
    throw InputError(str("--", key, ": unknown task '", kind, "'; expected 'position' or 'pose'"));
  }
  return t;
}

/// The robot: the built-in URDF text or the file (relative to the scenario file).
inline std::unique_ptr<Model> model_of(ScenarioKeys& k, const EmbeddedUrdf* embedded, UrdfReport& report) {
  const UrdfOptions options = k.load.build(k.end_effector);
  const bool from_command_line = k.overridden.count("urdf") > 0;
  if (k.file.empty() && embedded && !from_command_line && k.urdf == embedded->name)
    return std::make_unique<Model>(model_from_urdf_string(embedded->xml, embedded->source, options, &report));
  const size_t slash = k.file.find_last_of('/');
  if (!k.file.empty() && !from_command_line && !k.urdf_resolved && !k.urdf.empty() && k.urdf.front() != '/' &&
      slash != std::string::npos) {
    k.urdf = k.file.substr(0, slash + 1) + k.urdf;
    k.urdf_resolved = true;
  }
  return std::make_unique<Model>(model_from_urdf_file(k.urdf, options, &report));
}

/// The start state (Eq. 1's q at t = 0).
inline void start_of(const ScenarioKeys& k, const Model& model, CaptureProblem& pb) {
  if (static_cast<int>(k.joints_deg.size()) != model.n()) {
    std::string names;
    for (const auto& n : model.joint_names()) names += (names.empty() ? "" : ", ") + n;
    if (k.joints_deg.empty() && k.overridden.count("urdf"))  // a robot given by its URDF alone
      throw InputError(str("--joints-deg: required with --urdf (the robot's ", model.n(),
                           " joint angles in degrees, URDF tree order: ", names, ")"));
    throw InputError(str("--joints-deg: got ", k.joints_deg.size(), " angles, the robot has ", model.n(),
                         " joints (", names, ")"));
  }
  pb.theta = Eigen::Map<const Eigen::VectorXd>(k.joints_deg.data(), model.n()) * (M_PI / 180.0);
  for (double x : k.joints_deg) finite(x, "joints-deg");
  pb.base.position = vec3(k.base_position, "base-position");
  pb.base.orientation = Quaternion(rpy_deg(k.base_rpy_deg, "base-rpy-deg"));
}

inline Target target_of(const ScenarioKeys& k) {
  Target t;
  t.mass = finite(k.target_mass, "target-mass");
  const auto& I = k.target_inertia;
  if (I.size() != 3 && I.size() != 6)
    throw InputError(str("--target-inertia: expected 3 or 6 numbers, got ", I.size()));
  for (double x : I)
    if (!std::isfinite(x)) throw InputError(str("--target-inertia: values must be finite, got ", x));
  t.inertia = inertia_from_components(I);
  t.position = vec3(k.target_position, "target-position");
  t.attitude = Quaternion(rpy_deg(k.target_rpy_deg, "target-rpy-deg"));
  if (holds_target(k) && !k.given.count("target-angular-velocity-deg") && !k.given.count("contact-offset") &&
      !k.given.count("normal")) {  // no capture: the target moves with the gripper, touches nowhere
    try {
      t.validate("target");
    } catch (const InputError& e) {
      throw InputError(str("--target-mass/--target-inertia: ", e.what()));
    }
    return t;
  }
  t.angular_velocity = vec3(k.target_angular_velocity_deg, "target-angular-velocity-deg") * (M_PI / 180.0);
  t.velocity = vec3(k.target_velocity, "target-velocity");
  t.contact_offset = vec3(k.contact_offset, "contact-offset");
  finish_target(t, vec3(k.normal, "normal"), "--target-mass/--target-inertia");
  return t;
}

inline void contact_of(const ScenarioKeys& k, CaptureProblem& pb) {
  pb.contact = {finite(k.stiffness, "stiffness"), finite(k.exponent, "exponent"),
                finite(k.restitution, "restitution")};
  try {
    validate(pb.contact, "contact");
  } catch (const InputError& e) {
    throw InputError(str("--stiffness/--exponent/--restitution: ", e.what()));
  }
  try {
    make_contact_law(k.model, pb.contact, 1.0);  // an unknown model lists the laws
  } catch (const InputError& e) {
    throw InputError(str("--model: ", e.what()));
  }
  pb.law = k.model;
  pb.approach_speed = finite(k.approach_speed, "approach-speed");
  if (pb.approach_speed <= 0)
    throw InputError(str("--approach-speed: must be positive, got ", pb.approach_speed));
}

inline CaptureOptions capture_of(const ScenarioKeys& k) {
  CaptureOptions opt;
  opt.duration = finite(k.duration, "duration");
  opt.step = finite(k.step, "step");
  opt.gain = finite(k.gain, "gain");
  opt.feedback = finite(k.feedback, "feedback");
  opt.tolerance = finite(k.tolerance, "tolerance");
  opt.orientation_tolerance = finite(k.orientation_tolerance_deg, "orientation-tolerance-deg") * M_PI / 180.0;
  if (k.duration <= 0) throw InputError(str("--duration: must be positive, got ", k.duration));
  if (k.step <= 0 || k.step > k.duration)
    throw InputError(str("--step: must be in (0, duration], got ", k.step));
  if (k.tolerance <= 0) throw InputError(str("--tolerance: must be positive, got ", k.tolerance));
  // multibody-force and robust-force have no gradient the paper's method could use: it descends M_ie
  const std::string& o = k.objective;
  if (o == "mass" || o == "multibody-force" || o == "robust-force")
    opt.objective = CaptureObjective::IntegratedEffectiveMass;
  else if (o == "exact-force")
    opt.objective = CaptureObjective::ExactMaxForce;
  else
    throw InputError(str("--objective: unknown objective '", o,
                         "'; expected 'mass', 'exact-force', 'multibody-force' or 'robust-force'"));
  if (o == "robust-force" && k.file.empty())
    throw InputError(
        "--objective: robust-force needs a scenario file (--config) with an [uncertainty] table");
  return opt;
}

/// base-attitude: free (false) or hold (true); InputError naming the key for another mode or when the
/// optimized run's task and the held base-attitude rows leave the objective no joint (base_attitude.hpp).
inline bool base_attitude_of(const ScenarioKeys& k, const Model& model, const CaptureProblem& pb,
                             const CaptureTask& task, double gain) {
  if (k.base_attitude == "free") return false;
  if (k.base_attitude != "hold")
    throw InputError(str("--base-attitude: unknown mode '", k.base_attitude, "'; expected 'free' or 'hold'"));
  Data data(model);
  const int r = static_cast<int>(base_attitude_directions(model, data, pb.base, pb.theta, pb.frame).cols());
  const int needed = joints_needed_to_hold(task.rows(), r, gain != 0.0);
  if (needed > model.n())
    throw InputError(
        str("--base-attitude: hold takes ", task.rows(), " task rows + ", r,
            r == 1 ? " base-attitude row = " : " base-attitude rows = ", task.rows() + r, " of the robot's ",
            model.n(), " joints: ",
            gain != 0.0 ? "no freedom left for the objective (it needs " : "too few joints (it needs ",
            needed, " joints",
            gain != 0.0 && task.rows() + r <= model.n() ? "; gain = 0 tracks without optimizing)" : ")"));
  return true;
}

inline GlobalObjective global_objective_of(const std::string& name) {
  return name == "exact-force"       ? GlobalObjective::ExactForce
         : name == "multibody-force" ? GlobalObjective::MultibodyForce
         : name == "robust-force"    ? GlobalObjective::RobustForce
                                     : GlobalObjective::Mass;
}

}  // namespace detail

namespace detail {

/// The robot, its start state and the target (both scopes).
inline void build_robot(Scenario& sc, ScenarioKeys& k, const EmbeddedUrdf* embedded,
                        const UrdfReportCallback& on_load) {
  sc.model = model_of(k, embedded, sc.report);
  if (on_load) on_load(sc.report);
  const Model& model = *sc.model;
  CaptureProblem& pb = sc.problem;
  pb.model = sc.model.get();
  pb.frame = model.end_effector();
  start_of(k, model, pb);
  pb.target = target_of(k);
}

/// The rest of the main job's problem: contact, tasks and options (build_scenario without the file's
/// checks and the shapes). InputError naming the key.
inline void build_run(Scenario& sc, ScenarioKeys& k) {
  const Model& model = *sc.model;
  CaptureProblem& pb = sc.problem;
  contact_of(k, pb);
  sc.task = task_of(k.task, k, "task");
  sc.baseline_task = k.baseline_task.empty() ? sc.task : task_of(k.baseline_task, k, "baseline-task");
  sc.capture = capture_of(k);
  sc.objective = global_objective_of(k.objective);
  sc.seed = seed_of(k.seed);
  pb.joints = contact_joints_of(k.contact_joints, k.armature, model);  // joint models of the contact
  sc.joint_stiffness = per_joint_values(k.joint_stiffness, model, "--joint-stiffness");
  sc.joint_damping = per_joint_values(k.joint_damping, model, "--joint-damping");
  check_scenario_keys(k);  // each key's own check (the key table)
  if (sc.capture.gain != 0.0 && sc.task.rows() >= model.n())
    throw InputError(str("--gain: the ", k.task, " task has ", sc.task.rows(), " rows and the robot ",
                         model.n(),
                         " joints: no null space to optimize in (set gain = 0 or constrain fewer axes)"));
  sc.hold_base_attitude = base_attitude_of(k, model, pb, sc.task, sc.capture.gain);
  sc.scope = ScenarioScope::Run;
}

/// The contact law of a Configuration scenario: its parameters checked, the law's name as given (the
/// job contact takes 'all'), the approach speed finite.
inline void configuration_contact_of(const ScenarioKeys& k, CaptureProblem& pb) {
  pb.contact = {k.stiffness, k.exponent, k.restitution};  // validate names a non-finite value
  try {
    validate(pb.contact, "contact");
  } catch (const InputError& e) {
    throw InputError(std::string("--stiffness/--exponent/--restitution: ") + e.what());
  }
  pb.law = k.model;
  pb.approach_speed = finite(k.approach_speed, "approach-speed");
}

/// A file must name the required keys (the main job's).
inline void require_scenario_keys(const ScenarioKeys& k, const std::string& where) {
  if (!k.file.empty())
    for (const std::string& key : required_scenario_keys())
      if (!k.given.count(key)) throw InputError(str(where, ": missing key '", key, "'"));
}

/// The shapes and the clearance of a Run scenario.
inline void build_geometry(Scenario& sc, const EmbeddedUrdf* embedded) {
  try {
    sc.geometry = scenario_geometry(sc, embedded);
  } catch (const InputError& e) {
    throw InputError(located_key_message(sc.keys, e.what()));
  }
}

}  // namespace detail

inline ContactJoints Scenario::contact_joints() const {
  try {  // located in the file when the file gave the key
    const JointModel m =
        all_joint_models() ? JointModel::Free : parse_joint_model(keys.contact_joints, "--contact-joints");
    return {m, per_joint_values(keys.armature, *model, "--armature")};
  } catch (const InputError& e) {
    throw InputError(located_key_message(keys, e.what()));
  }
}

inline Scenario build_scenario(ScenarioKeys k, const EmbeddedUrdf* embedded, ScenarioScope scope,
                               const UrdfReportCallback& on_load) {
  using namespace detail;
  Scenario sc;
  sc.builtin = k.file.empty();
  sc.where =
      k.where.empty() ? (sc.builtin ? std::string("built-in scenario") : "scenario " + k.file) : k.where;
  sc.scope = scope;
  if (scope == ScenarioScope::Run) require_scenario_keys(k, sc.where);
  // an error of a key the file gave names the file and the key's line
  try {
    if (scope == ScenarioScope::Configuration) {
      for (const ScenarioKey& key : scenario_keys())  // every key read is checked, those of other jobs too
        if (key.check) key.check(k);
      build_robot(sc, k, embedded, on_load);
      if (!holds_target(k) || k.given.count("model") || k.given.count("stiffness"))  // held: no capture
        configuration_contact_of(k, sc.problem);
    } else {
      build_robot(sc, k, embedded, nullptr);
      build_run(sc, k);
    }
  } catch (const InputError& e) {
    throw InputError(located_key_message(k, e.what()));
  }
  sc.keys = std::move(k);
  if (scope == ScenarioScope::Run) build_geometry(sc, embedded);
  return sc;
}

inline void resolve_run(Scenario& sc, const EmbeddedUrdf* embedded) {
  using namespace detail;
  if (sc.scope == ScenarioScope::Run) return;
  require_scenario_keys(sc.keys, sc.where);
  try {
    build_run(sc, sc.keys);
  } catch (const InputError& e) {
    throw InputError(located_key_message(sc.keys, e.what()));
  }
  build_geometry(sc, embedded);
}

inline Scenario load_scenario(const std::string& path) { return build_scenario(read_scenario_file(path)); }
}  // namespace ffsr
