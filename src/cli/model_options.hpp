// src/cli/model_options.hpp -- how a URDF becomes a model (the spacecraft bus it is mounted on, locked
// joints, inertia repairs, the contact point at the gripper) for the subcommands that load a robot
// from flags (inspect, contact, map). The keys, their parsers and the checks are the library's
// (ffsr::ModelLoadKeys, ffsr/io/scenario.hpp); the main job and robust take them from the key table.
#pragma once

#include "ffsr/io/scenario.hpp"
#include "ffsr/io/scenario_run.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace ffsr::cli {

/// The flags of the scenario keys (ffsr::scenario_keys()): one per key, holding the text given.
class ScenarioFlags {
 public:
  /// Registers "--" + name for every key that `only` accepts (all when empty); a name `app` already
  /// has is left to it.
  void add_to(CLI::App& app, const std::function<bool(const std::string&)>& only = {});
  /// True when the flag of key `name` was given.
  bool given(const std::string& name) const;
  /// Sets the given flags' keys as overrides (InputError naming the flag on a bad value).
  void apply(ScenarioKeys& keys) const;

 private:
  std::map<std::string, std::string> text_;
  std::map<std::string, std::vector<std::string>> lists_;
  std::vector<std::pair<const ScenarioKey*, const CLI::Option*>> options_;
};

/// --bus-mass, --bus-inertia, --bus-com, --mount-xyz, --mount-rpy-deg, --lock-joints,
/// --inertia-repair, --min-mass, --min-inertia, --end-effector-offset: the load keys of the key table.
class ModelLoadOptions {
 public:
  void add_to(CLI::App& app);
  /// The loader options; throws InputError naming the key on a bad value.
  UrdfOptions build(const std::string& end_effector) const;

 private:
  ScenarioFlags flags_;
};

/// One warning line on stderr per repair ("ffsr-optimize: warning: link 'x': ...").
void warn_repairs(const UrdfReport& report);

}  // namespace ffsr::cli
