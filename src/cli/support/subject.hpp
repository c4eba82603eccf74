// src/cli/support/subject.hpp -- loading what a subcommand evaluates: the scenario of a command (the
// file or the built-in one, then the given flags as overrides) and the subject of inspect, contact and
// map (a robot at one configuration, the target, the contact law).
#pragma once

#include "support/scenario_flags.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <CLI/CLI.hpp>

#include <set>
#include <string>

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

/// The robot at one configuration, the target and the contact law that inspect, contact and map
/// evaluate: the keys of a scenario file (--config) or of the built-in scenario, then the scenario
/// keys given as flags (the robot and its start state, the bus, the target, the contact law), read,
/// checked and built by the library (ffsr/scenario/scenario.hpp) as for the main job. --urdf replaces the
/// robot: its joint angles (--joints-deg, then required) and end-effector come from the flags alone.
struct SubjectOptions {
  std::string config;
  ScenarioFlags flags;
  /// --config and the flags of the subject's keys; `also` adds keys of the key table (their flags).
  void add_to(CLI::App& app, const std::set<std::string>& also = {}, const std::set<std::string>& except = {});
};

/// Builds the scenario of the options' keys, scope Configuration (scenario/scenario.hpp: the robot at its
/// start configuration, the target, the contact law); warns about every repair of the model as soon as
/// it is loaded. `held`: the subcommand takes a stack that holds its target (grasp-after = held, with
/// no capture keys); else such a scenario must give the capture's keys (the target's spin, the contact
/// point and normal, the contact law, the approach speed). InputError naming the key or the file,
/// ModelError from the loader.
Scenario load_subject(const SubjectOptions& options, bool held = false);

}  // namespace ffsr::cli
