// ffsr/algorithm/joint_models.hpp -- what the arm's joints do during the few milliseconds of a
// contact, and the effective mass (Eq. 4) and integrated effective mass (Eq. 14) under each model.
//
//  - Free: the joints carry no torque during the impact (the paper's assumption): the inverse
//    effective mass along u at the contact point is u^T J_v H^-1 J_v^T u (effective_mass.hpp).
//  - Locked: the joints do not move during the impact; base and arm react as one rigid body (the
//    composite rigid body): u^T J_b H_bb^-1 J_b^T u, with H_bb the 6x6 base block of H (the
//    composite inertia of the whole robot about the base origin) and J_b the base columns of the
//    point Jacobian, J_b^T u = [u; (p_e - p_0) x u].
//  - Armature: free joints with a reflected rotor inertia a_k per coordinate (N^2 times the
//    rotor's inertia behind a gear of ratio N; kg m^2, or kg for a prismatic joint) added to H's
//    joint diagonal: u^T J_v (H + diag(0, a))^-1 J_v^T u. It runs from Free (a = 0) towards Locked
//    (a -> infinity). The rotor's own (un-reflected) mass and inertia belong to the link model.
//
// Every function here reads H and the kinematics of the last crba (or runs crba, as it says) and
// allocates nothing: the armature's factor is written into data.L (a copy of H with the armature
// on its diagonal, factorized in place); data.H stays that of the configuration.
#pragma once

#include "ffsr/algorithm/effective_mass_gradient.hpp"

#include <string>
#include <vector>

namespace ffsr {

enum class JointModel { Free, Locked, Armature };

inline const char* joint_model_name(JointModel m) {
  switch (m) {
    case JointModel::Locked:
      return "locked";
    case JointModel::Armature:
      return "armature";
    default:
      return "free";
  }
}

/// The joint model named `name` (free, locked, armature); InputError naming `where` otherwise.
inline JointModel parse_joint_model(const std::string& name, const std::string& where) {
  if (name == "free") return JointModel::Free;
  if (name == "locked") return JointModel::Locked;
  if (name == "armature") return JointModel::Armature;
  throw InputError(detail::str(where, ": unknown joint model '", name, "'; use free, locked or armature"));
}

/// One non-negative finite value per coordinate of `model` from `values`: empty gives zeros, one value
/// is used for every joint, otherwise there must be n. InputError naming `where` (a key, "--armature"),
/// listing the joints when the count is wrong, naming the joint of a bad value.
inline Eigen::VectorXd per_joint_values(const std::vector<double>& values, const Model& model,
                                        const std::string& where) {
  const int n = model.n();
  if (!values.empty() && values.size() != 1 && int(values.size()) != n) {
    std::string list;
    for (const auto& name : model.joint_names()) list += (list.empty() ? "" : ", ") + name;
    throw InputError(detail::str(where, ": ", values.size(), " values for ", n, " joints (", list,
                                 "); give one value or one per joint"));
  }
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    if (!values.empty()) v(k) = values.size() == 1 ? values[0] : values[size_t(k)];
    if (!(v(k) >= 0) || !std::isfinite(v(k)))
      throw InputError(detail::str(where, ": the value of joint '", model.joint(k).name,
                                   "' must be finite and >= 0, got ", v(k)));
  }
  return v;
}

/// The joints' model during the contact, with the armature per coordinate (size n; used by the
/// Armature model, and by the multibody reference whatever the model).
struct ContactJoints {
  JointModel model = JointModel::Free;
  Eigen::VectorXd armature;
};

/// The joint model of a scenario: `name` (key contact-joints) and the armature values (key armature,
/// per_joint_values). InputError naming the key.
inline ContactJoints contact_joints_of(const std::string& name, const std::vector<double>& armature,
                                       const Model& model) {
  return {parse_joint_model(name, "--contact-joints"), per_joint_values(armature, model, "--armature")};
}

