// ffsr/model/target.hpp -- the tumbling target: a free rigid body with one contact point, and its
// torque-free propagation (propagate_target).
#pragma once

#include "ffsr/errors.hpp"
#include "ffsr/spatial/spatial.hpp"

#include <algorithm>
#include <cmath>

namespace ffsr {

namespace detail {
/// Returns v; NumericalError naming `where` unless v is finite (finite inputs whose arithmetic
/// passed double precision, or inputs that were not finite).
inline Vector3 finite_result(const Vector3& v, const char* where) {
  if (!v.allFinite())
    FFSR_THROW(NumericalError(str(where, ": the result is not finite (", v.transpose(), ")")));
  return v;
}
}  // namespace detail

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
      FFSR_THROW(InputError(str(where, ": mass must be positive and finite, got ", mass)));
    detail::require_finite_all(inertia, where, "inertia");
    detail::require_finite_all(position, where, "position");
    detail::require_finite_all(attitude.coeffs(), where, "attitude");
    detail::require_finite_all(velocity, where, "velocity");
    detail::require_finite_all(angular_velocity, where, "angular velocity");
    detail::require_finite_all(contact_offset, where, "contact offset");
    detail::require_finite_all(normal, where, "normal");
    if (attitude.norm() < 1e-9) FFSR_THROW(InputError(str(where, ": attitude quaternion has zero norm")));
    if (normal.norm() < 1e-12) FFSR_THROW(InputError(str(where, ": normal must be a non-zero vector")));
    const double scale = inertia.cwiseAbs().maxCoeff();
    if ((inertia - inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
      FFSR_THROW(InputError(str(where, ": inertia must be symmetric")));
    Eigen::SelfAdjointEigenSolver<Matrix3> es(inertia, Eigen::EigenvaluesOnly);
    const Vector3& e = es.eigenvalues();
    if (!(e(0) > 1e-12 * scale) || !(scale > 0))
      FFSR_THROW(InputError(str(where, ": inertia must be positive definite, principal moments (", e(0), ", ",
                           e(1), ", ", e(2), ")")));
    if (e(2) > (e(0) + e(1)) * (1 + 1e-9))
      FFSR_THROW(InputError(str(where, ": principal moments (", e(0), ", ", e(1), ", ", e(2),
                           ") break the triangle inequality")));
    // A positive but denormal mass or inertia (1e-312 kg) has an inverse that overflows: Eq. 14 would
    // give M_ie = 0.
    const double inv = inverse_mass_along_normal();
    if (!std::isfinite(inv))
      FFSR_THROW(InputError(str(where, ": mass ", mass, " kg and inertia (smallest principal moment ", e(0),
                           ") are too small: the inverse mass along the normal is ", inv)));
  }
  /// oR_t.
  Matrix3 rotation() const { return attitude.normalized().toRotationMatrix(); }
  /// Contact normal u = R_t u_n in o (unit).
  Vector3 normal_world() const { return rotation() * normal.normalized(); }
  /// Contact point offset r = R_t r_tp in o.
  Vector3 offset_world() const { return rotation() * contact_offset; }
  /// Contact point position in o. NumericalError when the sum overflows double precision.
  Vector3 contact_point() const {
    return detail::finite_result(Vector3(position + offset_world()), "Target::contact_point");
  }
  /// Angular velocity in o.
  Vector3 angular_velocity_world() const { return rotation() * angular_velocity; }
  /// Velocity of the target's material contact point, v_tp = v_t + w_t x r (Eq. 12), in o.
  /// NumericalError when w_t x r overflows double precision.
  Vector3 contact_point_velocity() const {
    return detail::finite_result(Vector3(velocity + angular_velocity_world().cross(offset_world())),
                                         "Target::contact_point_velocity");
  }
  /// The target's inverse mass perceived along the normal at the contact point,
  /// 1/m_t + (r x u)^T I^-1 (r x u) (the target part of Eq. 14). It does not depend on the attitude.
  double inverse_mass_along_normal() const {
    const Vector3 ru = contact_offset.cross(normal.normalized());
    return 1.0 / mass + ru.dot(detail::ldlt_solve3(inertia, ru));
  }
};

namespace detail {

/// The inverse of a 3x3 matrix by its cofactors, with the operations of Eigen's inverse() for 3x3
/// in their order (the same numbers without its templates).
inline Matrix3 inverse3(const Matrix3& m) {
  auto cof = [&m](int i, int j) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    return m(i1, j1) * m(i2, j2) - m(i1, j2) * m(i2, j1);
  };
  const double c00 = cof(0, 0), c10 = cof(1, 0), c20 = cof(2, 0);
  const double det = (c00 * m(0, 0) + c10 * m(1, 0)) + c20 * m(2, 0);
  const double invdet = 1.0 / det;
  Matrix3 r;
  r(0, 0) = c00 * invdet, r(0, 1) = c10 * invdet, r(0, 2) = c20 * invdet;
  r(1, 0) = cof(0, 1) * invdet, r(1, 1) = cof(1, 1) * invdet, r(1, 2) = cof(2, 1) * invdet;
  r(2, 0) = cof(0, 2) * invdet, r(2, 1) = cof(1, 2) * invdet, r(2, 2) = cof(2, 2) * invdet;
  return r;
}

/// y = A x with the summation order of Eigen's fixed-size product at -O2 with SSE2 (rows 0 and 1
/// as one packet, left to right; row 2 by its unrolled reduction, a0 x0 + (a1 x1 + a2 x2)).
inline void matrix_vector3(const Matrix3& A, const double* x, double* y) {
  y[0] = (A(0, 0) * x[0] + A(0, 1) * x[1]) + A(0, 2) * x[2];
  y[1] = (A(1, 0) * x[0] + A(1, 1) * x[1]) + A(1, 2) * x[2];
  y[2] = A(2, 0) * x[0] + (A(2, 1) * x[1] + A(2, 2) * x[2]);
}

/// The torque-free Euler equations in the body frame, dw/dt = I^-1 (-w x I w).
inline void euler_rate(const Matrix3& I, const Matrix3& Iinv, const double* w, double* dw) {
  double Iw[3];
  matrix_vector3(I, w, Iw);
  const double c[3] = {-(w[1] * Iw[2] - w[2] * Iw[1]), -(w[2] * Iw[0] - w[0] * Iw[2]),
                       -(w[0] * Iw[1] - w[1] * Iw[0])};
  matrix_vector3(Iinv, c, dw);
}

}  // namespace detail

