// src/cli/scenario.hpp -- the scenario keys as flags (registered from the library's key table,
// ffsr/io/scenario.hpp) and the scenario of a command: the file or the built-in one, then the given
// flags as overrides. Used by every subcommand that reads a scenario.
#pragma once

#include "common.hpp"

#include "ffsr/io/scenario.hpp"
#include "ffsr/jobs/scenario_run.hpp"

#include <set>
#include <string>
#include <utility>
#include <vector>

namespace ffsr::cli {

/// The keys of a command's scenario: `config` (empty: the built-in paper 3-DOF scenario), then the
/// given flags. `command_keys`: the command's own keys a file may hold (ScenarioKeys::extra).
ScenarioKeys command_scenario_keys(const std::string& config, const ScenarioFlags& flags,
                                   const std::set<std::string>& command_keys = {});
/// The robot of the built-in scenario, compiled into the command.
EmbeddedUrdf builtin_urdf();
/// Builds the scenario (the built-in one from the robot compiled into the command) and warns about
/// every repair of the model.
Scenario command_scenario(ScenarioKeys keys);

}  // namespace ffsr::cli
