// ffsr/scenario/detail/key_entry.hpp -- the constructor of a key-table entry (make_key) and what the
// entries of the key table (keys.hpp, detumble_keys.hpp) share: echoes of the resolved scenario, where a
// key acts, the rows of the main job a key does not act on.
#pragma once

#include "ffsr/scenario/scenario.hpp"
#include "ffsr/scenario/detail/values.hpp"

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

/// An entry of the key table bound to its ScenarioKeys member (keys.hpp, detumble_keys.hpp; #undef at
/// the end of keys.hpp).
#define FFSR_KEY(name, member, ...) \
  make_key(                         \
      name, +[](ScenarioKeys& k) -> decltype(k.member)& { return k.member; }, __VA_ARGS__)

namespace ffsr {
namespace detail {

// --- the constructor of a key-table entry --------------------------------------------------------------

template <class T>
constexpr KeyKind kind_of() {
  if constexpr (std::is_same_v<T, std::string>) return KeyKind::Text;
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return KeyKind::Texts;
  if constexpr (std::is_same_v<T, double>) return KeyKind::Number;
  if constexpr (std::is_same_v<T, std::vector<double>>) return KeyKind::Numbers;
  if constexpr (std::is_same_v<T, int>) return KeyKind::Integer;
  return KeyKind::Boolean;
}

/// A key of member type T reached by `get`: its setters parse, store and mark the key as given; its
/// echo writes the value as stored (ScenarioKey::echoed replaces it).
template <class T>
ScenarioKey make_key(const char* name, T& (*get)(ScenarioKeys&), const char* help, const char* shown = "") {
  const std::string n = name, flag = std::string("--") + name;
  auto mark = [n](ScenarioKeys& k) {
    k.given.insert(n);
    k.load.given.insert(n);
  };
  ScenarioKey key;
  key.name = n;
  key.kind = kind_of<T>();
  key.help = help;
  key.default_text = shown;
  // a value of the file names the key as written there, a flag's value the flag
  key.from_toml = [get, n, mark](ScenarioKeys& k, const toml::node& node) {
    get(k) = value_from_toml<T>(node, n);
    mark(k);
  };
  key.from_text = [get, flag, mark](ScenarioKeys& k, const std::string& text) {
    get(k) = value_from_text<T>(text, flag);
    mark(k);
  };
  // the keys are read-only here: `get` takes a mutable reference only to share one accessor
  key.echo = [get, n](const Scenario& sc, nlohmann::json& j) {
    j[n] = get(const_cast<ScenarioKeys&>(sc.keys));
  };
  return key;
}

// --- echoes of the resolved scenario that are not the value as stored -------------------------------

/// The value as stored, only when the key was given.
template <class T>
std::function<void(const Scenario&, nlohmann::json&)> echo_given(const char* name, T ScenarioKeys::*member) {
  return [name, member](const Scenario& sc, nlohmann::json& j) {
    if (sc.keys.given.count(name)) j[name] = sc.keys.*member;
  };
}

/// A key of the bus: echoed with bus-mass only; `zero`: a vector that was not given is 0,0,0.
inline std::function<void(const Scenario&, nlohmann::json&)> echo_bus(
    const char* name, std::vector<double> ModelLoadKeys::*member, bool zero = true) {
  return [name, member, zero](const Scenario& sc, nlohmann::json& j) {
    if (!sc.keys.load.given.count("bus-mass")) return;
    const std::vector<double>& v = sc.keys.load.*member;
    j[name] = v.empty() && zero ? std::vector<double>{0, 0, 0} : v;
  };
}

/// A per-joint vector as resolved by the problem (one value per joint).
inline nlohmann::json joint_values_json(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

/// A key of the shapes: echoed when the scenario uses shapes (scenario_uses_geometry).
template <class T>
std::function<void(const Scenario&, nlohmann::json&)> echo_shape(const char* name, T ScenarioKeys::*member) {
  return [name, member](const Scenario& sc, nlohmann::json& j) {
    if (scenario_uses_geometry(sc.keys)) j[name] = sc.keys.*member;
  };
}

/// "given and not a positive finite number": the check of an optional limit.
inline void check_positive_if_given(const ScenarioKeys& k, const char* name, double value) {
  if (k.given.count(name) && !(finite(value, name) > 0))
    throw InputError(str("--", name, ": must be positive, got ", value));
}

// --- where a key acts (ScenarioKey::acts): "" where it does, else why it does not -------------------

inline std::string on_the_global_run(const ScenarioKeys& k) {
  return k.global ? "" : "acts on the global run only, and this run has none (global = false)";
}

/// The plain run's task: baseline-task, or the optimized run's.
inline const std::string& plain_run_task(const ScenarioKeys& k) {
  return k.baseline_task.empty() ? k.task : k.baseline_task;
}

/// A key of one kind of task ("pose", "position"): it acts when the optimized or the plain run has it.
inline std::function<std::string(const ScenarioKeys&)> on_the_task(const char* kind) {
  return [kind](const ScenarioKeys& k) -> std::string {
    if (k.task == kind || plain_run_task(k) == kind) return "";
    return str("acts on the ", kind, " task only, and no run here has it (task = ", k.task,
               ", baseline-task = ", plain_run_task(k), ")");
  };
}

inline std::string on_the_multibody_reference(const ScenarioKeys& k) {
  return k.global && k.objective == "multibody-force"
             ? ""
             : "acts on the multibody reference only: the global run's objective multibody-force (or the "
               "contact subcommand)";
}

// --- the rows of the main job a key does not act on (ScenarioKey::skips) ------------------------------

/// A key of one kind of task ("pose", "position"): the rows whose task is the other.
inline std::function<ScenarioRows(const ScenarioKeys&)> skips_other_task(const char* kind) {
  return [kind](const ScenarioKeys& k) {
    ScenarioRows r;
    r.plain = plain_run_task(k) != kind;
    r.optimized = r.global = k.task != kind;
    return r;
  };
}

/// A key of the global run: the plain and the optimized rows.
inline ScenarioRows skips_but_global(const ScenarioKeys&) { return {true, true, false}; }

/// base-attitude = hold: the optimized run holds the base's attitude, the plain and the global run
/// do not (free acts on no row: the base of every run is free).
inline ScenarioRows skips_of_base_attitude(const ScenarioKeys& k) {
  return k.base_attitude == "hold" ? ScenarioRows{true, false, true} : ScenarioRows{};
}

/// multibody-force and robust-force: the global run's objective; the paper's method descends M_ie.
inline ScenarioRows skips_of_objective(const ScenarioKeys& k) {
  return {false, k.objective == "multibody-force" || k.objective == "robust-force", false};
}

/// The multibody reference's servo: the global run's objective multibody-force only.
inline ScenarioRows skips_but_multibody_reference(const ScenarioKeys& k) {
  return {true, true, k.objective != "multibody-force"};
}

}  // namespace detail
}  // namespace ffsr
