// src/cli/model_options.hpp -- the scenario keys as flags (one per key of the library's key table,
// ffsr/io/scenario.hpp: its parsers and checks) and the warnings of the model loader.
#pragma once

#include "ffsr/io/scenario.hpp"
#include "ffsr/jobs/scenario_run.hpp"

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

/// One warning line on stderr per repair ("ffsr-optimize: warning: link 'x': ...").
void warn_repairs(const UrdfReport& report);

}  // namespace ffsr::cli
