// ffsr/optimize/line_reference.hpp -- the straight-line reference of the capture approach (Section 4).
//
// The end-effector goes from its initial position x0 to the capture point x_cap along a straight
// line in the inertial frame with the quintic time law s(t/T) (zero velocity and acceleration at
// both ends); for a pose task its orientation turns from R0 to R_end about one fixed axis with the
// same law (a slerp: rot_total = log(R_end R0^T)). This is x_d(t) and x_d_dot(t) of Eq. 30.
// Eigen only; reads nothing but its own fields.
#pragma once

#include "ffsr/spatial/spatial.hpp"

#include <algorithm>

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

/// The launch shape h(tau) = tau (1 - tau)^3 and its derivative dh/dtau (tau in [0, 1]): h(0) = 0,
/// dh/dtau(0) = 1, and h, dh/dtau, d2h/dtau2 vanish at tau = 1.
inline void launch(double tau, double& h, double& hdot) {
  const double u = 1 - tau;
  h = tau * u * u * u;
  hdot = u * u * u - 3 * tau * u * u;
}

}  // namespace detail

/// The straight-line reference of Section 4: the end-effector goes from x0 to the capture point
/// x_cap along a line with the quintic time law s(t/T), and (pose task) its orientation turns from
/// R0 to R_end about one fixed axis (rot_total = log(R_end R0^T)) with the same law. Before 0 and
/// after T (= duration) the reference rests at its end points.
/// Re-anchored line (the capture controller's update_target): with start = t_u > 0 and v0 the
/// position part goes from x0 at t_u to x_cap at T, leaving with velocity v0:
///   x_d = x0 + s(tau) (x_cap - x0) + (T - t_u) v0 h(tau),  tau = (t - t_u) / (T - t_u),
/// h(tau) = tau (1 - tau)^3 (h(0) = 0, h'(0) = 1, h(1) = h'(1) = h''(1) = 0). The orientation part
/// keeps the law s(t / T) from R0. With start = 0 (the planner's line) v0 is not used.
struct LineReference {
  Vector3 x0 = Vector3::Zero(), x_cap = Vector3::Zero();
  Matrix3 R0 = Matrix3::Identity();
  Vector3 rot_total = Vector3::Zero();
  double duration = 1.0;
  double start = 0.0;              ///< t_u, when the position part leaves x0 (s)
  Vector3 v0 = Vector3::Zero();    ///< reference velocity at start (m/s)
  /// Desired position xd and velocity vd at time t (writes all four outputs); for a pose task also
  /// the orientation Rd and the angular velocity wd (inertial frame).
  void at(double t, Vector3& xd, Vector3& vd, Matrix3& Rd, Vector3& wd) const {
    double s, sdot;
    detail::quintic(t / duration, s, sdot);
    sdot /= duration;
    Rd = rotation_from_vector(s * rot_total) * R0;
    wd = sdot * rot_total;
    if (start != 0.0) {  // the re-anchored position part
      const double D = duration - start;
      double h, hdot;
      detail::quintic((t - start) / D, s, sdot);
      detail::launch(std::clamp((t - start) / D, 0.0, 1.0), h, hdot);
      xd = x0 + s * (x_cap - x0) + D * h * v0;
      vd = sdot / D * (x_cap - x0) + hdot * v0;
      return;
    }
    xd = x0 + s * (x_cap - x0);
    vd = sdot * (x_cap - x0);
  }
  /// Desired position only (the same value as `at`).
  Vector3 position(double t) const {
    double s, sdot;
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
