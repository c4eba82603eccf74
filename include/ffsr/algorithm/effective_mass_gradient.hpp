// ffsr/algorithm/effective_mass_gradient.hpp -- the robot's inverse inertia at a frame
// (inverse_inertia_matrix) and the analytic gradients in the joint angles of its quadratic forms and
// of M_ie (Eq. 14), every overload and joint model. Apart from effective_mass.hpp so that a
// translation unit that needs only m_e and M_ie does not compile them.
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"

namespace ffsr {

/// The robot's 6x6 inverse inertia at the origin of `frame`, Lambda^-1 = J H^-1 J^T (J the point
/// Jacobian of frame_jacobian, linear rows first, for the free-floating system: the base moves under
/// momentum conservation). For a unit force u at the point p_e + rho (rho in the inertial frame),
/// the robot's inverse effective mass is s^T Lambda^-1 s with s = [u; rho x u]; its top-left 3x3
/// block is G = J_v H^-1 J_v^T. Computed as Y^T Y with Y = L^-1 J^T (six forward substitutions),
/// symmetrized.
/// Reads data.H (crba) and the kinematics. Writes data.L, data.w and data.y.
inline Matrix6 inverse_inertia_matrix(const Model& model, Data& data, int frame) {
  detail::check_frame(model, frame, "inverse_inertia_matrix");
  detail::cholesky(data.H, data.L, "inverse_inertia_matrix");
  Eigen::Matrix<double, Eigen::Dynamic, 6> Y(data.H.rows(), 6);
  for (int k = 0; k < 6; ++k) {
    Vector6 e = Vector6::Unit(k);
    detail::jacobian_transpose_times(model, data, frame, e.head<3>(), e.tail<3>());
    data.y = data.w;
    detail::cholesky_forward(data.L, data.y);
    Y.col(k) = data.y;
  }
  const Matrix6 L = Y.transpose() * Y;
  return 0.5 * (L + L.transpose());  // exactly symmetric (the product's rounding is not)
}

/// The robot's 6x6 inverse inertia Lambda^-1 at the origin of `frame` under the joint model, at the
/// configuration of the last crba: for a wrench s = [f; m] at the point (a force f and a couple m,
/// inertial frame) s^T Lambda^-1 s is the inverse effective mass of that wrench. Free:
/// inverse_inertia_matrix, J H^-1 J^T. Armature: J (H + diag(0, a))^-1 J^T, as Y^T Y with
/// Y = L_a^-1 J^T. Locked: X^T H_bb^-1 X with X = [E 0; [p_e - p_0]x E], which maps the wrench to the
/// base wrench s_b = J_b^T s. Exactly symmetric. Reads data.H and the kinematics. Writes data.L (the
/// factor of H, or of H + diag(0, a)), data.w and data.y.
inline Matrix6 inverse_inertia_matrix(const Model& model, Data& data, int frame,
                                      const ContactJoints& joints) {
  if (joints.model == JointModel::Free) return inverse_inertia_matrix(model, data, frame);
  detail::check_frame(model, frame, "inverse_inertia_matrix");
  Matrix6 Linv;
  if (joints.model == JointModel::Locked) {
    Matrix6 X = Matrix6::Identity();
    X.bottomLeftCorner<3, 3>() = skew(frame_pose(model, data, frame).p - data.p[0]);
    const Matrix6 Hbb = data.H.topLeftCorner<6, 6>();
    const Eigen::LLT<Matrix6> llt(Hbb);
    if (llt.info() != Eigen::Success)
      FFSR_THROW(NumericalError("inverse_inertia_matrix: the locked robot's inertia is not positive definite"));
    Linv = X.transpose() * llt.solve(X);
  } else {
    detail::require_size(joints.armature.size(), model.n(), "inverse_inertia_matrix", "armature");
    detail::factor_with_armature(data, joints.armature, "inverse_inertia_matrix");
    Eigen::Matrix<double, Eigen::Dynamic, 6> Y(data.H.rows(), 6);
    for (int k = 0; k < 6; ++k) {
      const Vector6 e = Vector6::Unit(k);
      detail::jacobian_transpose_times(model, data, frame, e.head<3>(), e.tail<3>());
      data.y = data.w;
      detail::cholesky_forward(data.L, data.y);
      Y.col(k) = data.y;
    }
    Linv = Y.transpose() * Y;
  }
  return 0.5 * (Linv + Linv.transpose());
}

namespace detail {

/// Marks the bodies on the path from `body` to the base (the base included) in data.on_path.
inline void mark_path(const Model& model, Data& data, int body) {
  std::fill(data.on_path.begin(), data.on_path.end(), char(0));
  for (int i = body; i >= 0; i = model.body(i).parent) data.on_path[static_cast<size_t>(i)] = 1;
}

/// The gradient part of inverse_inertia_form_gradient for s = [u; mc], given y = H^-1 w in data.y
/// (whichever way it was solved): the velocities V_i and subtree momenta F_i of the bodies for the
/// generalized velocity y, then per joint k: 2 s . d(J y)/dtheta_k - 2 (V_k x S_k) . F_k. O(n).
/// Reads data.y and the kinematics. Writes data.V, data.F, data.on_path and grad (size n).
inline void inverse_inertia_form_gradient_from_y(const Model& model, Data& data, int frame, const Vector3& u,
                                                 const Vector3& mc, Eigen::Ref<Eigen::VectorXd> grad) {
  const int nb = model.nb();
  const Vector3& p0 = data.p[0];
  // velocities and momenta of the bodies for the generalized velocity y
  data.V[0] = data.y.head<6>();
  for (int i = 1; i < nb; ++i)
    data.V[static_cast<size_t>(i)] = data.V[static_cast<size_t>(model.body(i).parent)] +
                                     data.S.col(i - 1) * data.y(6 + model.body(i).coord);
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    data.F[ui] = SpatialInertia::from_body(in.mass, in.com, in.I, data.R[ui], data.p[ui] - p0) * data.V[ui];
  }
  for (int i = nb - 1; i > 0; --i)
    data.F[static_cast<size_t>(model.body(i).parent)] += data.F[static_cast<size_t>(i)];
  const int ee_body = model.frame(frame).body;
  mark_path(model, data, ee_body);
  const Vector3 pe = frame_pose(model, data, frame).p;
  const Vector6& Vee = data.V[static_cast<size_t>(ee_body)];
  grad.setZero();
  for (int i = 1; i < nb; ++i) {  // body i adds its part to the gradient entry of its coordinate
    const auto ui = static_cast<size_t>(i);
    const Vector6 S = data.S.col(i - 1);
    const double yHy = 2.0 * cross_motion(data.V[ui], S).dot(data.F[ui]);
    double sdv = 0.0;
    if (data.on_path[ui]) {  // joint i carries the end-effector
      const Vector6 X = cross_motion(S, Vee - data.V[ui]);  // d(V_ee)/dtheta_k, referred to p0
      const Vector3 dp = S.head<3>() + S.tail<3>().cross(pe - p0);
      sdv = u.dot(X.head<3>() + X.tail<3>().cross(pe - p0) + Vee.tail<3>().cross(dp)) + mc.dot(X.tail<3>());
    }
    grad(model.body(i).coord) += 2.0 * sdv - yHy;
  }
}

/// inverse_inertia_form_gradient with data.L already the Cholesky factor of data.H (callers that
/// evaluate several forms at one configuration factorize once). No argument checks.
inline double inverse_inertia_form_gradient_factored(const Model& model, Data& data, int frame,
                                                     const Vector6& s, Eigen::Ref<Eigen::VectorXd> grad) {
  const Vector3 u = s.head<3>(), mc = s.tail<3>();
  detail::jacobian_transpose_times(model, data, frame, u, mc);
  data.y = data.w;
  detail::cholesky_forward(data.L, data.y);
  const double q = data.y.squaredNorm();
  detail::cholesky_backward(data.L, data.y);  // y = H^-1 w
  inverse_inertia_form_gradient_from_y(model, data, frame, u, mc, grad);
  return q;
}

/// Gradient of the locked form q = s_b^T H_bb^-1 s_b in the joint angles at a fixed base pose, for
/// the wrench [u; m] (the couple m constant in the inertial frame, as the base pose is):
/// dq/dtheta_k = 2 y_b . d s_b/dtheta_k - y_b^T dH_bb/dtheta_k y_b, where d s_b = [0; dp_e x u]
/// (dp_e the motion of the contact point for the twist S_k, when joint k carries it) and, as the
/// subtree of k (composite inertia Ic_k) moves by S_k, y^T dH_bb y = -2 (S_k x y) . (Ic_k y).
/// Reads data.Ic (crba), data.S and the kinematics. Writes data.on_path and grad (size n). O(n).
inline void locked_inverse_form_gradient(const Model& model, Data& data, int frame, const Vector3& u,
                                         const Vector6& yb, Eigen::Ref<Eigen::VectorXd> grad) {
  const int ee_body = model.frame(frame).body;
  const Vector3 pe = frame_pose(model, data, frame).p;
  const Vector3& p0 = data.p[0];
  mark_path(model, data, ee_body);
  grad.setZero();
  for (int i = 1; i < model.nb(); ++i) {
    const Vector6 S = data.S.col(i - 1);
    const double yHy = -2.0 * cross_motion(S, yb).dot(data.Ic[static_cast<size_t>(i)] * yb);
    double dsy = 0.0;
    if (data.on_path[static_cast<size_t>(i)]) {  // joint i carries the contact point
      const Vector3 dp = S.head<3>() + S.tail<3>().cross(pe - p0);
      dsy = yb.tail<3>().dot(dp.cross(u));
    }
    grad(model.body(i).coord) += 2.0 * dsy - yHy;
  }
}

/// The gradient of q = s^T Lambda^-1 s under the joint model with the factor already in data.L: that
/// of H (Free) or of H + diag(0, a) (Armature), as inverse_inertia_matrix(joints) leaves it; Locked
/// reads data.H alone. No argument checks. Writes data.w, data.y, data.V, data.F and grad. Returns q.
inline double inverse_inertia_form_gradient_prepared(const Model& model, Data& data, int frame,
                                                     const Vector6& s, const ContactJoints& joints,
                                                     Eigen::Ref<Eigen::VectorXd> grad) {
  if (joints.model != JointModel::Locked)  // the armature is constant: dH/dtheta is that of H
    return inverse_inertia_form_gradient_factored(model, data, frame, s, grad);
  Vector6 yb;
  const double q = locked_wrench_form(model, data, frame, s.head<3>(), s.tail<3>(), yb);
  locked_inverse_form_gradient(model, data, frame, s.head<3>(), yb, grad);
  return q;
}

}  // namespace detail

