// tests/support/command.hpp -- the shared fixture of the tests that run ffsr-optimize: where the
// command and the paper's files are, running the command, and reading its JSON and CSV outputs.
#pragma once

#include "support/run_command.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace ffsr::test {

using Args = std::vector<std::string>;

/// The command under test and the source tree (both defined by tests/CMakeLists.txt).
inline const std::string kCli = FFSR_CLI;
inline const std::string kSource = FFSR_SOURCE_DIR;
inline const std::string kUrdf3 = kSource + "/robots/paper_3dof.urdf";
inline const std::string kUrdf7 = kSource + "/robots/paper_7dof.urdf";
inline const std::string kScenario3 = kSource + "/robots/paper_3dof.toml";
/// How every error line of the command starts.
inline const std::string kErrorPrefix = "ffsr-optimize: error:";

/// Runs ffsr-optimize with `args` in `cwd` (empty: a throw-away temporary directory).
inline CommandResult cli(const Args& args, const std::string& cwd = {}, double timeout_s = 120.0) {
  Args full{kCli};
  full.insert(full.end(), args.begin(), args.end());
  if (!cwd.empty()) return run_command(full, cwd, timeout_s);
  TempDir tmp;
  return run_command(full, tmp.str(), timeout_s);
}

/// Runs the subcommand `sub` of ffsr-optimize with `args` in `cwd`.
inline CommandResult cli_sub(const std::string& sub, const Args& args, const std::string& cwd) {
  Args full{sub};
  full.insert(full.end(), args.begin(), args.end());
  return cli(full, cwd);
}

/// The whole content of a file ("" when it cannot be read).
inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The whole content of a file that must exist.
inline std::string read_existing_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in.good());
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Parses stdout as JSON; fails the test with the output when it is not.
inline nlohmann::json parse_json(const CommandResult& r) {
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  nlohmann::json j;
  REQUIRE_NOTHROW(j = nlohmann::json::parse(r.out));
  REQUIRE(j.is_object());
  return j;
}

/// A JSON file written by the command.
inline nlohmann::json read_json_file(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  nlohmann::json j;
  REQUIRE_NOTHROW(j = nlohmann::json::parse(in));
  return j;
}

inline std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string item;
  std::stringstream ss(s);
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

/// CSV file -> header and rows of cells.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int column(const std::string& name) const {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
};

inline Csv read_csv(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  Csv c;
  std::string line;
  REQUIRE(std::getline(in, line));
  c.header = split(line, ',');
  while (std::getline(in, line))
    if (!line.empty()) c.rows.push_back(split(line, ','));
  return c;
}

inline std::vector<double> numbers(const nlohmann::json& a) {
  std::vector<double> v;
  for (const auto& x : a) v.push_back(x.get<double>());
  return v;
}

/// A CSV of numbers (the map's output): the header line and rows of values.
struct NumericCsv {
  std::string header;
  std::vector<std::vector<double>> rows;
};

inline NumericCsv parse_numeric_csv(const std::string& text) {
  NumericCsv c;
  std::istringstream in(text);
  std::getline(in, c.header);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    const char* p = line.c_str();
    for (;;) {
      char* end = nullptr;
      row.push_back(std::strtod(p, &end));
      if (end == p) FAIL("not a number in the CSV line '" << line << "'");
      if (*end != ',') break;
      p = end + 1;
    }
    c.rows.push_back(std::move(row));
  }
  return c;
}

/// The keys of the main job's two runs and the reductions.
inline void check_result_keys(const nlohmann::json& j) {
  for (const char* run : {"baseline", "optimized"}) {
    INFO(run);
    REQUIRE(j.contains(run));
    for (const char* key :
         {"capture_configuration_deg", "integrated_effective_mass", "f_max_closed_form", "tracking_error"})
      CHECK(j.at(run).contains(key));
  }
  CHECK(j.contains("mass_reduction_percent"));
  CHECK(j.contains("force_reduction_percent"));
}

/// The version in the top-level CMakeLists.txt: project(ffsr VERSION x.y.z ...).
inline std::string project_version() {
  std::ifstream in(kSource + "/CMakeLists.txt");
  std::stringstream ss;
  ss << in.rdbuf();
  std::smatch m;
  const std::string text = ss.str();
  if (std::regex_search(text, m, std::regex(R"(project\s*\(\s*ffsr\s+VERSION\s+([0-9.]+))"))) return m[1];
  return {};
}

}  // namespace ffsr::test
