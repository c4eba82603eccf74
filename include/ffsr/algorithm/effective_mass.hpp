// ffsr/algorithm/effective_mass.hpp -- the effective mass m_e (Eq. 4) and the integrated effective
// mass M_ie (Eq. 14), every overload: integrated_effective_mass takes the O(n) articulated-body
// recursion under each joint model, or for few joints the composite route (mimic joints: crba and the
// dense solve);
// integrated_effective_mass_dense is the dense evaluation (crba, Cholesky), for cross-checks.
// Their gradients: effective_mass_gradient.hpp.
#pragma once

#include "ffsr/algorithm/articulated_effective_mass.hpp"
#include "ffsr/model/target.hpp"

#include <cmath>

namespace ffsr {

namespace detail {

/// w = J^T [f; m] for the origin of `frame` (J the 6x(6+n) point Jacobian, linear rows first): the
/// generalized force that a force f at the point and a couple m produce. A unit force u at the point
/// p_e + rho is the pair (u, rho x u). Reads the kinematics. Writes data.w.
inline void jacobian_transpose_times(const Model& model, Data& data, int frame, const Vector3& f,
                                     const Vector3& m) {
  const Vector3 pe = frame_pose(model, data, frame).p;
  if (!pe.allFinite())
    FFSR_THROW(NumericalError(str("effective_mass: the position of frame '", model.frame(frame).name,
                             "' overflows double precision")));
  data.w.setZero();
  data.w.head<3>() = f;
  data.w.segment<3>(3) = (pe - data.p[0]).cross(f) + m;
  for (int i = model.frame(frame).body; i > 0; i = model.body(i).parent) {
    const auto S = data.S.col(i - 1);
    data.w(6 + model.body(i).coord) +=
        model.body(i).joint.type == JointType::Revolute
            ? S.tail<3>().dot((pe - data.p[static_cast<size_t>(i)]).cross(f)) + S.tail<3>().dot(m)
            : S.head<3>().dot(f);
  }
}

/// w = J_v^T u for the origin of `frame`: the generalized force that a unit force along u at the
/// point produces. Reads the kinematics. Writes data.w.
inline void linear_jacobian_transpose_times(const Model& model, Data& data, int frame, const Vector3& u) {
  jacobian_transpose_times(model, data, frame, u, Vector3::Zero());
}

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
  if (!solve_spd6(Hbb, sb, yb))  // the recursion's fixed-size Cholesky (Eigen's LLT: +3 s to compile)
    FFSR_THROW(NumericalError("effective_mass: the locked robot's inertia is not positive definite"));
  return sb.dot(yb);
}

/// locked_wrench_form for a unit force u alone (u along the linear velocity of the frame origin).
inline double locked_inverse_form(const Model& model, Data& data, int frame, const Vector3& u, Vector6& yb) {
  return locked_wrench_form(model, data, frame, u, Vector3::Zero(), yb);
}

}  // namespace detail

/// Inverse effective mass u^T J_v H^-1 J_v^T u (the denominator of Eq. 4) at the configuration of
/// the last crba, by the dense route: |L^-1 w|^2 with H = L L^T and w = J_v^T u (one forward
/// substitution). Reads data.H and the kinematics. Writes data.L, data.w and data.y (= L^-1 w).
/// Allocation-free, as the overload under a joint model below (the armature's factor is written into
/// data.L, a copy of H with the armature on its diagonal, factorized in place; data.H stays that of the
/// configuration). The O(n) route: inverse_effective_mass_articulated.
inline double inverse_effective_mass(const Model& model, Data& data, int frame, const Vector3& u) {
  detail::check_unit_direction(u, "effective_mass");
  detail::check_frame(model, frame, "effective_mass");
  detail::linear_jacobian_transpose_times(model, data, frame, u);
  detail::cholesky(data.H, data.L, "effective_mass");
  data.y = data.w;
  detail::cholesky_forward(data.L, data.y);
  return data.y.squaredNorm();
}

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

/// Effective mass m_e = 1 / (u^T (J_v H^-1 J_v^T) u) of the free-floating robot at the origin of
/// `frame` along the unit inertial direction u (Eq. 4). Runs crba.
inline double effective_mass(const Model& model, Data& data, const BasePose& base,
                             const Eigen::Ref<const Eigen::VectorXd>& theta, int frame, const Vector3& u) {
  crba(model, data, base, theta);
  return 1.0 / inverse_effective_mass(model, data, frame, u);
}

