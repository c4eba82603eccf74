// ffsr/algorithm/jacobian.hpp -- J_bm = [J_b J_m] of a frame and the generalized Jacobian J_f.
#pragma once

#include "ffsr/algorithm/crba.hpp"

namespace ffsr {

/// Point Jacobian J_bm = [J_b J_m] of the origin of `frame` (Eq. 2): 6x(6+n), linear rows first,
/// in the inertial frame, for the generalized velocity [v0, w0, theta_dot] of model.hpp.
/// Reads the kinematics (call forward_kinematics or crba first). Writes data.J. Returns data.J.
inline const Eigen::MatrixXd& frame_jacobian(const Model& model, Data& data, int frame) {
  if (frame < 0 || frame >= static_cast<int>(model.frames().size()))
    FFSR_THROW(InputError(detail::str("frame_jacobian: frame index ", frame, " out of range")));
  Eigen::MatrixXd& J = data.J;
  const Vector3 pe = frame_pose(model, data, frame).p;
  if (!pe.allFinite())
    FFSR_THROW(NumericalError(detail::str("frame_jacobian: the position of frame '", model.frame(frame).name,
                                     "' overflows double precision")));
  const Vector3 d0 = pe - data.p[0];
  J.setZero();
  J.topLeftCorner<3, 3>().setIdentity();
  J.block<3, 3>(0, 3) = -skew(d0);
  J.block<3, 3>(3, 3).setIdentity();
  for (int i = model.frame(frame).body; i > 0; i = model.body(i).parent) {
    const auto S = data.S.col(i - 1);
    const Vector3 z = S.tail<3>();
    const int c = 6 + model.body(i).coord;  // mimics: several joints add into one column
    if (model.body(i).joint.type == JointType::Revolute) {
      J.block<3, 1>(0, c) += z.cross(pe - data.p[static_cast<size_t>(i)]);
      J.block<3, 1>(3, c) += z;
    } else {
      J.block<3, 1>(0, c) += S.head<3>();
    }
  }
  return J;
}

/// Generalized Jacobian J_f = J_m - J_b H_b^-1 H_bm (Eq. 29; Umetani and Yoshida): the map from
/// joint rates to the end-effector velocity when the base moves under zero total momentum.
/// Reads data.H (crba) and data.J (frame_jacobian) at the same configuration.
/// Writes data.HbInv_Hbm and data.Jf (6xn). Returns data.Jf.
inline const Eigen::MatrixXd& generalized_jacobian(const Model& model, Data& data) {
  const int n = model.n();
  const Eigen::LLT<Matrix6> Hb(data.H.topLeftCorner<6, 6>());
  if (Hb.info() != Eigen::Success)
    FFSR_THROW(NumericalError("generalized_jacobian: the base inertia H_b is singular"));
  data.HbInv_Hbm = data.H.topRightCorner(6, n);
  Hb.solveInPlace(data.HbInv_Hbm);
  data.Jf.noalias() = data.J.rightCols(n);
  data.Jf.noalias() -= data.J.leftCols<6>() * data.HbInv_Hbm;
  return data.Jf;
}

/// Convenience: crba, frame_jacobian and generalized_jacobian at one configuration.
/// Writes the kinematics, data.H, data.J and data.Jf. Returns data.Jf.
inline const Eigen::MatrixXd& generalized_jacobian(const Model& model, Data& data, const BasePose& base,
                                                   const Eigen::Ref<const Eigen::VectorXd>& theta,
                                                   int frame) {
  crba(model, data, base, theta);
  frame_jacobian(model, data, frame);
  return generalized_jacobian(model, data);
}

}  // namespace ffsr
