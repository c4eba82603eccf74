// ffsr/model/target.hpp -- the tumbling target: a free rigid body with one contact point, and its
// torque-free propagation (propagate_target).
#pragma once

#include "ffsr/errors.hpp"
#include "ffsr/spatial/spatial.hpp"

#include <algorithm>
#include <cmath>

namespace ffsr {

/// The target of the capture (Section 2.2). Vectors marked (target frame) rotate with it.
struct Target {
  double mass = 200.0;                                 ///< m_t, kg
  Matrix3 inertia = 100.0 * Matrix3::Identity();       ///< I_t about its centre of mass (target frame)
  Vector3 position = Vector3::Zero();                  ///< centre of mass in o
  Quaternion attitude = Quaternion::Identity();        ///< oR_t
  Vector3 velocity = Vector3::Zero();                  ///< v_t, inertial frame
  Vector3 angular_velocity = Vector3::Zero();          ///< omega_t (target frame), rad/s
  Vector3 contact_offset = Vector3(-0.25, 0.15, 0.0);  ///< r_tp (target frame)
  Vector3 normal = Vector3::UnitX();                   ///< u_n (target frame), unit

  /// Checks every field; throws InputError naming the field. The inertia must be symmetric positive
  /// definite (Eq. 14 inverts it) and satisfy the triangle inequality.
  void validate(const char* where = "target") const {
    using detail::str;
    if (!std::isfinite(mass) || mass <= 0)
      throw InputError(str(where, ": mass must be positive and finite, got ", mass));
    detail::require_finite_all(inertia, where, "inertia");
    detail::require_finite_all(position, where, "position");
    detail::require_finite_all(attitude.coeffs(), where, "attitude");
    detail::require_finite_all(velocity, where, "velocity");
    detail::require_finite_all(angular_velocity, where, "angular velocity");
    detail::require_finite_all(contact_offset, where, "contact offset");
    detail::require_finite_all(normal, where, "normal");
    if (attitude.norm() < 1e-9) throw InputError(str(where, ": attitude quaternion has zero norm"));
    if (normal.norm() < 1e-12) throw InputError(str(where, ": normal must be a non-zero vector"));
    const double scale = inertia.cwiseAbs().maxCoeff();
    if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
      throw InputError(str(where, ": inertia must be symmetric"));
    Eigen::SelfAdjointEigenSolver<Matrix3> es(inertia, Eigen::EigenvaluesOnly);
    const Vector3 e = es.eigenvalues();
    if (!(e(0) > 1e-12 * scale) || !(scale > 0))
      throw InputError(str(where, ": inertia must be positive definite, principal moments (", e(0), ", ",
                           e(1), ", ", e(2), ")"));
    if (e(2) > (e(0) + e(1)) * (1 + 1e-9))
      throw InputError(str(where, ": principal moments (", e(0), ", ", e(1), ", ", e(2),
                           ") break the triangle inequality"));
    // A positive but denormal mass or inertia (1e-312 kg) has an inverse that overflows: Eq. 14 would
    // give M_ie = 0.
    const double inv = inverse_mass_along_normal();
    if (!std::isfinite(inv))
      throw InputError(str(where, ": mass ", mass, " kg and inertia (smallest principal moment ", e(0),
                           ") are too small: the inverse mass along the normal is ", inv));
  }
  /// oR_t.
  Matrix3 rotation() const { return attitude.normalized().toRotationMatrix(); }
  /// Contact normal u = R_t u_n in o (unit).
  Vector3 normal_world() const { return rotation() * normal.normalized(); }
  /// Contact point offset r = R_t r_tp in o.
  Vector3 offset_world() const { return rotation() * contact_offset; }
  /// Contact point position in o.
  Vector3 contact_point() const { return position + offset_world(); }
  /// Angular velocity in o.
  Vector3 angular_velocity_world() const { return rotation() * angular_velocity; }
  /// Velocity of the target's material contact point, v_tp = v_t + w_t x r (Eq. 12), in o.
  Vector3 contact_point_velocity() const { return velocity + angular_velocity_world().cross(offset_world()); }
  /// The target's inverse mass perceived along the normal at the contact point,
  /// 1/m_t + (r x u)^T I^-1 (r x u) (the target part of Eq. 14). It does not depend on the attitude.
  double inverse_mass_along_normal() const {
    const Vector3 ru = contact_offset.cross(normal.normalized());
    return 1.0 / mass + ru.dot(detail::ldlt_solve3(inertia, ru));
  }
};

/// The target at time t: centre of mass drifting with its velocity, attitude and spin from the
/// torque-free Euler equations (RK4 with a fine step; exact rotation when the inertia is isotropic).
inline Target propagate_target(const Target& t0, double t) {
  Target t1 = t0;
  t1.position = t0.position + t0.velocity * t;
  const Matrix3 I = t0.inertia;
  const bool isotropic = (I - I(0, 0) * Matrix3::Identity()).cwiseAbs().maxCoeff() <= 1e-12 * I(0, 0);
  if (isotropic || t0.angular_velocity.norm() == 0.0) {
    t1.attitude = Quaternion(t0.rotation() * rotation_from_vector(t0.angular_velocity * t));
    return t1;
  }
  const Matrix3 Iinv = I.inverse();
  const long nsteps = std::max<long>(1, static_cast<long>(std::ceil(std::abs(t) / 1e-3)));
  if (nsteps > 100000000) throw InputError("propagate_target: time span too long");
  const double h = t / static_cast<double>(nsteps);
  Matrix3 R = t0.rotation();
  Vector3 w = t0.angular_velocity;  // body frame
  auto wdot = [&](const Vector3& x) { return Vector3(Iinv * (-x.cross(I * x))); };
  for (long k = 0; k < nsteps; ++k) {
    const Vector3 k1 = wdot(w), k2 = wdot(w + 0.5 * h * k1), k3 = wdot(w + 0.5 * h * k2),
                  k4 = wdot(w + h * k3);
    const Vector3 wn = w + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    R = R * rotation_from_vector(0.5 * h * (w + wn));  // midpoint rotation, body frame
    w = wn;
  }
  t1.attitude = Quaternion(R);
  t1.angular_velocity = w;
  return t1;
}

}  // namespace ffsr
