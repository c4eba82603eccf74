// ffsr/jobs/detail/detumble_result.hpp -- the result of the job `detumble` (ffsr/jobs/detumble.hpp), in a
// header of its own: the main job's result (ffsr/jobs/scenario_run.hpp) holds one per run.
#pragma once

#include "ffsr/control/detumble_run.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <Eigen/Dense>

#include <optional>
#include <string>

namespace ffsr {

/// The job's result: the grasp, the run's summary and series, the limits it ran under.
struct DetumbleJobResult {
  std::string
      run;  ///< the main job's run it starts from (baseline, optimized, global); empty: a configuration
  Eigen::VectorXd theta;  ///< the capture configuration, rad
  GraspResult grasp;
  /// grasp-after = contact: the Hertz contact run before the lock and its impulse on the gripper (N s)
  std::optional<MultibodyContactResult> contact;
  Vector3 contact_impulse = Vector3::Zero();
  DetumbleRunResult result;
  DetumbleLimits limits;
  DetumbleOptions options;
  std::string peak_joint_name;  ///< the joint of the peak torque
};

}  // namespace ffsr
