// src/cli/subcommands.hpp -- each subcommand registers its options and the action to run.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace ffsr::cli {

/// The action chosen by the command line; runs after parsing, returns the exit code.
using Action = std::function<int()>;

void register_inspect(CLI::App& app, Action& action);
void register_contact(CLI::App& app, Action& action);

}  // namespace ffsr::cli
