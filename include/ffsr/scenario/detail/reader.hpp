// ffsr/scenario/detail/reader.hpp -- the scenario file's reader over the key table (keys.hpp): TOML
// text to ScenarioKeys, a key's line in the file, messages located there, overrides as text, and the
// checks of a whole set of keys.
#pragma once

#include "ffsr/scenario/detail/keys.hpp"

#include <toml++/toml.h>

#include <fstream>
#include <set>
#include <string>

namespace ffsr {

namespace detail {

/// A caller's key as text: a scalar as written, a list joined with commas.
inline std::string extra_text(const toml::node& v, const std::string& key) {
  if (const toml::array* a = v.as_array()) {
    std::string joined;
    for (const toml::node& e : *a) {
      const auto t = text_of(e);
      if (!t) throw InputError(str(key, ": expected a list of single values"));
      joined += (joined.empty() ? "" : ",") + *t;
    }
    return joined;
  }
  const auto t = text_of(v);
  if (!t) throw InputError(str(key, ": expected a single value"));
  return *t;
}

/// "WHERE:LINE" of a node of the file (WHERE alone when toml++ gives no line).
inline std::string where_line(const std::string& where, const toml::node& n) {
  const auto line = n.source().begin.line;
  return line > 0 ? str(where, ":", line) : where;
}

/// "unknown key 'k'", with the nearest known key (of the table and the caller's) when one is close.
inline std::string unknown_key_message(const std::string& name, const std::set<std::string>& extra_keys) {
  std::vector<std::string> names(extra_keys.begin(), extra_keys.end());
  for (const ScenarioKey& k : scenario_keys()) names.push_back(k.name);
  names.push_back("uncertainty");
  const std::string near = nearest_name(name, names);
  return str("unknown key '", name, "'", near.empty() ? "" : str(" (did you mean '", near, "'?)"));
}

/// An error of a key's value from the file: "WHERE:LINE: " before the message, which names the key.
inline std::string located(const std::string& where, const toml::node& n, const std::string& message) {
  return str(where_line(where, n), ": ", message);
}

}  // namespace detail

/// The line of key `name` in the scenario file the keys were read from (0: not in the file, or
/// overridden by a flag).
inline long scenario_key_line(const ScenarioKeys& k, const std::string& name) {
  if (!k.document || k.overridden.count(name)) return 0;
  const toml::node* n = k.document->get(name);
  return n ? static_cast<long>(n->source().begin.line) : 0;
}

/// A message about the keys ("--key: ..." or "--a/--b: ...", the flags of the keys it is about)
/// located in the file that gave the first key, the keys the file gave named as written there:
/// "scenario FILE:LINE: key: ...". Unchanged when one of the keys came from a flag (an override: the
/// flag is named as the flag, not located at the line of another key) or the built-in scenario.
inline std::string located_key_message(const ScenarioKeys& k, const std::string& message) {
  if (k.file.empty() || message.rfind("--", 0) != 0) return message;
  const size_t end = std::min(message.find_first_of(": "), message.size());
  std::vector<std::string> names;  // the keys before the first ':' or ' ', "--a/--b"
  for (size_t at = 0; at < end;) {
    const size_t slash = std::min(message.find('/', at), end);
    names.push_back(message.substr(at, slash - at));
    at = slash + 1;
  }
  for (const std::string& n : names) {
    if (n.rfind("--", 0) != 0) return message;  // not a list of flags ("--a/b" is a path)
    if (k.overridden.count(n.substr(2))) return message;  // a flag at fault: named as the flag
  }
  const long line = scenario_key_line(k, names.front().substr(2));
  if (line <= 0) return message;
  std::string keys;
  for (const std::string& n : names)
    keys += (keys.empty() ? "" : "/") + (scenario_key_line(k, n.substr(2)) > 0 ? n.substr(2) : n);
  return detail::str(k.where, ":", line, ": ", keys, message.substr(end));
}

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
    try {
      if (extra_keys.count(name)) {
        keys.extra[name] = detail::extra_text(v, name);
        continue;
      }
      const ScenarioKey* key = find_scenario_key(name);
      if (!key) throw InputError(detail::unknown_key_message(name, extra_keys));
      key->from_toml(keys, v);
    } catch (const InputError& e) {
      throw InputError(detail::located(where, v, e.what()));
    }
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

/// Runs the check of every key of the table (ScenarioKey::check), then refuses a flag that would
/// change nothing (ScenarioKey::acts; a key given as an override, not by the file: a file may hold
/// keys for other jobs): a key of the global run without one, a key of the pose task where no run has
/// it, the multibody reference's servo gains without the objective that runs it. InputError naming
/// the key.
inline void check_scenario_keys(const ScenarioKeys& keys) {
  using detail::str;
  for (const ScenarioKey& key : scenario_keys())
    if (key.check) key.check(keys);
  for (const ScenarioKey& key : scenario_keys()) {
    if (!keys.overridden.count(key.name) || !key.acts) continue;
    const std::string why = key.acts(keys);
    if (!why.empty()) throw InputError(str("--", key.name, ": ", why));
  }
  if (keys.overridden.count("objective") && !keys.global &&
      (keys.objective == "multibody-force" || keys.objective == "robust-force"))
    throw InputError(str("--objective: ", keys.objective,
                         " acts on the global run only (the paper's method descends M_ie), and this run has "
                         "none (global = false)"));
}

}  // namespace ffsr