/// Analytic gradient in the joint angles of the quadratic form q = s^T Lambda^-1 s of the robot's
/// inverse inertia at the origin of `frame` (inverse_inertia_matrix) for a constant s = [f; m] in the
/// inertial frame, at a fixed base pose. With w = J^T s, y = H^-1 w and q = w^T y:
///   dq/dtheta_k = 2 s . d(J y)/dtheta_k - y^T (dH/dtheta_k) y,
/// where y^T (dH/dtheta_k) y = 2 (V_k x S_k) . h_k (V_k the spatial velocity of body k and h_k the
/// spatial momentum of the subtree of k, both for the velocity y), and d(J y)/dtheta_k -- the change
/// of the end-effector's linear velocity at its origin and of its angular velocity -- follows from
/// moving the subtree of k by the twist S_k. O(n) after the Cholesky factorization. For s = [u; 0]
/// q is the inverse effective mass of Eq. 4; for s = [u; rho x u], that at the point p_e + rho
/// (rho held fixed in the inertial frame). Reads data.H (crba) and the kinematics. Writes data.L,
/// data.w, data.y, data.V, data.F, data.on_path and `grad` (size n). Returns q.
inline double inverse_inertia_form_gradient(const Model& model, Data& data, int frame, const Vector6& s,
                                            Eigen::Ref<Eigen::VectorXd> grad) {
  detail::require_size(grad.size(), model.n(), "inverse_inertia_form_gradient", "grad");
  detail::check_frame(model, frame, "inverse_inertia_form_gradient");
  detail::require_finite_all(s, "inverse_inertia_form_gradient", "s");
  detail::cholesky(data.H, data.L, "inverse_inertia_form_gradient");
  return detail::inverse_inertia_form_gradient_factored(model, data, frame, s, grad);
}

