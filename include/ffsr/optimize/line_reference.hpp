// ffsr/optimize/line_reference.hpp -- the straight-line reference of the capture approach (Section 4).
#pragma once

#include "ffsr/spatial/spatial.hpp"

#include <algorithm>

// The end-effector goes from its initial position x0 to the capture point x_cap along a straight
// line in the inertial frame with the quintic time law s(t/T) (zero velocity and acceleration at
// both ends); for a pose task its orientation turns from R0 to R_end about one fixed axis with the
// same law (a slerp: rot_total = log(R_end R0^T)). This is x_d(t) and x_d_dot(t) of Eq. 30.
// Eigen only; reads nothing but its own fields.

namespace ffsr {

namespace detail {

/// log of a rotation matrix as a rotation vector (angle times unit axis).
inline Vector3 rotation_log(const Matrix3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

/// Quintic time law s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 and its derivative ds/dtau, tau clamped
/// to [0, 1]: s(0) = 0, s(1) = 1, and ds/dtau and d2s/dtau2 vanish at both ends.
inline void quintic(double tau, double& s, double& sdot) {
  tau = std::clamp(tau, 0.0, 1.0);
  s = tau * tau * tau * (10 - 15 * tau + 6 * tau * tau);
  sdot = 30 * tau * tau * (1 - 2 * tau + tau * tau);
}

/// The shapes of the re-anchored line on tau in [0, 1], each with its first and second derivative:
/// s the quintic (s(0) = 0, s(1) = 1), h(tau) = tau (1 - tau)^3 (h'(0) = 1, h''(0) = -6) and
/// g(tau) = tau^2 (1 - tau)^3 / 2 (g''(0) = 1); h, g and their first two derivatives vanish at
/// tau = 1, s' and s'' at both ends, h(0) = g(0) = g'(0) = 0.
struct ReanchorShapes {
  double s, ds, dds, h, dh, ddh, g, dg, ddg;
  explicit ReanchorShapes(double tau) {
    tau = std::clamp(tau, 0.0, 1.0);
    const double u = 1 - tau;
    s = tau * tau * tau * (10 - 15 * tau + 6 * tau * tau);
    ds = 30 * tau * tau * u * u;
    dds = 60 * tau * u * (1 - 2 * tau);
    h = tau * u * u * u;
    dh = u * u * (1 - 4 * tau);
    ddh = -2 * u * (1 - 4 * tau) - 4 * u * u;
    g = 0.5 * tau * tau * u * u * u;
    dg = tau * u * u * u - 1.5 * tau * tau * u * u;
    ddg = u * u * u - 6 * tau * u * u + 3 * tau * tau * u;
  }
};

}  // namespace detail

/// The straight-line reference of Section 4: the end-effector goes from x0 to the capture point
/// x_cap along a line with the quintic time law s(t/T), and (pose task) its orientation turns from
/// R0 to R_end about one fixed axis (rot_total = log(R_end R0^T)) with the same law. Before 0 and
/// after T (= duration) the reference rests at its end points.
/// Re-anchored line (the capture controller's update_target): with start = t_u > 0, the position
/// part is the quintic polynomial in t that has position x0, velocity v0 and acceleration a0 at t_u
/// and reaches x_cap at T with zero velocity and acceleration (six conditions, one quintic):
///   x_d = x0 + s(tau) (x_cap - x0) + D v0 h(tau) + (D^2 a0 + 6 D v0) g(tau),
/// tau = (t - t_u) / D, D = T - t_u, shapes of detail::ReanchorShapes. Re-anchored on the line's
/// own state with an unchanged x_cap it is the line itself. The orientation part keeps the law
/// s(t / T) from R0. With start = 0 (the planner's line) v0 and a0 are not used.
struct LineReference {
  Vector3 x0 = Vector3::Zero(), x_cap = Vector3::Zero();
  Matrix3 R0 = Matrix3::Identity();
  Vector3 rot_total = Vector3::Zero();
  double duration = 1.0;
  double start = 0.0;            ///< t_u, when the position part leaves x0 (s)
  Vector3 v0 = Vector3::Zero();  ///< reference velocity at start (m/s)
  Vector3 a0 = Vector3::Zero();  ///< reference acceleration at start (m/s^2)
  /// Desired position xd and velocity vd at time t (writes all four outputs); for a pose task also
  /// the orientation Rd and the angular velocity wd (inertial frame).
  void at(double t, Vector3& xd, Vector3& vd, Matrix3& Rd, Vector3& wd) const {
    double s = 0, sdot = 0;
    detail::quintic(t / duration, s, sdot);
    sdot /= duration;
    Rd = rotation_from_vector(s * rot_total) * R0;
    wd = sdot * rot_total;
    if (start != 0.0) {  // the re-anchored position part
      const double D = duration - start;
      const detail::ReanchorShapes b((t - start) / D);
      const Vector3 c = D * D * a0 + 6 * D * v0;
      xd = x0 + b.s * (x_cap - x0) + D * b.h * v0 + b.g * c;
      vd = b.ds / D * (x_cap - x0) + b.dh * v0 + b.dg / D * c;
      return;
    }
    xd = x0 + s * (x_cap - x0);
    vd = sdot * (x_cap - x0);
  }
  /// Desired acceleration of the position part at t.
  Vector3 acceleration(double t) const {
    if (start != 0.0) {
      const double D = duration - start;
      const detail::ReanchorShapes b((t - start) / D);
      return b.dds / (D * D) * (x_cap - x0) + b.ddh / D * v0 + b.ddg / (D * D) * (D * D * a0 + 6 * D * v0);
    }
    const detail::ReanchorShapes b(t / duration);
    return b.dds / (duration * duration) * (x_cap - x0);
  }
  /// Desired position only (the same value as `at`).
  Vector3 position(double t) const {
    double s = 0, sdot = 0;
    if (start != 0.0) {
      Vector3 xd, vd, wd;
      Matrix3 Rd;
      at(t, xd, vd, Rd, wd);
      return xd;
    }
    detail::quintic(t / duration, s, sdot);
    return x0 + s * (x_cap - x0);
  }
};

}  // namespace ffsr
