// ffsr/io/detail/scenario.hxx -- bodies of ffsr/io/scenario.hpp: the value parsers (one per kind,
// from a TOML node and from text), the key table, the reader, the [uncertainty] table and the
// validation that builds the problem.
#pragma once

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <type_traits>

namespace ffsr {
namespace detail {

// --- one parser per kind of value ------------------------------------------------------------------

inline std::string trimmed(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

/// A number written as text; NaN and infinities written as such pass (the validation names them), a
/// finite number too large for a double ("1e999") does not.
inline double number_from_text(const std::string& text, const std::string& key, const std::string& in = "") {
  const std::string t = trimmed(text);
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(t.c_str(), &end);
  const std::string within = in.empty() ? "" : " (in '" + in + "')";
  if (t.empty() || end != t.c_str() + t.size())
    throw InputError(str(key, ": '", t, "' is not a number", within));
  if (errno == ERANGE && std::isinf(x))
    throw InputError(str(key, ": '", t, "' is out of the range of a double", within));
  return x;
}

inline std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::string item;
  std::stringstream ss(text);
  while (std::getline(ss, item, ',')) items.push_back(item);
  return items;
}

inline std::vector<double> numbers_from_text(const std::string& text, const std::string& key) {
  if (text.empty()) throw InputError(str(key, ": expected comma-separated numbers, got an empty value"));
  if (text.back() == ',') throw InputError(str(key, ": trailing comma in '", text, "'"));
  std::vector<double> out;
  for (const std::string& item : split_list(text)) out.push_back(number_from_text(item, key, text));
  return out;
}

inline long long integer_from_text(const std::string& text, const std::string& key) {
  const std::string t = trimmed(text);
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(t.c_str(), &end, 10);
  if (t.empty() || end != t.c_str() + t.size() || errno == ERANGE || x < INT_MIN || x > INT_MAX)
    throw InputError(str(key, ": '", t, "' is not an integer"));
  return x;
}

inline bool boolean_from_text(const std::string& text, const std::string& key) {
  std::string t = trimmed(text);
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* yes : {"true", "1", "on", "yes", "y", "t", "enable", "+"})
    if (t == yes) return true;
  for (const char* no : {"false", "0", "off", "no", "n", "f", "disable", "-"})
    if (t == no) return false;
  throw InputError(str(key, ": expected true or false, got '", text, "'"));
}

/// A scalar node as text (a text key takes a number or a boolean as written).
inline std::optional<std::string> text_of(const toml::node& n) {
  if (auto s = n.value_exact<std::string>()) return *s;
  if (auto i = n.value_exact<int64_t>()) return std::to_string(*i);
  if (auto d = n.value_exact<double>()) {
    std::ostringstream os;
    os << std::setprecision(17) << *d;
    return os.str();
  }
  if (auto b = n.value_exact<bool>()) return std::string(*b ? "true" : "false");
  return std::nullopt;
}

inline double number_of(const toml::node& n, const std::string& key) {
  if (auto i = n.value_exact<int64_t>()) return static_cast<double>(*i);
  if (auto d = n.value_exact<double>()) return *d;
  if (auto s = n.value_exact<std::string>()) return number_from_text(*s, key);
  throw InputError(str(key, ": expected a number"));
}

template <class T>
T value_from_text(const std::string& text, const std::string& key) {
  if constexpr (std::is_same_v<T, std::string>) {
    return text;
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    return split_list(text);
  } else if constexpr (std::is_same_v<T, double>) {
    return number_from_text(text, key);
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    return numbers_from_text(text, key);
  } else if constexpr (std::is_same_v<T, int>) {
    return static_cast<int>(integer_from_text(text, key));
  } else {
    static_assert(std::is_same_v<T, bool>);
    return boolean_from_text(text, key);
  }
}

template <class T>
T value_from_toml(const toml::node& n, const std::string& key) {
  if constexpr (std::is_same_v<T, std::vector<double>> || std::is_same_v<T, std::vector<std::string>>) {
    if (const toml::array* a = n.as_array()) {
      T out;
      for (const toml::node& e : *a) {
        if constexpr (std::is_same_v<T, std::vector<double>>) {
          out.push_back(number_of(e, key));
        } else {
          const auto t = text_of(e);
          if (!t) throw InputError(str(key, ": expected a list of text values"));
          out.push_back(*t);
        }
      }
      return out;
    }
    if constexpr (std::is_same_v<T, std::vector<double>>)
      if (!n.is_string()) return {number_of(n, key)};
  } else if constexpr (std::is_same_v<T, double>) {
    return number_of(n, key);
  } else if constexpr (std::is_same_v<T, int>) {
    if (auto i = n.value_exact<int64_t>()) {
      if (*i < INT_MIN || *i > INT_MAX) throw InputError(str(key, ": '", *i, "' is not an integer"));
      return static_cast<int>(*i);
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    if (auto b = n.value_exact<bool>()) return *b;
  }
  const auto t = text_of(n);
  if (!t) throw InputError(str(key, ": expected a single value"));
  return value_from_text<T>(*t, key);
}

template <class T>
constexpr KeyKind kind_of() {
  if constexpr (std::is_same_v<T, std::string>) return KeyKind::Text;
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return KeyKind::Texts;
  if constexpr (std::is_same_v<T, double>) return KeyKind::Number;
  if constexpr (std::is_same_v<T, std::vector<double>>) return KeyKind::Numbers;
  if constexpr (std::is_same_v<T, int>) return KeyKind::Integer;
  return KeyKind::Boolean;
}

/// A key of member type T reached by `get`: its setters parse, store and mark the key as given.
template <class T>
ScenarioKey make_key(const char* name, T& (*get)(ScenarioKeys&), const char* help, const char* shown = "") {
  const std::string n = name, flag = std::string("--") + name;
  auto mark = [n](ScenarioKeys& k) {
    k.given.insert(n);
    k.load.given.insert(n);
  };
  return {n,
          kind_of<T>(),
          help,
          shown,
          [get, flag, mark](ScenarioKeys& k, const toml::node& node) {
            get(k) = value_from_toml<T>(node, flag);
            mark(k);
          },
          [get, flag, mark](ScenarioKeys& k, const std::string& text) {
            get(k) = value_from_text<T>(text, flag);
            mark(k);
          }};
}

// --- the keys ------------------------------------------------------------------------------------

#define FFSR_KEY(name, member, ...) \
  make_key(                         \
      name, +[](ScenarioKeys& k) -> decltype(k.member)& { return k.member; }, __VA_ARGS__)

inline std::vector<ScenarioKey> build_scenario_keys() {
  return {
      FFSR_KEY("urdf", urdf, "Robot URDF (relative to the scenario file)"),
      FFSR_KEY("end-effector", end_effector, "End-effector frame (default: the single leaf link)"),
      FFSR_KEY("bus-mass", load.bus_mass,
               "Mount the URDF on a spacecraft bus of this mass, kg (the bus is the base)"),
      FFSR_KEY("bus-inertia", load.bus_inertia,
               "Bus inertia about its centre of mass (bus frame): Ixx,Iyy,Izz[,Ixy,Ixz,Iyz], kg m^2"),
      FFSR_KEY("bus-com", load.bus_com, "Bus centre of mass in the bus frame, m (default 0,0,0)"),
      FFSR_KEY("mount-xyz", load.mount_xyz,
               "Position of the URDF's root link in the bus frame, m (default 0,0,0)"),
      FFSR_KEY("mount-rpy-deg", load.mount_rpy_deg,
               "Attitude of the URDF's root link in the bus frame, roll,pitch,yaw deg (default 0,0,0)"),
      FFSR_KEY("lock-joints", load.lock_joints,
               "Joints frozen at a value, name=value (rad or m), comma-separated"),
      FFSR_KEY("inertia-repair", load.inertia_repair,
               "Inertias breaking the triangle inequality: none (error) or balance", "none"),
      FFSR_KEY("min-mass", load.min_mass, "Links lighter than this get this mass, kg (0: off)", "0"),
      FFSR_KEY("min-inertia", load.min_inertia,
               "Principal moments below this are raised to it, kg m^2 (0: off)", "0"),
      FFSR_KEY("end-effector-offset", load.end_effector_offset,
               "Contact point in the end-effector frame, m (x,y,z)"),
      FFSR_KEY("joints-deg", joints_deg, "Initial joint angles, deg"),
      FFSR_KEY("base-position", base_position, "Initial base position, m"),
      FFSR_KEY("base-rpy-deg", base_rpy_deg, "Initial base attitude (roll, pitch, yaw), deg"),
      FFSR_KEY("target-mass", target_mass, "Target mass, kg"),
      FFSR_KEY("target-inertia", target_inertia,
               "Target inertia: Ixx,Iyy,Izz[,Ixy,Ixz,Iyz], kg m^2 (target frame)"),
      FFSR_KEY("target-position", target_position, "Target centre of mass at t = 0, m"),
      FFSR_KEY("target-rpy-deg", target_rpy_deg, "Target attitude at t = 0, deg"),
      FFSR_KEY("target-angular-velocity-deg", target_angular_velocity_deg,
               "Target spin (target frame), deg/s"),
      FFSR_KEY("target-velocity", target_velocity, "Target linear velocity, m/s"),
      FFSR_KEY("contact-offset", contact_offset,
               "r_tp: contact point from the target centre of mass (target frame), m"),
      FFSR_KEY("normal", normal, "u_n: contact normal (target frame)"),
      FFSR_KEY("model", model, "Hysteresis damping law (Table 1)"),
      FFSR_KEY("stiffness", stiffness, "K, N/m^alpha"),
      FFSR_KEY("exponent", exponent, "alpha"),
      FFSR_KEY("restitution", restitution, "c_r, 0 < c_r <= 1"),
      FFSR_KEY("approach-speed", approach_speed, "End-effector speed along the normal at the capture, m/s"),
      FFSR_KEY("task", task, "Optimized run's task: position or pose"),
      FFSR_KEY("task-axes", task_axes, "Position task: constrained inertial axes, e.g. xy", "xyz"),
      FFSR_KEY("baseline-task", baseline_task, "Plain run's task (default: the optimized run's)"),
      FFSR_KEY("final-rpy-deg", final_rpy_deg,
               "Pose task: final end-effector orientation (default: hold the initial)"),
      FFSR_KEY("duration", duration, "Task time T, s"),
      FFSR_KEY("step", step, "RK4 step, s"),
      FFSR_KEY("gain", gain, "rho of Eq. 30 (< 0 lowers the objective)"),
      FFSR_KEY("feedback", feedback, "Tracking feedback gain, 1/s", "1"),
      FFSR_KEY("tolerance", tolerance, "Required capture-point accuracy, m"),
      FFSR_KEY("orientation-tolerance-deg", orientation_tolerance_deg,
               "Pose task: required orientation accuracy, deg", "0.5"),
      FFSR_KEY(
          "objective", objective,
          "mass (M_ie, the paper's), exact-force, or multibody-force (CVODE peak; global search only, the "
          "paper's method then descends M_ie)",
          "mass"),
      FFSR_KEY("global", global, "Also run the global capture optimization (true/false)", "true"),
      FFSR_KEY("seed", seed, "Seed of the global search's random starts (non-negative integer)", "1"),
      FFSR_KEY("max-joint-rate-deg", max_joint_rate_deg,
               "Global run: largest joint rate, deg/s (> 0; default: not limited; the paper's method is not "
               "limited)"),
      FFSR_KEY("global-starts", global_starts, "Global search: random starts (>= 1)", "32"),
      FFSR_KEY(
          "max-base-rate-deg", max_base_rate_deg,
          "Global search: largest jump of the base's angular velocity at the impact, deg/s (a constraint; "
          "> 0; default: not limited; `pareto` shows the trade-off against M_ie)"),
      // the spacecraft's side: the reaction-null-space approach
      FFSR_KEY("base-attitude", base_attitude,
               "Optimized run: free, or hold (the base's angular velocity stays zero; the objective uses "
               "the freedom left)",
               "free"),
      // reconfiguration before the approach (optimize/reconfigure.hpp)
      FFSR_KEY("reconfigure", reconfigure,
               "Global run: reconfigure the arm before the approach: auto (only when the best capture "
               "configuration is not reached otherwise), always or never",
               "auto"),
      FFSR_KEY("reconfigure-duration", reconfigure_duration,
               "Global run: time of the reconfiguration, s, 0 < t < duration (default: duration / 4, longer "
               "if max-joint-rate-deg needs it)"),
      // joint models of the contact (algorithm/joint_models.hpp)
      FFSR_KEY("contact-joints", contact_joints,
               "The joints during the contact: free (the paper's), locked (one rigid body) or armature "
               "(free with the armature's reflected rotor inertia)",
               "free"),
      FFSR_KEY("armature", armature,
               "Reflected rotor inertia per joint, kg m^2 (kg for prismatic): one value or one per joint",
               "0"),
      FFSR_KEY(
          "joint-stiffness", joint_stiffness,
          "Multibody reference: joint PD stiffness holding the pre-contact rates, N m/rad (one or per joint)",
          "0"),
      FFSR_KEY("joint-damping", joint_damping,
               "Multibody reference: joint PD damping, N m s/rad (one or per joint)", "0"),
      // shapes and clearance (io/scenario_geometry.hpp, docs/geometry.md)
      FFSR_KEY("target-shape", target_shape,
               "Target's collision shape: box, sphere or cylinder (default: none)"),
      FFSR_KEY("target-size", target_size,
               "Target shape's size, m: box edge lengths; sphere radius; cylinder radius, length (along z)"),
      FFSR_KEY("target-shape-offset", target_shape_offset, "Target shape's centre in the target frame, m",
               "0,0,0"),
      FFSR_KEY("link-radius", link_radius,
               "Capsule radius of links without URDF collision primitives, m (one, or one per moving body)",
               "0.05"),
      FFSR_KEY("bus-box", bus_box,
               "The bus as a box centred on the base frame (edge lengths, m), when the URDF's "
               "base has no collision primitive"),
      FFSR_KEY("clearance", clearance,
               "Least distance the global run keeps between arm, bus and target, m (0: none)", "0"),
      FFSR_KEY("contact-exemption", contact_exemption,
               "Length of the arm before the contact point (along the links' centre lines) not checked against the target, m",
               "0.2"),
  };
}

#undef FFSR_KEY

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

inline const std::vector<std::string>& required_scenario_keys() {
  static const std::vector<std::string> keys{"urdf",
                                             "joints-deg",
                                             "target-mass",
                                             "target-inertia",
                                             "target-position",
                                             "target-angular-velocity-deg",
                                             "contact-offset",
                                             "normal",
                                             "model",
                                             "stiffness",
                                             "exponent",
                                             "restitution",
                                             "approach-speed",
                                             "task",
                                             "duration",
                                             "step",
                                             "gain",
                                             "tolerance"};
  return keys;
}

// --- the reader --------------------------------------------------------------------------------------

namespace detail {

/// A caller's key as text: a scalar as written, a list joined with commas.
inline std::string extra_text(const toml::node& v, const std::string& key) {
  if (const toml::array* a = v.as_array()) {
    std::string joined;
    for (const toml::node& e : *a) {
      const auto t = text_of(e);
      if (!t) throw InputError(str("--", key, ": expected a list of single values"));
      joined += (joined.empty() ? "" : ",") + *t;
    }
    return joined;
  }
  const auto t = text_of(v);
  if (!t) throw InputError(str("--", key, ": expected a single value"));
  return *t;
}

}  // namespace detail

inline ScenarioKeys read_scenario_text(const std::string& text, const std::string& where,
                                       const std::string& file, const std::set<std::string>& extra_keys) {
  auto root = std::make_shared<toml::table>();
  try {
    *root = toml::parse(text, file.empty() ? std::string_view{} : std::string_view{file});
  } catch (const toml::parse_error& e) {
    throw InputError(detail::str(where, ":", e.source().begin.line, ": ", e.description()));
  }
  ScenarioKeys keys;
  keys.file = file;
  keys.where = where;
  for (const auto& [k, v] : *root) {
    const std::string name(k.str());
    if (name == "uncertainty") continue;  // read by uncertainty_spec
    if (extra_keys.count(name)) {
      keys.extra[name] = detail::extra_text(v, name);
      continue;
    }
    const ScenarioKey* key = find_scenario_key(name);
    if (!key) throw InputError(detail::str(where, ": unknown key '", name, "'"));
    key->from_toml(keys, v);
  }
  keys.document = std::move(root);
  return keys;
}

inline ScenarioKeys read_scenario_file(const std::string& path, const std::set<std::string>& extra_keys) {
  const std::string where = "scenario " + path;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(detail::str(where, ": cannot open the file"));
  std::ostringstream ss;
  ss << in.rdbuf();
  return read_scenario_text(ss.str(), where, path, extra_keys);
}

inline void override_scenario_key(ScenarioKeys& keys, const std::string& name, const std::string& text) {
  const ScenarioKey* key = find_scenario_key(name);
  if (!key) throw InputError(detail::str("unknown scenario key '", name, "'"));
  key->from_text(keys, text);
  keys.overridden.insert(name);
}

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

inline nlohmann::json ModelLoadKeys::to_json() const {
  nlohmann::json j;
  auto or_zero = [](const std::vector<double>& v) { return v.empty() ? std::vector<double>{0, 0, 0} : v; };
  if (given.count("bus-mass")) {
    j["bus-mass"] = bus_mass;
    j["bus-inertia"] = bus_inertia;
    j["bus-com"] = or_zero(bus_com);
    j["mount-xyz"] = or_zero(mount_xyz);
    j["mount-rpy-deg"] = or_zero(mount_rpy_deg);
  }
  j["lock-joints"] = lock_joints;
  j["inertia-repair"] = inertia_repair;
  j["min-mass"] = min_mass;
  j["min-inertia"] = min_inertia;
  if (!end_effector_offset.empty()) j["end-effector-offset"] = end_effector_offset;
  return j;
}

// --- validation ------------------------------------------------------------------------------------------

namespace detail {

inline Vector3 vec3(const std::vector<double>& v, const char* key) {
  if (v.size() != 3) throw InputError(str("--", key, ": expected 3 numbers, got ", v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(str("--", key, ": values must be finite, got ", x));
  return {v[0], v[1], v[2]};
}

inline double finite(double x, const char* key) {
  if (!std::isfinite(x)) throw InputError(str("--", key, ": must be finite, got ", x));
  return x;
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

/// The seed as a non-negative integer (text, so that a bad value names the key).
inline std::uint64_t seed_of(const std::string& sd) {
  if (sd.empty() || sd.size() > 19 || sd.find_first_not_of("0123456789") != std::string::npos)
    throw InputError(str("--seed: expected a non-negative integer (at most 19 digits), got '", sd, "'"));
  return std::stoull(sd);
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

inline Scenario build_scenario(ScenarioKeys k, const EmbeddedUrdf* embedded) {
  using namespace detail;
  Scenario sc;
  sc.builtin = k.file.empty();
  sc.where =
      k.where.empty() ? (sc.builtin ? std::string("built-in scenario") : "scenario " + k.file) : k.where;
  if (!sc.builtin)
    for (const std::string& key : required_scenario_keys())
      if (!k.given.count(key)) throw InputError(str(sc.where, ": missing key '", key, "'"));
  sc.model = model_of(k, embedded, sc.report);
  const Model& model = *sc.model;
  CaptureProblem& pb = sc.problem;
  pb.model = sc.model.get();
  pb.frame = model.end_effector();
  start_of(k, model, pb);
  pb.target = target_of(k);
  contact_of(k, pb);
  sc.task = task_of(k.task, k, "task");
  sc.baseline_task = k.baseline_task.empty() ? sc.task : task_of(k.baseline_task, k, "baseline-task");
  sc.capture = capture_of(k);
  sc.objective = global_objective_of(k.objective);
  sc.seed = seed_of(k.seed);
  pb.joints = contact_joints_of(k.contact_joints, k.armature, model);  // joint models of the contact
  sc.joint_stiffness = per_joint_values(k.joint_stiffness, model, "--joint-stiffness");
  sc.joint_damping = per_joint_values(k.joint_damping, model, "--joint-damping");
  if (k.global_starts < 1) throw InputError(str("--global-starts: must be >= 1, got ", k.global_starts));
  if (k.given.count("max-joint-rate-deg") && !(finite(k.max_joint_rate_deg, "max-joint-rate-deg") > 0))
    throw InputError(str("--max-joint-rate-deg: must be positive, got ", k.max_joint_rate_deg));
  if (k.given.count("max-base-rate-deg") && !(finite(k.max_base_rate_deg, "max-base-rate-deg") > 0))
    throw InputError(str("--max-base-rate-deg: must be positive, got ", k.max_base_rate_deg));
  reconfigure_mode_of(k.reconfigure, "--reconfigure");
  if (k.given.count("reconfigure-duration") &&
      !(finite(k.reconfigure_duration, "reconfigure-duration") > 0 && k.reconfigure_duration < k.duration))
    throw InputError(str("--reconfigure-duration: must lie in (0, duration = ", k.duration, ") s, got ",
                         k.reconfigure_duration));
  if (sc.capture.gain != 0.0 && sc.task.rows() >= model.n())
    throw InputError(str("--gain: the ", k.task, " task has ", sc.task.rows(), " rows and the robot ",
                         model.n(),
                         " joints: no null space to optimize in (set gain = 0 or constrain fewer axes)"));
  sc.hold_base_attitude = base_attitude_of(k, model, pb, sc.task, sc.capture.gain);
  sc.keys = std::move(k);
  sc.geometry = scenario_geometry(sc, embedded);
  return sc;
}

inline Scenario load_scenario(const std::string& path) { return build_scenario(read_scenario_file(path)); }

// --- the [uncertainty] table -------------------------------------------------------------------------------

namespace detail {

inline double spread_number(const toml::node& n, const std::string& key) {
  if (auto i = n.value_exact<int64_t>()) return static_cast<double>(*i);
  if (auto d = n.value_exact<double>()) {
    if (!std::isfinite(*d)) throw InputError(str(key, ": must be finite, got ", *d));
    return *d;
  }
  throw InputError(str(key, ": expected a number"));
}

/// Exactly one of `opts` given, or InputError naming them.
inline void one_of(const std::string& key, const std::string& law,
                   std::initializer_list<std::pair<const char*, std::optional<double>>> opts) {
  int count = 0;
  std::string names;
  for (const auto& [n, v] : opts) {
    count += v.has_value();
    names += (names.empty() ? "" : " or ") + std::string(n);
  }
  if (count != 1) throw InputError(str(key, ": the ", law, " law takes exactly one of ", names));
}

inline Spread spread_of(Quantity q, const toml::table& t, const std::string& key) {
  static const std::set<std::string> known{"law", "std", "relative-std", "half-width", "relative",
                                           "min", "max", "sigma",        "angle-deg",  "axes-deg"};
  for (const auto& [k, v] : t)
    if (!known.count(std::string(k.str())))
      throw InputError(str(key, ".", k.str(),
                           ": unknown parameter; expected law, std, relative-std, half-width, ",
                           "relative, min, max, sigma, angle-deg or axes-deg"));
  const auto law = t["law"].value<std::string>();
  if (!law) throw InputError(str(key, ": missing law (normal, uniform, log-normal or cone)"));
  auto get = [&](const char* name) -> std::optional<double> {
    if (const toml::node* n = t.get(name)) return spread_number(*n, str(key, ".", name));
    return std::nullopt;
  };
  const auto sd = get("std"), rsd = get("relative-std"), hw = get("half-width"), rel = get("relative"),
             lo = get("min"), hi = get("max"), sigma = get("sigma"), angle = get("angle-deg"),
             axes = get("axes-deg");
  for (const auto& [name, v] : {std::pair{"std", sd},
                                {"relative-std", rsd},
                                {"half-width", hw},
                                {"relative", rel},
                                {"sigma", sigma},
                                {"angle-deg", angle},
                                {"axes-deg", axes}})
    if (v && *v < 0)
      throw InputError(str(key, ".", name, ": a spread must be non-negative, got ", short_number(*v)));
  // spin is given in deg/s, the library takes rad/s
  const double unit = q == Quantity::Spin ? M_PI / 180.0 : 1.0;
  Spread sp;
  if (*law == "normal") {
    sp.law = Spread::Law::Normal;
    one_of(key, *law, {{"std", sd}, {"relative-std", rsd}});
    sp.relative = rsd.has_value();
    sp.scale = sd ? *sd * unit : *rsd;
  } else if (*law == "uniform") {
    sp.law = Spread::Law::Uniform;
    const bool range = lo.has_value() && hi.has_value() && !hw && !rel;
    if (!range) one_of(key, *law, {{"half-width", hw}, {"relative", rel}});
    sp.has_range = range;
    sp.relative = rel.has_value();
    sp.scale = hw ? *hw * unit : rel ? *rel : 0.0;
  } else if (*law == "log-normal") {
    sp.law = Spread::Law::LogNormal;
    if (!sigma) throw InputError(str(key, ": the log-normal law needs sigma (standard deviation of ln x)"));
    sp.scale = *sigma;
  } else if (*law == "cone") {
    sp.law = Spread::Law::Cone;
    if (!angle) throw InputError(str(key, ": the cone law needs angle-deg (half-angle)"));
    sp.scale = *angle * M_PI / 180.0;
  } else {
    throw InputError(
        str(key, ".law: unknown law '", *law, "'; expected normal, uniform, log-normal or cone"));
  }
  if (q == Quantity::TargetInertia && sp.law != Spread::Law::Cone && !sp.relative)
    throw InputError(str(key, ": the inertia takes a relative spread (relative-std or relative)"));
  if (lo) sp.min = *lo * unit;
  if (hi) sp.max = *hi * unit;
  if (axes) sp.axes = *axes * M_PI / 180.0;
  if (axes && q != Quantity::TargetInertia)
    throw InputError(str(key, ".axes-deg: only the inertia takes it"));
  return sp;
}

/// samples or seed of the table.
inline std::uint64_t count_of(const toml::node& v, const std::string& name, const std::string& key) {
  const auto i = v.value_exact<int64_t>();
  if (!i) throw InputError(str(key, ": must be an integer"));
  if (name == "samples" && *i < 1) throw InputError(str(key, ": must be at least 1, got ", *i));
  if (name == "seed" && *i < 0) throw InputError(str(key, ": must be a non-negative integer, got ", *i));
  return static_cast<std::uint64_t>(*i);
}

}  // namespace detail

inline UncertaintySpec uncertainty_spec(const ScenarioKeys& keys, std::optional<std::uint64_t> samples,
                                        std::optional<std::uint64_t> seed) {
  using detail::str;
  const toml::node* node = keys.document ? keys.document->get("uncertainty") : nullptr;
  if (!node) throw InputError(str(keys.where, ": no [uncertainty] table"));
  const toml::table* u = node->as_table();
  if (!u) throw InputError(str(keys.where, ": 'uncertainty' must be a table"));
  UncertaintySpec spec;
  for (const auto& [k, v] : *u) {
    const std::string name(k.str());
    const std::string key = "uncertainty." + name;
    if (name == "samples" || name == "seed") {
      (name == "samples" ? spec.samples : spec.seed) = detail::count_of(v, name, key);
      continue;
    }
    const auto it = std::find(kQuantityNames.begin(), kQuantityNames.end(), name);
    if (it == kQuantityNames.end()) {
      std::string names;
      for (auto n : kQuantityNames) names += (names.empty() ? "" : ", ") + std::string(n);
      throw InputError(str(key, ": unknown uncertain quantity; expected one of ", names, ", samples, seed"));
    }
    const toml::table* t = v.as_table();
    if (!t) throw InputError(str(key, ": expected a table such as { law = \"normal\", std = 0.01 }"));
    const Quantity q = static_cast<Quantity>(it - kQuantityNames.begin());
    spec[q] = detail::spread_of(q, *t, key);
  }
  if (samples) spec.samples = *samples;
  if (seed) spec.seed = *seed;
  validate(spec);
  return spec;
}

}  // namespace ffsr
