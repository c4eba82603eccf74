// ffsr/jobs/detail/detumble_result.hpp -- the result of the job `detumble` (ffsr/jobs/detumble.hpp), in a
// header of its own: the main job's result (ffsr/jobs/scenario_run.hpp) holds one per run.
#pragma once

#include "ffsr/control/detumble_run.hpp"

#include <Eigen/Dense>

#include <string>

namespace ffsr {

/// The job's result: the grasp, the run's summary and series, the limits it ran under.
struct DetumbleJobResult {
  std::string
      run;  ///< the main job's run it starts from (baseline, optimized, global); empty: a configuration
  Eigen::VectorXd theta;  ///< the capture configuration, rad
  GraspResult grasp;
  DetumbleRunResult result;
  DetumbleLimits limits;
  DetumbleOptions options;
  std::string peak_joint_name;  ///< the joint of the peak torque
};

}  // namespace ffsr