/// Analytic gradient in the joint angles of q = s^T Lambda^-1 s (Lambda^-1 of
/// inverse_inertia_matrix under the joint model) for a constant wrench s = [f; m], at a fixed base
/// pose and the configuration of the last crba. Free: inverse_inertia_form_gradient. Armature: the
/// same with H + diag(0, a) factorized. Locked: detail::locked_inverse_form_gradient with f in place
/// of u. Writes data.L, data.w, data.y, data.V, data.F and grad (size n). Returns q.
inline double inverse_inertia_form_gradient(const Model& model, Data& data, int frame, const Vector6& s,
                                            const ContactJoints& joints, Eigen::Ref<Eigen::VectorXd> grad) {
  if (joints.model == JointModel::Free) return inverse_inertia_form_gradient(model, data, frame, s, grad);
  detail::require_size(grad.size(), model.n(), "inverse_inertia_form_gradient", "grad");
  detail::check_frame(model, frame, "inverse_inertia_form_gradient");
  detail::require_finite_all(s, "inverse_inertia_form_gradient", "s");
  if (joints.model == JointModel::Armature) {
    detail::require_size(joints.armature.size(), model.n(), "inverse_inertia_form_gradient", "armature");
    detail::factor_with_armature(data, joints.armature, "inverse_inertia_form_gradient");
  }
  return detail::inverse_inertia_form_gradient_prepared(model, data, frame, s, joints, grad);
}

