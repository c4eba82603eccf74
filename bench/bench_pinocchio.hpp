// bench/bench_pinocchio.hpp -- the Pinocchio side of ffsr-bench-pinocchio (bench_pinocchio_side.cpp),
// compiled apart so that Pinocchio's include folder never meets ffsr's URDF loader, once with
// Pinocchio's templates instantiated in the bench's own unit and once against its precompiled library.
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
/// an operational frame and as a 3-D contact) and the poses to evaluate it at.
class PinocchioRoutes {
 public:
  /// pinocchio::crba (Convention::LOCAL, the default, or WORLD; upper triangle); LOCAL followed by
  /// the copy of the upper triangle into the lower (CrbaLocalFull: the full symmetric matrix, as
  /// ffsr::crba returns it); u^T J_v M^-1 J_v^T u by crba, computeJointJacobians, getFrameJacobian
  /// LOCAL_WORLD_ALIGNED and an LLT solve (Dense); u_c^T D u_c by computeDelassusMatrix, D the 3x3
  /// Delassus matrix of a 3-D contact at the frame and u_c = R_c^T u the direction in the contact's
  /// axes (Delassus: the O(n) operational-space route).
  enum class Kind { CrbaLocal, CrbaLocalFull, CrbaWorld, Dense, Delassus };
  virtual ~PinocchioRoutes() = default;
  /// One pass over poses [0, count) of route `kind`. Returns the thread CPU time of the pass, seconds.
  virtual double pass(Kind kind, int count) = 0;
  /// u^T J_v M^-1 J_v^T u at pose k by route `kind` (Dense or Delassus).
  virtual double inverse_effective_mass(Kind kind, int k) = 0;
  /// M's joint-joint block (symmetrized) at pose k.
  virtual Eigen::MatrixXd joint_block(int k) = 0;
};

using PinocchioFactory = std::unique_ptr<PinocchioRoutes> (*)(const ffsr::Model& model, int frame,
                                                              const std::vector<ffsr::BasePose>& base,
                                                              const std::vector<Eigen::VectorXd>& theta,
                                                              const std::vector<Eigen::Vector3d>& u);

/// Pinocchio's templates instantiated in the bench's own unit, at the bench's compiler and flags (a
/// shared library of its own with hidden symbols, so that they do not replace the precompiled ones).
std::unique_ptr<PinocchioRoutes> make_pinocchio_inline(const ffsr::Model& model, int frame,
                                                       const std::vector<ffsr::BasePose>& base,
                                                       const std::vector<Eigen::VectorXd>& theta,
                                                       const std::vector<Eigen::Vector3d>& u);
/// The explicit instantiations of the `pin` wheel's precompiled libpinocchio_default.
std::unique_ptr<PinocchioRoutes> make_pinocchio_library(const ffsr::Model& model, int frame,
                                                        const std::vector<ffsr::BasePose>& base,
                                                        const std::vector<Eigen::VectorXd>& theta,
                                                        const std::vector<Eigen::Vector3d>& u);

}  // namespace ffsr_bench