/// Effective mass m_e (Eq. 4) under the joint model (joint_models.hpp). Runs crba.
inline double effective_mass(const Model& model, Data& data, const BasePose& base,
                             const Eigen::Ref<const Eigen::VectorXd>& theta, int frame, const Vector3& u,
                             const ContactJoints& joints) {
  crba(model, data, base, theta);
  return 1.0 / inverse_effective_mass(model, data, frame, u, joints);
}

/// Integrated effective mass (Eq. 14) from the robot's effective mass along u = R_t u_n:
/// M_ie = 1 / (1/m_e + 1/m_t + (r x u)^T I^-1 (r x u)), r = R_t r_tp, I = R_t I_t R_t^T.
/// NumericalError when the sum of the inverses overflows (a denormal m_e: M_ie would read 0).
inline double integrated_effective_mass(double m_e, const Target& target) {
  if (!(m_e > 0) || !std::isfinite(m_e))
    FFSR_THROW(InputError(detail::str("integrated_effective_mass: m_e must be positive and finite, got ", m_e)));
  const double inverse = 1.0 / m_e + target.inverse_mass_along_normal();
  if (!std::isfinite(inverse))
    FFSR_THROW(NumericalError(
        detail::str("integrated_effective_mass: 1/m_e + 1/m_t overflows double precision, m_e = ", m_e)));
  return 1.0 / inverse;
}

/// Kept for callers that chose the route by size: integrated_effective_mass never takes the dense
/// route (crba and a Cholesky factorization of H) for a tree, from one joint on.
inline constexpr int kArticulatedMinJoints = 1;

/// Up to this many joints integrated_effective_mass takes the composite route
/// (detail::inverse_form_composite: the composite inertias and the floating base's Schur complement,
/// O(n^2) entries and an n x n factorization), above it the O(n) recursion. The rule is the size at
/// which the two cost the same on ffsr-bench-pinocchio's chains (7 to 8 joints with random axes: the
/// composite route 2-5 % faster at 7, the recursion 1-2 % faster at 8, 10-15 % at 10-12; the
/// composite route is 10-15 % faster at 3 joints).
inline constexpr int kCompositeMaxJoints = 7;

namespace detail {
/// True when integrated_effective_mass takes the articulated-body recursion: at least
/// kArticulatedMinJoints joints and one body per coordinate (a mimic joint couples bodies through one
/// coordinate, which is not a tree recursion: such a model takes the dense route).
inline bool takes_recursion(const Model& model) {
  return model.n() >= kArticulatedMinJoints && model.nb() - 1 == model.n();
}

/// Returns M = 1 / (inverse + target_inverse_mass); NumericalError unless M is positive and finite
/// (a robot whose finite values overflow its inverse effective mass would read M_ie = 0).
inline double integrated_from_inverse(double inverse, double target_inverse_mass) {
  const double M = 1.0 / (inverse + target_inverse_mass);
  if (!(M > 0.0) || !std::isfinite(M))
    FFSR_THROW(NumericalError(str("integrated_effective_mass: M_ie is not representable (1/m_e = ", inverse,
                             ", target's inverse mass ", target_inverse_mass, ")")));
  return M;
}

/// True when integrated_effective_mass tries the composite route (detail::inverse_form_composite)
/// before the recursion: a depth-first model with one body per coordinate and at most
/// kCompositeMaxJoints joints, under the Free or Armature joint model.
inline bool takes_composite(const Model& model, const ContactJoints& joints) {
  return joints.model != JointModel::Locked && model.depth_first() && model.nb() - 1 == model.n() &&
         model.n() <= kCompositeMaxJoints;
}

/// The inverse effective mass by the route integrated_effective_mass takes (after the kinematics).
inline double inverse_effective_mass_routed(const Model& model, Data& data, int frame, const Vector3& u,
                                            const ContactJoints& joints) {
  if (takes_composite(model, joints)) {
    const Vector6 f = unit_point_force(model, data, frame, u);
    double q = 0.0;
    if (inverse_form_composite(model, data, model.frame(frame).body, f, armature_of(model, joints), q))
      return q;
  }
  return inverse_effective_mass_articulated(model, data, frame, u, joints);
}

inline void check_target_inverse_mass(double target_inverse_mass) {
  if (!(target_inverse_mass >= 0.0) || !std::isfinite(target_inverse_mass))
    FFSR_THROW(InputError(str("integrated_effective_mass: the target's inverse mass along the normal must be ",
                         "finite and >= 0, got ", target_inverse_mass)));
}
}  // namespace detail

