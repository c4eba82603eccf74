// ffsr/jobs/detail/json_values.hpp -- the JSON form of a vector, shared by the results of the jobs.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace ffsr::detail {

inline nlohmann::json vector_json(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

}  // namespace ffsr::detail
