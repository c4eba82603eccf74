// ffsr/algorithm/base_disturbance.hpp -- the jump of the base's velocity caused by the contact impulse
// of a capture (the impact disturbance of the spacecraft's bus).
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/contact/contact_law.hpp"

// The contact lasts milliseconds, so over it the configuration stays put and only the impulse
// P = integral of F dt matters: the robot receives -P u at its contact point p_e + rho, and its
// generalized velocity jumps by
//     Delta [v_0; w_0; theta_dot] = H^-1 J^T [-P u; rho x (-P u)]            (impulsive dynamics)
// with H the free-floating inertia matrix (crba) and J the 6x(6+n) point Jacobian of the end-effector
// frame (frame_jacobian). The base rows are the jump of the base origin's velocity v_0 and of the
// base's angular velocity w_0, inertial frame, as in model.hpp. The joints are passive at the impact.
//
// The impulse follows from the single-body model of the contact (Eq. 16, M_ie delta_ddot = -F): with
// the approach rate delta_dot^- and the separation rate -e delta_dot^-, P = M_ie delta_dot^- (1 + e).
// For the Hertz-damped law F = K delta^alpha (1 + f delta_dot / delta_dot^-) (Eq. 15, 22), dividing
// the equation of motion by (1 + f s), s = delta_dot / delta_dot^-, separates it:
//     s ds / (1 + f s) = -(K / (M_ie delta_dot^-2)) delta^alpha d delta,
// and the right side integrates to zero over the whole contact (delta returns to 0). So the realized
// restitution e is the root of G(-e) = 0 with G(s) = integral_s^1 sigma / (1 + f sigma) d sigma
// (contact_law.hpp, detail::contact_G): it depends only on the damping factor f(c_r) of the law, not
// on K, alpha, M_ie or delta_dot^- (f = 0: e = 1). simulate_single_body measures the same number
// (SingleBodyResult::restitution); a test compares them.

