// bench/bench_pinocchio.hpp -- the Pinocchio side of ffsr-bench-pinocchio (bench_pinocchio_side.cpp),
// compiled apart so that Pinocchio's include folder never meets ffsr's URDF loader.
#pragma once

#include <ffsr/ffsr.hpp>

#include <ctime>
#include <vector>

namespace ffsr_bench {

/// CPU time of the calling thread, seconds (time while descheduled does not count).
inline double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Builds a Pinocchio model equal to `model` (free-flyer root, one revolute or prismatic joint per
/// body, the frame `frame` as an operational frame) and evaluates u^T J_v M^-1 J_v^T u at every pose
/// (crba, computeJointJacobians, getFrameJacobian LOCAL_WORLD_ALIGNED, LLT solve). Writes the values
/// to `values`; returns the median over `passes` passes of the mean thread CPU time per evaluation, seconds.
double pinocchio_inverse_effective_mass(const ffsr::Model& model, int frame,
                                        const std::vector<ffsr::BasePose>& base,
                                        const std::vector<Eigen::VectorXd>& theta,
                                        const std::vector<Eigen::Vector3d>& u, int passes,
                                        std::vector<double>& values);

}  // namespace ffsr_bench