namespace detail {

/// data.L = the Cholesky factor of H + diag(0, armature) (H untouched). Reads data.H.
inline void factor_with_armature(Data& data, const Eigen::VectorXd& armature, const char* where) {
  data.L = data.H;
  data.L.diagonal().tail(armature.size()) += armature;
  cholesky(data.L, data.L, where);  // in place: column j reads only entries not yet overwritten
}

/// The locked system's inverse form s_b^T H_bb^-1 s_b for the wrench [f; m] at the origin of
/// `frame` (a force f at the point and a couple m), s_b = J_b^T [f; m] = [f; (p_e - p_0) x f + m];
/// writes y_b = H_bb^-1 s_b. Reads data.H, the kinematics. Writes data.w.
inline double locked_wrench_form(const Model& model, Data& data, int frame, const Vector3& f,
                                 const Vector3& m, Vector6& yb) {
  jacobian_transpose_times(model, data, frame, f, m);
  const Vector6 sb = data.w.head<6>();
  const Matrix6 Hbb = data.H.topLeftCorner<6, 6>();
  const Eigen::LLT<Matrix6> llt(Hbb);
  if (llt.info() != Eigen::Success)
    throw NumericalError("effective_mass: the locked robot's inertia is not positive definite");
  yb = llt.solve(sb);
  return sb.dot(yb);
}

/// locked_wrench_form for a unit force u alone (u along the linear velocity of the frame origin).
inline double locked_inverse_form(const Model& model, Data& data, int frame, const Vector3& u, Vector6& yb) {
  return locked_wrench_form(model, data, frame, u, Vector3::Zero(), yb);
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

}  // namespace detail

/// Inverse effective mass along the unit direction u at the origin of `frame` under the joint model
/// `joints`, at the configuration of the last crba. Free: inverse_effective_mass (the same numbers,
/// bit for bit). Reads data.H, data.Ic and the kinematics. Writes data.L, data.w, data.y.
inline double inverse_effective_mass(const Model& model, Data& data, int frame, const Vector3& u,
                                     const ContactJoints& joints) {
  switch (joints.model) {
    case JointModel::Locked: {
      detail::check_unit_direction(u, "effective_mass");
      detail::check_frame(model, frame, "effective_mass");
      Vector6 yb;
      return detail::locked_inverse_form(model, data, frame, u, yb);
    }
    case JointModel::Armature:
      detail::check_unit_direction(u, "effective_mass");
      detail::check_frame(model, frame, "effective_mass");
      detail::require_size(joints.armature.size(), model.n(), "effective_mass", "armature");
      detail::linear_jacobian_transpose_times(model, data, frame, u);
      detail::factor_with_armature(data, joints.armature, "effective_mass");
      data.y = data.w;
      detail::cholesky_forward(data.L, data.y);
      return data.y.squaredNorm();
    default:
      return inverse_effective_mass(model, data, frame, u);
  }
}

/// Effective mass m_e (Eq. 4) under the joint model. Runs crba.
inline double effective_mass(const Model& model, Data& data, const BasePose& base,
                             const Eigen::Ref<const Eigen::VectorXd>& theta, int frame, const Vector3& u,
                             const ContactJoints& joints) {
  crba(model, data, base, theta);
  return 1.0 / inverse_effective_mass(model, data, frame, u, joints);
}

/// Integrated effective mass (Eq. 14) under the joint model, u = the target's normal. Runs crba.
inline double integrated_effective_mass(const Model& model, Data& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Target& target, const ContactJoints& joints) {
  crba(model, data, base, theta);
  const double inv_me = inverse_effective_mass(model, data, frame, target.normal_world(), joints);
  return 1.0 / (inv_me + target.inverse_mass_along_normal());
}

/// integrated_effective_mass_gradient (below) at the configuration of the last crba (data.H and the
/// kinematics as crba left them), for a caller that has just run it at (base, theta): the same
/// numbers, without a second crba.
/// Writes data.L, data.w, data.y, data.V, data.F and grad (size n). Returns M_ie.
inline double integrated_effective_mass_gradient_at(const Model& model, Data& data, int frame, const Vector3& u,
                                                    double target_inverse_mass, const ContactJoints& joints,
                                                    Eigen::Ref<Eigen::VectorXd> grad) {
  if (joints.model == JointModel::Free)
    return integrated_effective_mass_gradient_at(model, data, frame, u, target_inverse_mass, grad);
  detail::require_size(grad.size(), model.n(), "integrated_effective_mass_gradient", "grad");
  detail::check_unit_direction(u, "effective_mass");
  detail::check_frame(model, frame, "effective_mass");
  double inv_me;
  if (joints.model == JointModel::Locked) {
    Vector6 yb;
    inv_me = detail::locked_inverse_form(model, data, frame, u, yb);
    detail::locked_inverse_form_gradient(model, data, frame, u, yb, grad);
  } else {
    detail::require_size(joints.armature.size(), model.n(), "effective_mass", "armature");
    detail::factor_with_armature(data, joints.armature, "effective_mass");
    Vector6 s;
    s << u, Vector3::Zero();
    inv_me = detail::inverse_inertia_form_gradient_factored(model, data, frame, s, grad);
  }
  const double M = 1.0 / (inv_me + target_inverse_mass);
  grad *= -M * M;
  return M;
}

/// Analytic gradient of the integrated effective mass in the joint angles under the joint model, at
/// a fixed base pose (see integrated_effective_mass_gradient of effective_mass.hpp; Free calls it).
/// Armature: the same gradient formula with H + diag(0, a) factorized (the armature is constant, so
/// dH/dtheta is unchanged). Locked: detail::locked_inverse_form_gradient. dM_ie = -M_ie^2 d(1/m_e).
/// Runs crba. Writes data.H, data.L, data.w, data.y, data.V, data.F and grad (size n). Returns M_ie.
inline double integrated_effective_mass_gradient(const Model& model, Data& data, const BasePose& base,
                                                 const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                                 const Vector3& u, double target_inverse_mass,
                                                 const ContactJoints& joints,
                                                 Eigen::Ref<Eigen::VectorXd> grad) {
  if (joints.model == JointModel::Free)
    return integrated_effective_mass_gradient(model, data, base, theta, frame, u, target_inverse_mass, grad);
  detail::require_size(grad.size(), model.n(), "integrated_effective_mass_gradient", "grad");
  detail::check_unit_direction(u, "effective_mass");
  detail::check_frame(model, frame, "effective_mass");
  crba(model, data, base, theta);
  return integrated_effective_mass_gradient_at(model, data, frame, u, target_inverse_mass, joints, grad);
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
      throw NumericalError("inverse_inertia_matrix: the locked robot's inertia is not positive definite");
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

}  // namespace ffsr