/// integrated_effective_mass_gradient_dense (below) at the configuration of the last crba (data.H and the
/// kinematics as crba left them), for a caller that has just run it at (base, theta): the same
/// numbers, without a second crba. Free: inverse_inertia_form_gradient for s = [u; 0]. Armature: the
/// same formula with H + diag(0, a) factorized (the armature is constant, so dH/dtheta is unchanged).
/// Locked: detail::locked_inverse_form_gradient. dM_ie = -M_ie^2 d(1/m_e).
/// Writes data.L, data.w, data.y, data.V, data.F and grad (size n). Returns M_ie.
inline double integrated_effective_mass_gradient_at(const Model& model, Data& data, int frame,
                                                    const Vector3& u, double target_inverse_mass,
                                                    const ContactJoints& joints,
                                                    Eigen::Ref<Eigen::VectorXd> grad) {
  detail::require_size(grad.size(), model.n(), "integrated_effective_mass_gradient", "grad");
  detail::check_unit_direction(u, "effective_mass");
  detail::check_frame(model, frame, "effective_mass");
  double inv_me = 0;
  if (joints.model == JointModel::Locked) {
    Vector6 yb;
    inv_me = detail::locked_inverse_form(model, data, frame, u, yb);
    detail::locked_inverse_form_gradient(model, data, frame, u, yb, grad);
  } else {
    if (joints.model == JointModel::Armature) {
      detail::require_size(joints.armature.size(), model.n(), "effective_mass", "armature");
      detail::factor_with_armature(data, joints.armature, "effective_mass");
    } else {
      detail::cholesky(data.H, data.L, "inverse_inertia_form_gradient");
    }
    Vector6 s;
    s << u, Vector3::Zero();
    inv_me = detail::inverse_inertia_form_gradient_factored(model, data, frame, s, grad);
  }
  const double M = 1.0 / (inv_me + target_inverse_mass);
  grad *= -M * M;
  return M;
}

/// integrated_effective_mass_gradient_at for the free joints (the paper's).
inline double integrated_effective_mass_gradient_at(const Model& model, Data& data, int frame,
                                                    const Vector3& u, double target_inverse_mass,
                                                    Eigen::Ref<Eigen::VectorXd> grad) {
  return integrated_effective_mass_gradient_at(model, data, frame, u, target_inverse_mass, ContactJoints{},
                                               grad);
}

