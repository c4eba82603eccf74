// Shared by the tests: where the paper's robots are, degrees -> radians vectors, and the capture
// problems of the paper's scenario files.
#pragma once

#include "ffsr/optimize/capture.hpp"

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

/// The paper's target (Sections 5.1 and 5.2; 200 kg, diag(100, 100, 100), identity attitude, the
/// Target defaults) with the contact offset and spin of the 3-DOF or the 7-DOF scenario.
inline Target paper_target(bool seven_dof) {
  Target t;
  t.contact_offset = seven_dof ? Vector3(-0.25, 0.15, 0.1) : Vector3(-0.25, 0.15, 0.0);
  t.angular_velocity = (seven_dof ? Vector3(1, -0.5, 2) : Vector3(0, 0, 2)) * (M_PI / 180.0);
  return t;
}

/// The paper's contact (Sections 5.1.1 and 5.2.1): K = 1e9, alpha = 1.5, c_r = 0.9.
inline const ContactParams kPaperContact{1e9, 1.5, 0.9};

/// robots/paper_3dof.toml: the 3-DOF robot, its initial joints and the target.
inline CaptureProblem problem_3dof(const Model& m) {
  CaptureProblem pb;
  pb.model = &m;
  pb.frame = m.end_effector();
  pb.theta = deg({0, 150, -100});
  pb.target.position = Vector3(2.75, 1.45, 0);
  pb.target.angular_velocity = Vector3(0, 0, 2) * (M_PI / 180);
  return pb;
}

/// robots/paper_7dof_position.toml (and _pose.toml: the same robot and target)
inline CaptureProblem problem_7dof(const Model& m) {
  CaptureProblem pb;
  pb.model = &m;
  pb.frame = m.end_effector();
  pb.theta = deg({0, 90, 90, -90, 90, 90, 0});
  pb.target.position = Vector3(2.3, -0.8, 2);
  pb.target.angular_velocity = Vector3(1, -0.5, 2) * (M_PI / 180);
  pb.target.contact_offset = Vector3(-0.25, 0.15, 0.1);
  return pb;
}

}  // namespace ffsr::test
