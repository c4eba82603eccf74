// fuzz_scenario: arbitrary bytes as a scenario file of the main job of ffsr-optimize, run in-process
// through the command's own code (src/cli: support/, inspect, contact, robust and run of commands/; the CLI11
// app is set up as in main.cpp, and the same exceptions are caught). Checks: scenario_check.hpp.
#include "scenario_check.hpp"
#include "commands/subcommands.hpp"
#include "support/parse.hpp"
#include "support/output.hpp"

#include "ffsr/errors.hpp"

#include <CLI/CLI.hpp>

#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace {

/// The exit code main.cpp would return for argv; what it prints goes to `out` (stdout) and is dropped
/// (stderr). An exception main.cpp maps to exit code 1 (not an ffsr::Error) is reported as 1.
int run_main(std::vector<std::string> args, std::ostringstream& out) {
  using namespace ffsr::cli;
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int argc = static_cast<int>(args.size());

  std::ostringstream err;
  struct Redirect {
    std::streambuf* o;
    std::streambuf* e;
    ~Redirect() {
      std::cout.rdbuf(o);
      std::cerr.rdbuf(e);
    }
  } redirect{std::cout.rdbuf(out.rdbuf()), std::cerr.rdbuf(err.rdbuf())};

  CLI::App app{"ffsr-optimize (fuzz)", "ffsr-optimize"};
  app.set_version_flag("--version", "fuzz");
  Action action;
  register_inspect(app, action);
  register_contact(app, action);
  register_robust(app, action);
  register_run(app, action);
  app.require_subcommand(0, 1);
  try {
    app.parse(argc, argv.data());
  } catch (const CLI::ParseError& e) {
    app.exit(e, out, err);
    return e.get_exit_code() == 0 ? 0 : kExitInput;
  } catch (const ffsr::Error&) {
    return kExitInput;
  }
  try {  // as main.cpp: an empty action would throw std::bad_function_call, a finding
    return action();
  } catch (const ffsr::InputError&) {
    return kExitInput;
  } catch (const ffsr::ModelError&) {
    return kExitInput;
  } catch (const ffsr::Error&) {
    return kExitNumerical;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_scenario: exception %s: %s\n", typeid(e).name(), e.what());
    return 1;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "ffsr_fuzz_scenario_XXXXXX").string();
    if (!mkdtemp(pattern.data())) std::abort();
    ffsr_fuzz::prepare_scenario_dir(pattern);
    static std::string to_remove = pattern;
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(to_remove, ec);
    });
    return pattern;
  }();
  {
    std::ofstream f(dir + "/scenario.toml", std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  std::filesystem::remove(dir + "/out.json");
  std::filesystem::remove(dir + "/out.csv");
  std::vector<std::string> args{"ffsr-optimize"};
  for (const auto& a : ffsr_fuzz::scenario_arguments(dir)) args.push_back(a);
  auto check = [&](const uint8_t*, size_t) {
    std::ostringstream out;
    const int code = run_main(args, out);
    ffsr_fuzz::check_scenario_outputs(dir, code, out.str());
  };
  return ffsr_fuzz::run_fuzz_input("fuzz_scenario", check, data, size);
}
