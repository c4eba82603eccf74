// ffsr/model/data.hpp -- the workspace every algorithm writes into.
//
// Made once from a Model (all storage is allocated here); the algorithms then run without heap
// allocation. One Data per thread. Nothing in it is a cache: each algorithm says what it reads
// and what it writes.
#pragma once

#include "ffsr/model/model.hpp"

#include <vector>

namespace ffsr {

struct Data {
  explicit Data(const Model& model)
      : R(static_cast<size_t>(model.nb())),
        p(static_cast<size_t>(model.nb())),
        S(6, model.nb() - 1),
        sin_q(static_cast<size_t>(model.nb())),
        cos_q(static_cast<size_t>(model.nb())),
        Ic(static_cast<size_t>(model.nb())),
        Fc(6, model.nb() - 1),
        H(model.nv(), model.nv()),
        L(model.nv(), model.nv()),
        J(6, model.nv()),
        Jf(6, model.n()),
        w(model.nv()),
        y(model.nv()),
        V(static_cast<size_t>(model.nb())),
        A(static_cast<size_t>(model.nb())),
        F(static_cast<size_t>(model.nb())),
        Xup(static_cast<size_t>(model.nb())),
        tau(model.nv()),
        HbInv_Hbm(6, model.n()),
        IA(static_cast<size_t>(model.nb())),
        pA(static_cast<size_t>(model.nb())),
        U(static_cast<size_t>(model.nb())),
        D(model.n()),
        u(model.n()),
        path(static_cast<size_t>(model.nb())),
        on_path(static_cast<size_t>(model.nb())) {
    S.setZero();
    Fc.setZero();
    H.setZero();
    L.setZero();
    J.setZero();
    Jf.setZero();
  }
  // --- kinematics (forward_kinematics): world pose of every body frame ---------------------------
  std::vector<Matrix3> R;  ///< oR_i
  std::vector<Vector3> p;  ///< origin of body i in o
  BasePose base;           ///< the base pose the kinematics were computed at
  /// Joint motion subspace columns in the inertial orientation, about the base frame origin:
  /// [ (p_k - p_0) x z_k ; z_k ] (revolute) or [ z_k ; 0 ] (prismatic).
  Eigen::Matrix<double, 6, Eigen::Dynamic> S;
  /// sin and cos of each revolute body's joint position (entry i for body i; the base's and prismatic
  /// joints' entries are not written)
  std::vector<double> sin_q, cos_q;
  // --- CRBA --------------------------------------------------------------------------------------
  std::vector<SpatialInertia> Ic;  ///< composite inertias about the base origin, inertial axes
  Eigen::Matrix<double, 6, Eigen::Dynamic> Fc;  ///< Ic_i S_i, one column per moving body
  Eigen::MatrixXd H;               ///< (6+n)x(6+n) joint-space inertia
  Eigen::MatrixXd L;               ///< Cholesky factor of H (lower), written by the solves
  // --- Jacobians -------------------------------------------------------------------------------
  Eigen::MatrixXd J;   ///< 6x(6+n) point Jacobian [J_b J_m] of a frame origin
  Eigen::MatrixXd Jf;  ///< 6xn generalized Jacobian
  /// Scratch vectors of size 6+n: the effective-mass functions write w = J^T s and y (L^-1 w or
  /// H^-1 w, as each says) and return what they compute from them. The planner (optimize/) takes
  /// those return values and never reads w or y left by an earlier call.
  Eigen::VectorXd w, y;
  // --- RNEA (body coordinates) ---------------------------------------------------------------
  std::vector<Vector6> V, A, F;
  std::vector<Pose> Xup;  ///< pose of body i in its parent
  Eigen::VectorXd tau;
  Eigen::Matrix<double, 6, Eigen::Dynamic> HbInv_Hbm;  ///< H_b^-1 H_bm
  // --- articulated-body recursion (RBDA 7.3; inertial axes about the base origin) -------------
  std::vector<ArticulatedInertia> IA;  ///< articulated inertias
  std::vector<Vector6> pA;  ///< articulated bias forces
  std::vector<Vector6> U;   ///< IA_i S_i
  Eigen::VectorXd D, u;     ///< S_i^T U_i and tau_i - S_i^T pA_i, one per joint
  std::vector<int> path;    ///< bodies from a leaf to the base (scratch of one call, never read after it)
  std::vector<char> on_path;  ///< 1 for the bodies of `path` (scratch of one call)
};

}  // namespace ffsr
