// bench/bench_pinocchio.hpp -- the Pinocchio side of ffsr-bench-pinocchio (bench_pinocchio_side.cpp),
// compiled apart so that Pinocchio's include folder never meets ffsr's URDF loader, once with
// Pinocchio's templates instantiated in the bench's own executable and once against its precompiled
// library.
#pragma once

#include "ffsr/model/model.hpp"

#include <ctime>
#include <memory>
#include <string>
#include <vector>

namespace ffsr_bench {

/// CPU time of the calling thread, seconds (time while descheduled does not count).
inline double thread_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// A Pinocchio model loaded from a URDF text as its users load one (pinocchio::urdf::buildModelFromXML
/// with a free-flyer root joint: a continuous joint becomes Pinocchio's unbounded revolute joint, whose
/// configuration is the pair (cos q, sin q), a revolute one its RX/RY/RZ or unaligned revolute joint),
/// the URDF frame `frame` (a link or a fixed joint's child) as the contact point, and the poses to
/// evaluate it at (the configurations are converted once, outside the timed loops).
class PinocchioRoutes {
 public:
  /// CrbaLocal, CrbaWorld: pinocchio::crba in its LOCAL (the default) and WORLD conventions (upper
  /// triangle); CrbaLocalFull: LOCAL followed by the copy of the upper triangle into the lower (the
  /// full symmetric matrix, as ffsr::crba returns it). The inverse effective mass u^T J_v M^-1 J_v^T u
  /// by: DenseLocal -- crba (LOCAL), computeFrameJacobian of the one frame (LOCAL_WORLD_ALIGNED),
  /// Pinocchio's sparse cholesky::decompose (M = U D U^T) and |D^-1/2 U^-1 w|^2 (cholesky::Uiv, half
  /// of cholesky::solve), w = J_v^T u; DenseWorld -- crba (WORLD), which leaves the joint Jacobians in
  /// data.J, getFrameJacobian from them, then the same factorization; Minverse -- computeMinverse (the
  /// O(n^2) articulated-body inverse), computeFrameJacobian and w^T M^-1 w; Delassus -- u_c^T D u_c by
  /// computeDelassusMatrix, D the 3x3 Delassus matrix of a 3-D contact at the frame and u_c = R_c^T u
  /// the direction in the contact's axes (the O(n) operational-space route).
  enum class Kind { CrbaLocal, CrbaLocalFull, CrbaWorld, DenseLocal, DenseWorld, Minverse, Delassus };
  virtual ~PinocchioRoutes() = default;
  /// One pass over poses [0, count) of route `kind`. Returns the thread CPU time of the pass, seconds.
  virtual double pass(Kind kind, int count) = 0;
  /// u^T J_v M^-1 J_v^T u at pose k by route `kind` (DenseLocal, DenseWorld, Minverse or Delassus).
  virtual double inverse_effective_mass(Kind kind, int k) = 0;
  /// M's joint-joint block (symmetrized) at pose k, by crba in convention LOCAL or WORLD (`kind`).
  virtual Eigen::MatrixXd joint_block(Kind kind, int k) = 0;
};

using PinocchioFactory = std::unique_ptr<PinocchioRoutes> (*)(
    const std::string& urdf, const std::string& frame, const std::vector<ffsr::BasePose>& base,
    const std::vector<Eigen::VectorXd>& theta, const std::vector<Eigen::Vector3d>& u);

/// Pinocchio's templates instantiated in the bench's executable, at the bench's compiler and flags
/// (an object library linked in statically; its symbols hidden, so that the precompiled library
/// loaded beside it cannot take their place, nor they its).
std::unique_ptr<PinocchioRoutes> make_pinocchio_inline(const std::string& urdf, const std::string& frame,
                                                       const std::vector<ffsr::BasePose>& base,
                                                       const std::vector<Eigen::VectorXd>& theta,
                                                       const std::vector<Eigen::Vector3d>& u);
/// The explicit instantiations of the `pin` wheel's precompiled libpinocchio_default (a shared library
/// of its own, so that its calls bind to the precompiled code and not to the templates above).
std::unique_ptr<PinocchioRoutes> make_pinocchio_library(const std::string& urdf, const std::string& frame,
                                                        const std::vector<ffsr::BasePose>& base,
                                                        const std::vector<Eigen::VectorXd>& theta,
                                                        const std::vector<Eigen::Vector3d>& u);

}  // namespace ffsr_bench
