// bench/bench_pinocchio.hpp -- the Pinocchio side of ffsr-bench-pinocchio (bench_pinocchio_side.cpp),
// compiled apart so that Pinocchio's include folder never meets ffsr's URDF loader.
#pragma once

#include "ffsr/model/model.hpp"

#include <ctime>
#include <memory>
#include <vector>

namespace ffsr_bench {

/// CPU time of the calling thread, seconds (time while descheduled does not count).
inline double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// A Pinocchio model equal to an ffsr model (free-flyer root; one joint per body: RX, RY or RZ for a
/// revolute axis +x, +y or +z, else the unaligned revolute or prismatic joint; the frame `frame` as
/// an operational frame) and the poses to evaluate it at.
class PinocchioBench {
 public:
  enum class Kind { CrbaLocal, CrbaLocalFull, CrbaWorld, InverseEffectiveMass };
  PinocchioBench(const ffsr::Model& model, int frame, const std::vector<ffsr::BasePose>& base,
                 const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& u);
  ~PinocchioBench();
  /// One pass over poses [0, count): pinocchio::crba (Convention::LOCAL, the default, or WORLD; upper
  /// triangle), LOCAL followed by the copy of the upper triangle into the lower (CrbaLocalFull: the
  /// full symmetric matrix, as ffsr::crba returns it), or u^T J_v M^-1 J_v^T u (crba,
  /// computeJointJacobians, getFrameJacobian LOCAL_WORLD_ALIGNED, LLT solve). Returns the thread CPU
  /// time of the pass, seconds.
  double pass(Kind kind, int count);
  /// u^T J_v M^-1 J_v^T u at pose k.
  double inverse_effective_mass(int k);
  /// M's joint-joint block (symmetrized) at pose k.
  Eigen::MatrixXd joint_block(int k);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ffsr_bench
