// src/cli/commands/subcommands.hpp -- each subcommand registers its options and the action to run.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace ffsr::cli {

/// The action chosen by the command line; runs after parsing, returns the exit code.
using Action = std::function<int()>;

void register_inspect(CLI::App& app, Action& action);
void register_contact(CLI::App& app, Action& action);
/// xi: the relative error of the closed-form maximum force against K, delta_dot^- and c_r.
void register_xi(CLI::App& app, Action& action);
void register_map(CLI::App& app, Action& action);
/// `robust`: Monte Carlo of F_max over the scenario's [uncertainty] table.
void register_robust(CLI::App& app, Action& action);
/// `pareto`: the front of M_ie against the base's angular rate jump at the impact.
void register_pareto(CLI::App& app, Action& action);
/// The main job (no subcommand): run a capture scenario; a flag overrides the scenario file's key.
void register_run(CLI::App& app, Action& action);
/// `closed-loop`: the capture controller with the robot's dynamics and a noisy target estimate.
void register_closed_loop(CLI::App& app, Action& action);
/// `detumble`: the grasp and the post-capture run of robot and target as one stack.
void register_detumble(CLI::App& app, Action& action);

}  // namespace ffsr::cli
