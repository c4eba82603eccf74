// src/cli/baseline.hpp -- regression runs: compare a JSON result with a stored one (--expect).
#pragma once

#include <nlohmann/json.hpp>

#include <string>
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
/// `skip` (inputs such as the resolved scenario and the version, not results) are not compared.
std::vector<std::string> compare_results(const nlohmann::json& stored, const nlohmann::json& now, Tolerance tol,
                                         const std::vector<std::string>& skip);

}  // namespace ffsr::cli
