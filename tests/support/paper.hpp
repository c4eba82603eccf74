// Shared by the tests: where the paper's robots are, and degrees -> radians vectors.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <initializer_list>
#include <string>

namespace ffsr::test {

/// robots/ of the source tree (FFSR_SOURCE_DIR is defined by tests/CMakeLists.txt).
inline const std::string kRobots = std::string(FFSR_SOURCE_DIR) + "/robots/";

/// A vector of angles given in degrees, in radians.
inline Eigen::VectorXd deg(std::initializer_list<double> d) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(d.size()));
  Eigen::Index i = 0;
  for (double x : d) v(i++) = x * M_PI / 180.0;
  return v;
}

}  // namespace ffsr::test
