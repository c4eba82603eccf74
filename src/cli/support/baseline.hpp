// src/cli/support/baseline.hpp -- regression runs: compare a JSON result with a stored one (--expect).
// Header-only: the CLI's source files are also compiled, by name, into fuzz/fuzz_scenario.
#pragma once

#include "ffsr/errors.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace ffsr::cli {

/// Reads a stored result (a JSON file written earlier with --json). Throws InputError naming `flag`
/// and the file when it cannot be read or is not a JSON object.
nlohmann::json load_baseline(const std::string& path, const std::string& flag);

/// Tolerances of the comparison: numbers a (stored) and b (now) agree when
///   |a - b| <= rtol * max(|a|, |b|) + atol,
/// the absolute floor `atol` covering values that should be zero and come out as round-off.
struct Tolerance {
  double rtol = 1e-6;
  double atol = 1e-9;
};

/// Compares `now` with `stored` recursively over objects and arrays and returns one line per
/// difference, "path: stored X, now Y" (path like optimized.capture_configuration_deg[1]; numbers
/// in their shortest round-trip form). A key present on one side only, an array of another length,
/// a changed string or boolean and a change of type are differences too. Top-level keys listed in
/// `skip` (inputs such as the resolved scenario and the version, not results) are not compared, nor
/// are the keys of kUncomparedKeys at any depth (wall-clock times, the optimizers' work counters,
/// the keys not applied to a row).
std::vector<std::string> compare_results(const nlohmann::json& stored, const nlohmann::json& now,
                                         Tolerance tol, const std::vector<std::string>& skip);

// --- definitions ----------------------------------------------------------------------------------
namespace detail_baseline {

using ffsr::detail::str;
using nlohmann::json;

/// Keys of these names (at any depth) are never compared: wall-clock times (global.search.seconds)
/// and the optimizers' work counters (SLSQP and damped-step evaluations), which move with the last
/// bit of a gradient -- another compiler, Eigen version or libm -- while the results agree; each
/// row's keys_not_applied, which the scenario's keys decide (inputs, as the top-level `scenario`).
inline constexpr std::array<std::string_view, 5> kUncomparedKeys{
    "seconds", "evaluations", "damped_evaluations", "multibody_evaluations", "keys_not_applied"};
inline bool uncompared(const std::string& key) {
  return std::find(kUncomparedKeys.begin(), kUncomparedKeys.end(), key) != kUncomparedKeys.end();
}

inline std::string show(const json& v) {
  if (v.is_array()) return str("an array of ", v.size());
  if (v.is_object()) return str("an object of ", v.size(), " keys");
  return v.dump();
}

inline void compare(const json& a, const json& b, const std::string& path, Tolerance tol,
                    std::vector<std::string>& out) {
  const std::string where = path.empty() ? std::string("(top level)") : path;
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    const bool same = (x == y) || std::abs(x - y) <= tol.rtol * std::max(std::abs(x), std::abs(y)) + tol.atol;
    if (!same) out.push_back(str(where, ": stored ", a.dump(), ", now ", b.dump()));
    return;
  }
  if (a.is_object() && b.is_object()) {
    const std::string prefix = path.empty() ? "" : path + ".";
    for (const auto& [key, value] : a.items()) {
      if (uncompared(key)) continue;  // a wall-clock time or a work counter is not a result
      if (!b.contains(key))
        out.push_back(str(prefix, key, ": stored ", show(value), ", now missing"));
      else
        compare(value, b.at(key), prefix + key, tol, out);
    }
    for (const auto& [key, value] : b.items())
      if (!uncompared(key) && !a.contains(key))
        out.push_back(str(prefix, key, ": stored missing, now ", show(value)));
    return;
  }
  if (a.is_array() && b.is_array()) {
    if (a.size() != b.size()) {
      out.push_back(str(where, ": stored ", a.size(), " entries, now ", b.size()));
      return;
    }
    for (size_t i = 0; i < a.size(); ++i) compare(a[i], b[i], str(path, "[", i, "]"), tol, out);
    return;
  }
  if (a != b) out.push_back(str(where, ": stored ", show(a), ", now ", show(b)));
}

}  // namespace detail_baseline

inline nlohmann::json load_baseline(const std::string& path, const std::string& flag) {
  using detail_baseline::str;
  using nlohmann::json;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(str(flag, " ", path, ": cannot open the baseline file"));
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(str(flag, " ", path, ": cannot read the baseline file"));
  json j = json::parse(ss.str(), nullptr, false);
  if (j.is_discarded())
    throw InputError(str(flag, " ", path, ": not a JSON file (write a baseline with --json FILE)"));
  if (!j.is_object())
    throw InputError(str(flag, " ", path, ": expected a JSON object (a result written with --json)"));
  return j;
}

inline std::vector<std::string> compare_results(const nlohmann::json& stored, const nlohmann::json& now,
                                                Tolerance tol, const std::vector<std::string>& skip) {
  nlohmann::json a = stored, b = now;
  for (const auto& key : skip) {
    if (a.is_object()) a.erase(key);
    if (b.is_object()) b.erase(key);
  }
  std::vector<std::string> out;
  detail_baseline::compare(a, b, "", tol, out);
  return out;
}

}  // namespace ffsr::cli
