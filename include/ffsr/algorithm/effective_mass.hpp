// ffsr/algorithm/effective_mass.hpp -- effective mass m_e (Eq. 4) and integrated effective mass M_ie (Eq. 14).
// The robot's inverse inertia at a frame and the gradients: effective_mass_gradient.hpp.
#pragma once

#include "ffsr/algorithm/crba.hpp"
#include "ffsr/model/target.hpp"

#include <algorithm>

namespace ffsr {
namespace detail {

/// w = J^T [f; m] for the origin of `frame` (J the 6x(6+n) point Jacobian, linear rows first): the
/// generalized force that a force f at the point and a couple m produce. A unit force u at the point
/// p_e + rho is the pair (u, rho x u). Reads the kinematics. Writes data.w.
inline void jacobian_transpose_times(const Model& model, Data& data, int frame, const Vector3& f,
                                     const Vector3& m) {
  const Vector3 pe = frame_pose(model, data, frame).p;
  if (!pe.allFinite())
    throw NumericalError(str("effective_mass: the position of frame '", model.frame(frame).name,
                             "' overflows double precision"));
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

inline void check_frame(const Model& model, int frame, const char* where) {
  if (frame < 0 || frame >= static_cast<int>(model.frames().size()))
    throw InputError(str(where, ": frame index ", frame, " out of range"));
}

inline void check_unit_direction(const Vector3& u, const char* where) {
  require_finite_all(u, where, "direction u");
  if (std::abs(u.norm() - 1.0) > 1e-9)
    throw InputError(str(where, ": direction u must be a unit vector, |u| = ", u.norm()));
}

}  // namespace detail

/// Inverse effective mass u^T J_v H^-1 J_v^T u (the denominator of Eq. 4) at the configuration of
/// the last crba, computed as |L^-1 w|^2 with H = L L^T and w = J_v^T u (one forward substitution).
/// Reads data.H and the kinematics. Writes data.L, data.w and data.y (= L^-1 w).
inline double inverse_effective_mass(const Model& model, Data& data, int frame, const Vector3& u) {
  detail::check_unit_direction(u, "effective_mass");
  detail::check_frame(model, frame, "effective_mass");
  detail::linear_jacobian_transpose_times(model, data, frame, u);
  detail::cholesky(data.H, data.L, "effective_mass");
  data.y = data.w;
  detail::cholesky_forward(data.L, data.y);
  return data.y.squaredNorm();
}

/// Effective mass m_e = 1 / (u^T (J_v H^-1 J_v^T) u) of the free-floating robot at the origin of
/// `frame` along the unit inertial direction u (Eq. 4). Runs crba.
inline double effective_mass(const Model& model, Data& data, const BasePose& base,
                             const Eigen::Ref<const Eigen::VectorXd>& theta, int frame, const Vector3& u) {
  crba(model, data, base, theta);
  return 1.0 / inverse_effective_mass(model, data, frame, u);
}

/// Integrated effective mass (Eq. 14) from the robot's effective mass along u = R_t u_n:
/// M_ie = 1 / (1/m_e + 1/m_t + (r x u)^T I^-1 (r x u)), r = R_t r_tp, I = R_t I_t R_t^T.
/// NumericalError when the sum of the inverses overflows (a denormal m_e: M_ie would read 0).
inline double integrated_effective_mass(double m_e, const Target& target) {
  if (!(m_e > 0) || !std::isfinite(m_e))
    throw InputError(detail::str("integrated_effective_mass: m_e must be positive and finite, got ", m_e));
  const double inverse = 1.0 / m_e + target.inverse_mass_along_normal();
  if (!std::isfinite(inverse))
    throw NumericalError(
        detail::str("integrated_effective_mass: 1/m_e + 1/m_t overflows double precision, m_e = ", m_e));
  return 1.0 / inverse;
}

/// Integrated effective mass (Eq. 14) of the robot at (base, theta) with the end-effector `frame`
/// touching `target` (its attitude gives u = R_t u_n). Runs crba. Does not validate the target on
/// every call: validate it once (Target::validate) when it is made.
inline double integrated_effective_mass(const Model& model, Data& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Target& target) {
  crba(model, data, base, theta);
  const double inv_me = inverse_effective_mass(model, data, frame, target.normal_world());
  return 1.0 / (inv_me + target.inverse_mass_along_normal());
}

}  // namespace ffsr