namespace ffsr {

/// The impact disturbance of the base at a capture configuration (single-body impulse).
struct BaseDisturbance {
  double M_ie = 0;                    ///< integrated effective mass (Eq. 14), kg
  double approach_velocity = 0;       ///< delta_dot^-, m/s
  double restitution = 0;             ///< e of the single-body model (realized by the law)
  double impulse = 0;                 ///< P = M_ie delta_dot^- (1 + e), N s
  Vector3 linear = Vector3::Zero();   ///< jump of the base origin's velocity, m/s (inertial frame)
  Vector3 angular = Vector3::Zero();  ///< jump of the base's angular velocity, rad/s (inertial frame)
  /// |Delta w_0|, rad/s
  double angular_rate() const { return angular.norm(); }
};

/// The realized coefficient of restitution of the Hertz-damped law with damping factor f >= 0 in
/// the single-body model (the file comment): the root e in (0, 1] of G(-e) = 0, by bisection to
/// rounding. InputError for a negative or non-finite f.
inline double single_body_restitution(double f);

/// The same for a law: single_body_restitution(damping_factor(law)).
inline double single_body_restitution(const AnyContactLaw& law) {
  return single_body_restitution(damping_factor(law));
}

/// The base rows of H^-1 J^T [u; rho x u]: the jump of [v_0; w_0] per unit impulse along +u applied
/// to the robot at its contact point p_e + rho (rho inertial, from the origin of `frame`).
/// Reads data.H (crba) and the kinematics. Writes data.L, data.w and data.y (= H^-1 J^T [u; rho x u]).
inline Vector6 base_velocity_per_unit_impulse(const Model& model, Data& data, int frame, const Vector3& u,
                                              const Vector3& rho = Vector3::Zero());

/// The same under the joint model of the contact (joint_models.hpp): Free as above; Armature, the
/// base rows of (H + diag(0, a))^-1 J^T s; Locked, H_bb^-1 J_b^T s (the robot moves as one rigid
/// body). Writes inverse_mass = s^T Lambda^-1 s of that model, s = [u; rho x u]. Reads data.H (crba)
/// and the kinematics. Writes data.L, data.w and data.y.
inline Vector6 base_velocity_per_unit_impulse(const Model& model, Data& data, int frame, const Vector3& u,
                                              const ContactJoints& joints, double& inverse_mass,
                                              const Vector3& rho = Vector3::Zero());

/// The impact disturbance at the configuration of the last crba: the contact along the unit
/// inertial direction u (the robot approaches along +u and receives -P u), the target's inverse
/// mass along the normal (Target::inverse_mass_along_normal) and `law` (its approach velocity is
/// delta_dot^-). M_ie = 1 / (s^T Lambda^-1 s + target_inverse_mass), s = [u; rho x u].
/// Reads data.H and the kinematics. Writes data.L, data.w, data.y.
inline BaseDisturbance base_disturbance_at(const Model& model, Data& data, int frame, const Vector3& u,
                                           double target_inverse_mass, const AnyContactLaw& law,
                                           const Vector3& rho = Vector3::Zero());

/// The same under the joint model of the contact (M_ie and the base's jump of that model).
inline BaseDisturbance base_disturbance_at(const Model& model, Data& data, int frame, const Vector3& u,
                                           double target_inverse_mass, const AnyContactLaw& law,
                                           const ContactJoints& joints, const Vector3& rho = Vector3::Zero());

/// The impact disturbance of the robot at (base, theta) with `frame` touching `target` (its attitude
/// gives u = R_t u_n) under `law`. Runs crba. Writes data.
inline BaseDisturbance base_disturbance(const Model& model, Data& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Target& target, const AnyContactLaw& law,
                                        const Vector3& rho = Vector3::Zero()) {
  crba(model, data, base, theta);
  return base_disturbance_at(model, data, frame, target.normal_world(), target.inverse_mass_along_normal(),
                             law, rho);
}

/// base_disturbance under the joint model of the contact. Runs crba. Writes data.
inline BaseDisturbance base_disturbance(const Model& model, Data& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Target& target, const AnyContactLaw& law,
                                        const ContactJoints& joints, const Vector3& rho = Vector3::Zero()) {
  crba(model, data, base, theta);
  return base_disturbance_at(model, data, frame, target.normal_world(), target.inverse_mass_along_normal(),
                             law, joints, rho);
}

// ============================================================================================
// Implementation
// ============================================================================================

inline double single_body_restitution(double f) {
  if (!std::isfinite(f) || f < 0.0)
    FFSR_THROW(InputError(
        detail::str("single_body_restitution: the damping factor must be >= 0 and finite, got ", f)));
  if (f == 0.0) return 1.0;
  // G is increasing in s on s < 0 (dG/ds = -s/(1 + f s)), positive at 0, <= 0 at -1 and -> -inf at
  // -1/f: the root lies in (max(-1, -1/f), 0).
  double lo = std::max(-1.0, -1.0 / f), hi = 0.0;
  for (int it = 0; it < 200 && hi - lo > 4 * std::numeric_limits<double>::epsilon(); ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    if (1.0 + f * mid <= 0.0 || detail::contact_G(f, mid) < 0.0)
      lo = mid;
    else
      hi = mid;
  }
  return -0.5 * (lo + hi);
}

inline Vector6 base_velocity_per_unit_impulse(const Model& model, Data& data, int frame, const Vector3& u,
                                              const Vector3& rho) {
  detail::check_frame(model, frame, "base_disturbance");
  detail::require_finite_all(u, "base_disturbance", "direction u");
  detail::require_finite_all(rho, "base_disturbance", "contact offset rho");
  detail::jacobian_transpose_times(model, data, frame, u, rho.cross(u));
  detail::cholesky(data.H, data.L, "base_disturbance");
  data.y = data.w;
  detail::cholesky_forward(data.L, data.y);
  detail::cholesky_backward(data.L, data.y);
  return data.y.head<6>();
}

inline Vector6 base_velocity_per_unit_impulse(const Model& model, Data& data, int frame, const Vector3& u,
                                              const ContactJoints& joints, double& inverse_mass,
                                              const Vector3& rho) {
  if (joints.model == JointModel::Free) {
    Vector6 b = base_velocity_per_unit_impulse(model, data, frame, u, rho);
    inverse_mass = data.w.dot(data.y);  // s^T J H^-1 J^T s
    return b;
  }
  detail::check_frame(model, frame, "base_disturbance");
  detail::require_finite_all(u, "base_disturbance", "direction u");
  detail::require_finite_all(rho, "base_disturbance", "contact offset rho");
  if (joints.model == JointModel::Locked) {
    Vector6 yb;
    inverse_mass = detail::locked_wrench_form(model, data, frame, u, rho.cross(u), yb);
    return yb;
  }
  detail::require_size(joints.armature.size(), model.n(), "base_disturbance", "armature");
  detail::jacobian_transpose_times(model, data, frame, u, rho.cross(u));
  detail::factor_with_armature(data, joints.armature, "base_disturbance");
  data.y = data.w;
  detail::cholesky_forward(data.L, data.y);
  detail::cholesky_backward(data.L, data.y);
  inverse_mass = data.w.dot(data.y);
  return data.y.head<6>();
}

inline BaseDisturbance base_disturbance_at(const Model& model, Data& data, int frame, const Vector3& u,
                                           double target_inverse_mass, const AnyContactLaw& law,
                                           const Vector3& rho) {
  return base_disturbance_at(model, data, frame, u, target_inverse_mass, law, ContactJoints{}, rho);
}

inline BaseDisturbance base_disturbance_at(const Model& model, Data& data, int frame, const Vector3& u,
                                           double target_inverse_mass, const AnyContactLaw& law,
                                           const ContactJoints& joints, const Vector3& rho) {
  detail::check_unit_direction(u, "base_disturbance");
  BaseDisturbance d;
  double inv_me = 0;
  const Vector6 per_unit = base_velocity_per_unit_impulse(model, data, frame, u, joints, inv_me, rho);
  d.M_ie = 1.0 / (inv_me + target_inverse_mass);
  d.approach_velocity = approach_velocity(law);
  d.restitution = single_body_restitution(law);
  d.impulse = d.M_ie * d.approach_velocity * (1.0 + d.restitution);
  d.linear = -d.impulse * per_unit.head<3>();
  d.angular = -d.impulse * per_unit.tail<3>();
  if (!d.linear.allFinite() || !d.angular.allFinite() || !std::isfinite(d.M_ie))
    FFSR_THROW(NumericalError("base_disturbance: the configuration gives a non-finite impulse response"));
  return d;
}

}  // namespace ffsr