/// Analytic gradient of the integrated effective mass with respect to the joint angles under the
/// joint model, at a fixed base pose and for a fixed inertial contact direction u and target inverse
/// mass along the normal (Target::inverse_mass_along_normal), by the dense route (crba, then
/// integrated_effective_mass_gradient_at): with 1/m_e = q(u) of inverse_inertia_form_gradient for
/// s = [u; 0], dM_ie = -M_ie^2 d(1/m_e). Writes data.H, data.L, data.w, data.y, data.V, data.F and
/// grad (size n). Returns M_ie.
inline double integrated_effective_mass_gradient_dense(const Model& model, Data& data, const BasePose& base,
                                                       const Eigen::Ref<const Eigen::VectorXd>& theta,
                                                       int frame, const Vector3& u,
                                                       double target_inverse_mass,
                                                       const ContactJoints& joints,
                                                       Eigen::Ref<Eigen::VectorXd> grad) {
  crba(model, data, base, theta);  // integrated_effective_mass_gradient_at checks grad, u and frame
  return integrated_effective_mass_gradient_at(model, data, frame, u, target_inverse_mass, joints, grad);
}

/// integrated_effective_mass_gradient_dense for the free joints (the paper's).
inline double integrated_effective_mass_gradient_dense(const Model& model, Data& data, const BasePose& base,
                                                       const Eigen::Ref<const Eigen::VectorXd>& theta,
                                                       int frame, const Vector3& u,
                                                       double target_inverse_mass,
                                                       Eigen::Ref<Eigen::VectorXd> grad) {
  return integrated_effective_mass_gradient_dense(model, data, base, theta, frame, u, target_inverse_mass,
                                                  ContactJoints{}, grad);
}

/// Analytic gradient of the integrated effective mass in the joint angles under the joint model, at a
/// fixed base pose, in O(n): the same formula as integrated_effective_mass_gradient_dense
/// (inverse_inertia_form_gradient: dq = 2 s . d(J y) - y^T dH y with q = 1/m_e, y = (H + diag(0, a))^-1 w,
/// w = J_v^T u), with y the generalized acceleration of the articulated-body algorithm under the test
/// force (detail::articulated_solve with every body) instead of a dense Cholesky solve; Locked: the
/// composite inertias and detail::locked_inverse_form_gradient. dM_ie = -M_ie^2 d(1/m_e). Mimic joints:
/// integrated_effective_mass_gradient_dense. Runs forward_kinematics. Writes the recursion's fields,
/// data.Ic (composite when Locked), data.y, data.V, data.F and grad (size n); not data.H. Returns M_ie.
inline double integrated_effective_mass_gradient(const Model& model, Data& data, const BasePose& base,
                                                 const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                                 const Vector3& u, double target_inverse_mass,
                                                 const ContactJoints& joints,
                                                 Eigen::Ref<Eigen::VectorXd> grad) {
  if (model.nb() - 1 != model.n())
    return integrated_effective_mass_gradient_dense(model, data, base, theta, frame, u, target_inverse_mass,
                                                    joints, grad);
  detail::require_size(grad.size(), model.n(), "integrated_effective_mass_gradient", "grad");
  forward_kinematics(model, data, base, theta);
  const Vector6 f = detail::unit_point_force(model, data, frame, u);
  double inv_me = 0;
  if (joints.model == JointModel::Locked) {
    detail::composite_inertias(model, data);
    Vector6 yb;
    inv_me = detail::locked_inverse_form_composite(data, f, yb);
    detail::locked_inverse_form_gradient(model, data, frame, u, yb, grad);
  } else {
    detail::articulated_inertias(model, data, detail::armature_of(model, joints));
    inv_me = detail::articulated_solve(model, data, model.frame(frame).body, f, true);
    detail::inverse_inertia_form_gradient_from_y(model, data, frame, f.head<3>(), Vector3::Zero(), grad);
  }
  const double M = 1.0 / (inv_me + target_inverse_mass);
  grad *= -M * M;
  return M;
}

}  // namespace ffsr
