// src/cli/support/scenario_flags.hpp -- the scenario keys as flags (one per key of the library's key
// table, ffsr/scenario/scenario.hpp: its parsers and checks).
#pragma once

#include "ffsr/scenario/scenario.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace ffsr::cli {

/// The flags of the scenario keys (ffsr::scenario_keys()): one per key, holding the text given.
class ScenarioFlags {
 public:
  /// Registers "--" + name for every key that `only` accepts (all when empty); a name `app` already
  /// has is left to it.
  void add_to(CLI::App& app, const std::function<bool(const std::string&)>& only = {});
  /// Registers the flags of the keys of `groups` but the keys named in `except`.
  void add_groups(CLI::App& app, std::initializer_list<KeyGroup> groups, const std::set<std::string>& except = {});
  /// True when the flag of key `name` was given.
  bool given(const std::string& name) const;
  /// Sets the given flags' keys as overrides (InputError naming the flag on a bad value).
  void apply(ScenarioKeys& keys) const;

 private:
  std::map<std::string, std::string> text_;
  std::map<std::string, std::vector<std::string>> lists_;
  std::vector<std::pair<const ScenarioKey*, const CLI::Option*>> options_;
};

/// Makes every scenario key's flag known to every subcommand of `app`: where a subcommand does not
/// take a key, its flag (hidden from the help) is refused with one line saying why and which jobs
/// take it ("--joint-torque-limit: a key of the post-capture phase, which inspect does not run (the
/// subcommand inspect does not take it; the main job, pareto and detumble do)"), as the main job
/// refuses a key where its run does not act, instead of the parser's "arguments were not expected".
/// Call after every subcommand registered its flags.
void refuse_untaken_scenario_keys(CLI::App& app);

/// Refuses a shape key given as a flag (the Shapes group but the clearance) for a job that uses the
/// shapes through the clearance only, when the clearance is 0: InputError naming the key.
void refuse_shapes_without_clearance(const ScenarioKeys& keys, const std::string& job);

}  // namespace ffsr::cli
