// tests/support/baselines.hpp -- values read from the stored results tests/data/baselines/<name>.json
// (the main job's --json output of robots/<name>.toml), shared by the tests and the benchmarks.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ffsr::test {

/// The global plan's capture configuration (rad) of the stored baseline `name`.
inline Eigen::VectorXd global_configuration(const std::string& name) {
  const std::string path = std::string(FFSR_SOURCE_DIR) + "/tests/data/baselines/" + name + ".json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the stored baseline");
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto deg = j.at("global").at("capture_configuration_deg").get<std::vector<double>>();
  Eigen::VectorXd q(static_cast<Eigen::Index>(deg.size()));
  for (size_t i = 0; i < deg.size(); ++i) q(static_cast<Eigen::Index>(i)) = deg[i] * M_PI / 180;
  return q;
}

}  // namespace ffsr::test