/// Integrated effective mass (Eq. 14) by the dense route: crba, then
/// M_ie = 1 / (u^T J_v (H + ...)^-1 J_v^T u + target_inverse_mass) by a Cholesky solve
/// (inverse_effective_mass under the joint model, above), u the unit contact normal in the
/// inertial frame and target_inverse_mass = Target::inverse_mass_along_normal. O(n^2) to O(n^3): for
/// tests and cross-checks of integrated_effective_mass, which gives the same value to rounding.
/// Writes data.H (valid afterwards), data.L, data.w, data.y. InputError for a target_inverse_mass
/// that is negative or not finite; NumericalError when M_ie is not representable.
inline double integrated_effective_mass_dense(const Model& model, Data& data, const BasePose& base,
                                              const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                              const Vector3& u, double target_inverse_mass,
                                              const ContactJoints& joints = ContactJoints{}) {
  detail::check_target_inverse_mass(target_inverse_mass);
  crba(model, data, base, theta);
  return detail::integrated_from_inverse(inverse_effective_mass(model, data, frame, u, joints),
                                         target_inverse_mass);
}

/// integrated_effective_mass_dense with the end-effector `frame` touching `target` (u = R_t u_n).
inline double integrated_effective_mass_dense(const Model& model, Data& data, const BasePose& base,
                                              const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                              const Target& target,
                                              const ContactJoints& joints = ContactJoints{}) {
  return integrated_effective_mass_dense(model, data, base, theta, frame, target.normal_world(),
                                         target.inverse_mass_along_normal(), joints);
}

/// Integrated effective mass (Eq. 14) of the robot at (base, theta) touching at the origin of `frame`,
/// under the joint model `joints` (Free by default), for the unit contact normal u (inertial frame)
/// and the target's inverse mass along it, target_inverse_mass = Target::inverse_mass_along_normal:
/// M_ie = 1 / (1/m_e + target_inverse_mass). In O(n) by the articulated-body recursion
/// (inverse_effective_mass_articulated: Free, Armature with its a_i, Locked from the composite
/// inertia of the whole robot), without forming H; up to kCompositeMaxJoints joints (Free and
/// Armature, depth-first models) by the composite route, which hands the cases it cannot decide (an
/// inertia that is not positive definite, an overflow) to the recursion; a model with mimic joints
/// takes the dense route (integrated_effective_mass_dense). The routes agree to rounding (tested to
/// 1e-12 relative). Writes the kinematics and the routes' fields (data.Ic, data.Fc, data.L, data.w,
/// data.y and the recursion's; data.H for mimics): do not rely on data.H afterwards. Errors as
/// integrated_effective_mass_dense.
inline double integrated_effective_mass(const Model& model, Data& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Vector3& u, double target_inverse_mass,
                                        const ContactJoints& joints = ContactJoints{}) {
  if (!detail::takes_recursion(model))
    return integrated_effective_mass_dense(model, data, base, theta, frame, u, target_inverse_mass, joints);
  detail::check_target_inverse_mass(target_inverse_mass);
  forward_kinematics(model, data, base, theta);
  return detail::integrated_from_inverse(detail::inverse_effective_mass_routed(model, data, frame, u, joints),
                                         target_inverse_mass);
}

/// Integrated effective mass (Eq. 14) of the robot at (base, theta) with the end-effector `frame`
/// touching `target` (its attitude gives u = R_t u_n), under the joint model `joints` (Free by
/// default); the O(n) route above. Does not validate the target on every call: validate it once
/// (Target::validate) when it is made.
inline double integrated_effective_mass(const Model& model, Data& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Target& target, const ContactJoints& joints = ContactJoints{}) {
  return integrated_effective_mass(model, data, base, theta, frame, target.normal_world(),
                                   target.inverse_mass_along_normal(), joints);
}

}  // namespace ffsr
