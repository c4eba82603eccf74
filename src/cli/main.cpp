// ffsr-optimize: plan the capture configuration of a free-floating space robot.
// Parses the command line, runs the chosen action and maps exceptions to one error line and an exit
// code (2: bad input or an output that cannot be written, 3: numerical failure, 4: the result moved
// away from the --expect baseline). The library itself never prints.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/scenario_flags.hpp"
#include "support/subject.hpp"
#include "commands/subcommands.hpp"

#include <csignal>
#include <iostream>

namespace {

/// The exit code of the exception in flight (in a catch block), after its one error line. Bad input
/// (a parse error, InputError, ModelError) is 2; another ffsr::Error (numerical, integration) is 3.
int exit_code_of_current_exception(bool parsing) {
  try {
    throw;
  } catch (const ffsr::InputError& e) {
    std::cerr << "ffsr-optimize: error: " << e.what() << "\n";
    return ffsr::cli::kExitInput;
  } catch (const ffsr::ModelError& e) {
    std::cerr << "ffsr-optimize: error: " << e.what() << "\n";
    return ffsr::cli::kExitInput;
  } catch (const ffsr::Error& e) {
    std::cerr << "ffsr-optimize: error: " << e.what() << "\n";
    return parsing ? ffsr::cli::kExitInput : ffsr::cli::kExitNumerical;
  } catch (const std::exception& e) {
    std::cerr << "ffsr-optimize: error: " << e.what() << "\n";
    return 1;
  }
}

/// "(did you mean --x?)" for the first flag of `argv` that the chosen subcommand (or the main job)
/// does not know and that is close to one it knows; "" otherwise.
std::string flag_suggestion(const CLI::App& app, int argc, char** argv) {
  const auto subs = app.get_subcommands();
  const CLI::App& chosen = subs.empty() ? app : *subs.front();
  std::vector<std::string> names;
  for (const CLI::Option* opt : chosen.get_options())
    for (const std::string& n : opt->get_lnames()) names.push_back("--" + n);
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) != 0) continue;
    a = a.substr(0, a.find('='));
    if (chosen.get_option_no_throw(a)) continue;
    const std::string near = ffsr::detail::nearest_name(a, names);
    if (!near.empty()) return " (did you mean " + near + "?)";
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace ffsr::cli;
  // A reader that closes the pipe early (`ffsr-optimize --json - | head -c 10`) makes a write fail
  // with EPIPE, reported like any other write error (one line, exit 2), instead of killing the
  // process with SIGPIPE.
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{
      "ffsr-optimize: capture-configuration optimization for free-floating space robots (ffsr " FFSR_VERSION
      ")",
      "ffsr-optimize"};
  app.set_version_flag("--version", FFSR_VERSION);
  Action action;
  register_inspect(app, action);
  register_contact(app, action);
  register_xi(app, action);
  register_map(app, action);
  register_robust(app, action);
  register_pareto(app, action);
  register_closed_loop(app, action);
  register_detumble(app, action);
  register_run(app, action);
  refuse_untaken_scenario_keys(app);  // a key's flag on a subcommand that does not take it: why
  app.require_subcommand(0, 1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --help-all, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "ffsr-optimize: error: " << e.what() << flag_suggestion(app, argc, argv) << "\n";
    return kExitInput;
  } catch (...) {
    return exit_code_of_current_exception(true);
  }
  try {
    const int code = action();
    flush_stdout();  // a table or JSON printed on a closed pipe or a full disk is an error too
    return code;
  } catch (...) {
    return exit_code_of_current_exception(false);
  }
}
