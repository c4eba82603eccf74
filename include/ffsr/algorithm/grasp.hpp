// ffsr/algorithm/grasp.hpp -- the grasp: the gripper locks on the target at the contact point, a
// perfectly plastic 6-D impulse (no external force), and the stack model (model/attach.hpp) it leaves.
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/model/attach.hpp"
#include "ffsr/model/target.hpp"

namespace ffsr {

/// The velocities just before and after the lock, and the impulse it took. Vectors in the inertial
/// frame; twists and wrenches linear first.
struct GraspResult {
  Eigen::VectorXd v_before, v_after;        ///< robot generalized velocity (6+n); v_after is the stack's
  Vector6 target_before = Vector6::Zero();  ///< target [v_c; w]: centre-of-mass velocity, angular velocity
  Vector6 target_after = Vector6::Zero();   ///< the same after the lock
  Vector6 impulse = Vector6::Zero();  ///< on the gripper from the target at the contact point: N s, N m s
  Vector6 base_velocity_jump = Vector6::Zero();  ///< [v_0; w_0] after minus before
  Vector6 momentum_before = Vector6::Zero();     ///< robot + target [P; L about o]
  Vector6 momentum_after = Vector6::Zero();
  double energy_before = 0, energy_after = 0;      ///< kinetic energy of robot + target, J
  Vector6 relative_twist_after = Vector6::Zero();  ///< gripper minus target at the contact point (zero)
  Vector3 contact_point = Vector3::Zero();         ///< the lock's point: the frame's origin
  AttachedBody body;  ///< the target as a body attached at the frame (attach_body gives the stack model)
};

namespace detail {

/// The target's momentum [m v_c; c x m v_c + I_w w] about o, for its twist [v_c; w] (inertial).
inline Vector6 target_momentum(const Target& t, const Vector6& twist) {
  const Matrix3 R = t.rotation();
  Vector6 h;
  h.head<3>() = t.mass * twist.head<3>();
  h.tail<3>() = t.position.cross(h.head<3>()) + R * t.inertia * R.transpose() * twist.tail<3>();
  return h;
}

/// The robot's momentum about o: momentum() (about the base origin p_0) moved, L_o = L_0 + p_0 x P.
inline Vector6 robot_momentum_about_origin(const Model& model, const Data& data,
                                           const Eigen::Ref<const Eigen::VectorXd>& v) {
  Vector6 h = momentum(model, data, v);
  h.tail<3>() += data.p[0].cross(h.head<3>());
  return h;
}

}  // namespace detail

/// The grasp at the robot's state (base, theta, v) and the target's (position, attitude, velocity,
/// spin): the gripper (the origin of `frame`, the contact point p) and the target become one rigid
/// body. With the robot's generalized velocity and the target's twist [v_c; w] stacked as v (6+n+6),
/// M = diag(H, m_t 1, I_t,o) and J = [J_bm(p), -J_t(p)] the relative twist of gripper and target at p
/// (J_t = [1, -[p - c]x; 0, 1]), the plastic impulse solves the KKT system
///   [M J^T; J 0] [v+; -p] = [M v-; 0],
/// by its Schur complement: p = -(J M^-1 J^T)^-1 J v-, v+ = v- + M^-1 J^T p (H by Cholesky, the
/// target block by its 3x3 inertia; one 6x6 solve). p is the wrench impulse on the gripper at p;
/// the target gets -p, so the total momentum is unchanged. Cost: one CRBA and a Cholesky of H
/// (O(n^3) for n joints), six solves with it. Reads base, theta, v. Writes the kinematics, data.H,
/// data.L, data.J. Throws InputError for bad sizes, non-finite values, a bad frame or target.
inline GraspResult grasp(const Model& model, Data& data, const BasePose& base,
                         const Eigen::Ref<const Eigen::VectorXd>& theta,
                         const Eigen::Ref<const Eigen::VectorXd>& v, int frame, const Target& target) {
  constexpr const char* w = "grasp";
  detail::require_size(v.size(), model.nv(), w, "v");
  detail::require_finite_all(v, w, "v");
  detail::check_frame(model, frame, w);
  target.validate("grasp: target");
  crba(model, data, base, theta);
  frame_jacobian(model, data, frame);
  const Pose pf = frame_pose(model, data, frame);
  const Matrix3 Rt = target.rotation();
  const Matrix3 It = Rt * target.inertia * Rt.transpose();
  Eigen::Matrix<double, 6, 6> Jt = Eigen::Matrix<double, 6, 6>::Identity();
  Jt.block<3, 3>(0, 3) = -skew(pf.p - target.position);
  GraspResult r;
  r.contact_point = pf.p;
  r.v_before = v;
  r.target_before << target.velocity, target.angular_velocity_world();
  // M^-1 J^T, robot block (nv x 6) and target block (6 x 6, with a minus sign from J = [J_bm, -J_t])
  detail::cholesky(data.H, data.L, w);
  Eigen::MatrixXd MinvJr = data.J.transpose();
  for (int k = 0; k < 6; ++k) {
    Eigen::VectorXd col = MinvJr.col(k);
    detail::cholesky_solve(data.L, col);
    MinvJr.col(k) = col;
  }
  Eigen::Matrix<double, 6, 6> MinvJt = -Jt.transpose();
  MinvJt.topRows<3>() /= target.mass;
  const Eigen::Matrix<double, 3, 6> ang = MinvJt.bottomRows<3>();
  MinvJt.bottomRows<3>() = It.ldlt().solve(ang);
  const Matrix6 S = data.J * MinvJr - Jt * MinvJt;  // J M^-1 J^T
  const Vector6 rel = data.J * v - Jt * r.target_before;
  const Eigen::LLT<Matrix6> llt(S);
  if (llt.info() != Eigen::Success) FFSR_THROW(NumericalError("grasp: the lock's inverse inertia is singular"));
  r.impulse = -llt.solve(rel);
  r.v_after = v + MinvJr * r.impulse;
  r.target_after = r.target_before + MinvJt * r.impulse;
  r.relative_twist_after = data.J * r.v_after - Jt * r.target_after;
  r.base_velocity_jump = r.v_after.head<6>() - v.head<6>();
  r.momentum_before =
      detail::robot_momentum_about_origin(model, data, v) + detail::target_momentum(target, r.target_before);
  r.momentum_after = detail::robot_momentum_about_origin(model, data, r.v_after) +
                     detail::target_momentum(target, r.target_after);
  auto energy = [&](const Eigen::VectorXd& vr, const Vector6& tw) {
    return kinetic_energy(model, data, vr) + 0.5 * target.mass * tw.head<3>().squaredNorm() +
           0.5 * tw.tail<3>().dot(It * tw.tail<3>());
  };
  r.energy_before = energy(v, r.target_before);
  r.energy_after = energy(r.v_after, r.target_after);
  r.body.mass = target.mass;
  r.body.inertia = target.inertia;
  r.body.pose = Pose{pf.R.transpose() * (target.position - pf.p), pf.R.transpose() * Rt};
  return r;
}

}  // namespace ffsr
