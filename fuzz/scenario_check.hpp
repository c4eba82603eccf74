// fuzz/scenario_check.hpp -- the fuzz_scenario check, shared by the libFuzzer harness (which runs the
// command's code in-process, fuzz_scenario.cpp) and tests/test_fuzz_regressions.cpp (which runs the
// built ffsr-optimize on each reproducer).
#pragma once

#include "fuzz_checks.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

// A scenario text is run as `ffsr-optimize [robust] --config DIR/scenario.toml` plus the rest of
// scenario_arguments() (robust when the text has an [uncertainty] table): a short bounded run
// (command-line flags override the file) whose outputs go to DIR. The URDFs the seed scenarios name
// (paper_3dof.urdf, paper_7dof.urdf) are copied into DIR. Asserted afterwards:
//  - the exit code is 0, 4 (written; differs from an --expect baseline), 2 (bad input) or 3 (numerical
//    failure): 1 means an exception that is not an ffsr::Error or a CLI11 parse error reached main;
//  - a failed run leaves no output file and no temporary file behind;
//  - a successful run's JSON parses and has no null (nlohmann writes NaN and inf as null; only the
//    reductions against a run that failed, {"error": message}, are null) and no non-finite number,
//    its CSV and its terminal table contain no nan or inf.

namespace ffsr_fuzz {

/// Copies the paper's URDFs into `dir` (the seed scenarios name them relative to the file).
inline void prepare_scenario_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  for (const char* name : {"paper_3dof.urdf", "paper_7dof.urdf"})
    fs::copy_file(fs::path(FFSR_SOURCE_DIR) / "robots" / name, fs::path(dir) / name,
                  fs::copy_options::overwrite_existing);
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The arguments after the program name: the scenario DIR/scenario.toml, a bounded run, outputs in
/// `dir`. A scenario with an [uncertainty] table runs `robust` on 20 samples (its table reader, the
/// sampler's laws and redraws, the summaries), any other the main job.
inline std::vector<std::string> scenario_arguments(const std::string& dir) {
  std::vector<std::string> args;
  if (read_text(dir + "/scenario.toml").find("[uncertainty]") != std::string::npos)
    args = {"robust", "--samples", "20", "--threads", "1"};
  for (const char* a : {"--quiet", "--global", "false", "--duration", "2", "--step", "0.1"})
    args.push_back(a);
  for (const std::string& a : std::vector<std::string>{"--config", dir + "/scenario.toml", "--json",
                                                       dir + "/out.json", "--csv", dir + "/out.csv"})
    args.push_back(a);
  return args;
}

/// True when `text` has a token nan or inf (any case, with a sign or not) that is not part of a word.
inline bool has_non_finite_token(const std::string& text) {
  static const std::regex re("(^|[^A-Za-z0-9_])[-+]?(nan|inf)(inity)?([^A-Za-z0-9_]|$)", std::regex::icase);
  return std::regex_search(text, re);
}

/// `null_ok`: the paths where a null is documented (the reductions against a run that failed).
inline void check_json_finite(const nlohmann::json& j, const std::string& path,
                              const std::vector<std::string>& null_ok = {}) {
  if (j.is_null() && std::find(null_ok.begin(), null_ok.end(), path) != null_ok.end()) return;
  if (j.is_null()) fail("JSON output: null (a NaN or inf) at " + path);
  if (j.is_number_float() && !std::isfinite(j.get<double>()))
    fail("JSON output: non-finite number at " + path);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) check_json_finite(it.value(), path + "/" + it.key(), null_ok);
  if (j.is_array())
    for (size_t i = 0; i < j.size(); ++i) check_json_finite(j[i], path + "/" + std::to_string(i), null_ok);
}

/// The checks after one run of the scenario in `dir` (see the top of this file). `terminal` is what
/// the command printed on stdout.
inline void check_scenario_outputs(const std::string& dir, int exit_code, const std::string& terminal) {
  namespace fs = std::filesystem;
  // 4: the result was written and differs from an --expect baseline (a scenario may name one)
  const bool wrote = exit_code == 0 || exit_code == 4;
  if (!wrote && exit_code != 2 && exit_code != 3)
    fail("exit code " + std::to_string(exit_code) + " (an unexpected exception type reached main)");
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos)
      fail("temporary output file left behind: " + e.path().string());
  const bool json = fs::exists(dir + "/out.json"), csv = fs::exists(dir + "/out.csv");
  if (!wrote) {
    if (json || csv) fail("a failed run left an output file behind");
    return;
  }
  if (json != csv) fail("a successful run wrote only one of its two output files");
  std::string table = terminal;
  for (size_t p; (p = table.find(dir)) != std::string::npos;) table.erase(p, dir.size());
  if (has_non_finite_token(table)) fail("the terminal output has nan or inf:\n" + terminal);
  if (!json) return;  // --help, --version
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_text(dir + "/out.json"));
  } catch (const std::exception& e) {
    fail(std::string("the JSON output does not parse: ") + e.what());
  }
  // a plain or paper's-method run that failed while the global row ran: {"error": text} in its place,
  // and the reductions against it null
  std::vector<std::string> null_ok;
  for (const char* row : {"baseline", "optimized"})
    if (j.contains(row) && j[row].contains("error")) {
      if (!j[row]["error"].is_string() || j[row]["error"].get<std::string>().empty())
        fail(std::string("JSON output: /") + row + "/error is not a message");
      if (!j.contains("global")) fail(std::string("JSON output: /") + row + " failed without a global row");
      for (const char* k : {"/mass_reduction_percent", "/force_reduction_percent", "/exact_force_reduction_percent"})
        null_ok.push_back(k);
      if (std::string(row) == "baseline")
        for (const char* k : {"/global_mass_reduction_percent", "/global_force_reduction_percent",
                              "/global_exact_force_reduction_percent"})
          null_ok.push_back(k);
    }
  check_json_finite(j, "", null_ok);
  if (has_non_finite_token(read_text(dir + "/out.csv"))) fail("the CSV output has nan or inf");
}

}  // namespace ffsr_fuzz