/// The target at time t: centre of mass drifting with its velocity, attitude and spin from the
/// torque-free Euler equations (RK4 with a fine step; exact rotation when the inertia is isotropic).
/// InputError for a t that is not finite or too long a span; NumericalError when the motion of
/// finite values passes double precision.
inline Target propagate_target(const Target& t0, double t) {
  if (!std::isfinite(t)) FFSR_THROW(InputError(detail::str("propagate_target: time must be finite, got ", t)));
  Target t1 = t0;
  t1.position = detail::finite_result(Vector3(t0.position + t0.velocity * t), "propagate_target: position");
  const Matrix3 I = t0.inertia;
  bool isotropic = true;
  const double tol = 1e-12 * I(0, 0);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (!(std::abs(r == c ? I(r, c) - I(0, 0) : I(r, c)) <= tol)) isotropic = false;
  if (isotropic || t0.angular_velocity.norm() == 0.0) {
    t1.attitude = detail::quaternion_from_rotation(t0.rotation() * rotation_from_vector(t0.angular_velocity * t));
    return t1;
  }
  const Matrix3 Iinv = detail::inverse3(I);
  const double steps = std::ceil(std::abs(t) / 1e-3);
  if (steps > 1e8) FFSR_THROW(InputError("propagate_target: time span too long"));
  const long nsteps = std::max<long>(1, static_cast<long>(steps));
  const double h = t / static_cast<double>(nsteps), hh = 0.5 * h, h6 = h / 6;
  Matrix3 R = t0.rotation();
  double w[3] = {t0.angular_velocity(0), t0.angular_velocity(1), t0.angular_velocity(2)};  // body frame
  for (long k = 0; k < nsteps; ++k) {
    double k1[3], k2[3], k3[3], k4[3], x[3], wn[3];
    detail::euler_rate(I, Iinv, w, k1);
    for (int i = 0; i < 3; ++i) x[i] = w[i] + hh * k1[i];
    detail::euler_rate(I, Iinv, x, k2);
    for (int i = 0; i < 3; ++i) x[i] = w[i] + hh * k2[i];
    detail::euler_rate(I, Iinv, x, k3);
    for (int i = 0; i < 3; ++i) x[i] = w[i] + h * k3[i];
    detail::euler_rate(I, Iinv, x, k4);
    for (int i = 0; i < 3; ++i) wn[i] = w[i] + h6 * (((k1[i] + 2.0 * k2[i]) + 2.0 * k3[i]) + k4[i]);
    const Vector3 half(hh * (w[0] + wn[0]), hh * (w[1] + wn[1]), hh * (w[2] + wn[2]));
    R = R * rotation_from_vector(half);  // midpoint rotation, body frame
    for (int i = 0; i < 3; ++i) w[i] = wn[i];
  }
  if (!R.allFinite() || !Vector3(w[0], w[1], w[2]).allFinite())  // a spin whose products overflow
    FFSR_THROW(NumericalError(detail::str("propagate_target: the rotation is not finite after ", t,
                                     " s (angular velocity ", t0.angular_velocity.transpose(), " rad/s)")));
  t1.attitude = detail::quaternion_from_rotation(R);
  t1.angular_velocity = Vector3(w[0], w[1], w[2]);
  return t1;
}


}  // namespace ffsr
