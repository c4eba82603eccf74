// ffsr/spatial/spatial.hpp -- small rotation and 6-vector helpers.
//
// Conventions (fixed here, once): 6-vectors are linear first, then angular, as in the paper.
// `aRb` maps coordinates of frame b to frame a; `o` is the inertial frame.
#pragma once

#include <Eigen/Dense>

#include <cmath>

namespace ffsr {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Quaternion = Eigen::Quaterniond;

/// The skew-symmetric matrix [a]x with [a]x b = a x b.
inline Matrix3 skew(const Vector3& a) {
  Matrix3 S;
  S << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return S;
}

/// URDF roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll), angles in radians.
inline Matrix3 rotation_from_rpy(const Vector3& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Vector3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vector3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vector3::UnitX()))
      .toRotationMatrix();
}

/// Inverse of rotation_from_rpy (roll, pitch, yaw), pitch in [-pi/2, pi/2].
inline Vector3 rpy_from_rotation(const Matrix3& R) {
  const double pitch = std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0)));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

namespace detail {

/// sin x and cos x together, for the joint angles of the kinematics (a fifth of forward_kinematics
/// went to libm's sincos). |x| <= 1e5: x = k pi/2 + r, |r| <= pi/4, with pi/2 split in three parts
/// (the first two with 33 significant bits, so k * part is exact for |k| < 2^20) and the Taylor
/// series of sin r to r^17 and cos r to r^18 (the first omitted terms are below 1e-19 on |r| <= pi/4),
/// by Horner: within 2 units in the last place of std::sin / std::cos (tested). Larger, infinite or
/// NaN x: std::sin and std::cos.
inline void sin_cos(double x, double& s, double& c) {
  if (!(std::abs(x) <= 1e5)) {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  constexpr double kTwoOverPi = 0.6366197723675814;
  constexpr double kP1 = 0x1.921fb544p+0, kP2 = 0x1.0b4611a6p-34, kP3 = 0x1.3198a2e037073p-69;  // pi/2 = sum
  const double k = std::nearbyint(x * kTwoOverPi);
  const double r = ((x - k * kP1) - k * kP2) - k * kP3;
  const double z = r * r;
  // sin r = r + r z (-1/3! + z (1/5! - ...)), cos r = 1 - z/2 + z^2 (1/4! - z (1/6! - ...))
  const double ps =
      -1.0 / 6 +
      z * (1.0 / 120 +
           z * (-1.0 / 5040 +
                z * (1.0 / 362880 +
                     z * (-1.0 / 39916800 + z * (1.0 / 6227020800 + z * (-1.0 / 1307674368000 +
                                                                         z * (1.0 / 355687428096000)))))));
  const double pc =
      1.0 / 24 +
      z * (-1.0 / 720 +
           z * (1.0 / 40320 +
                z * (-1.0 / 3628800 + z * (1.0 / 479001600 +
                                           z * (-1.0 / 87178291200 + z * (1.0 / 20922789888000 +
                                                                          z * (-1.0 / 6402373705728000)))))));
  const double sr = r + r * z * ps, cr = 1.0 - 0.5 * z + z * z * pc;
  switch (static_cast<long long>(k) & 3) {
    case 0:
      s = sr;
      c = cr;
      break;
    case 1:
      s = cr;
      c = -sr;
      break;
    case 2:
      s = -sr;
      c = -cr;
      break;
    default:
      s = -cr;
      c = sr;
      break;
  }
}

}  // namespace detail

/// Rotation by `angle` about the unit vector `axis` (Rodrigues), without allocation.
inline Matrix3 rotation_about(const Vector3& axis, double angle) {
  double s, c;
  detail::sin_cos(angle, s, c);
  const double t = 1.0 - c;
  const double x = axis.x(), y = axis.y(), z = axis.z();
  Matrix3 R;
  R << t * x * x + c, t * x * y - s * z, t * x * z + s * y,  //
      t * x * y + s * z, t * y * y + c, t * y * z - s * x,   //
      t * x * z - s * y, t * y * z + s * x, t * z * z + c;
  return R;
}

/// Rotation vector (axis * angle) -> rotation matrix.
inline Matrix3 rotation_from_vector(const Vector3& w) {
  const double angle = w.norm();
  if (angle < 1e-300) return Matrix3::Identity();
  return rotation_about(w / angle, angle);
}

/// Angle of the rotation R (radians, in [0, pi]).
inline double rotation_angle(const Matrix3& R) { return Eigen::AngleAxisd(R).angle(); }

/// Spatial cross product for motion vectors, linear first: V x m.
inline Vector6 cross_motion(const Vector6& V, const Vector6& m) {
  Vector6 r;
  r.head<3>() = V.tail<3>().cross(m.head<3>()) + V.head<3>().cross(m.tail<3>());
  r.tail<3>() = V.tail<3>().cross(m.tail<3>());
  return r;
}

/// Spatial cross product for force vectors, linear first: V x* f.
inline Vector6 cross_force(const Vector6& V, const Vector6& f) {
  Vector6 r;
  r.head<3>() = V.tail<3>().cross(f.head<3>());
  r.tail<3>() = V.tail<3>().cross(f.tail<3>()) + V.head<3>().cross(f.head<3>());
  return r;
}

/// A rigid body's inertia about a reference point, stored by its ten parameters:
/// mass m, first moment h = m c (c the centre of mass relative to the point) and the
/// rotational inertia Ibar about the point. As a 6x6 matrix (linear first) it is
///   [ m E     -[h]x ]
///   [ [h]x     Ibar ].
struct SpatialInertia {
  double m = 0.0;
  Vector3 h = Vector3::Zero();
  Matrix3 Ibar = Matrix3::Zero();

  /// From mass, centre of mass c (relative to the reference point) and inertia about c.
  static SpatialInertia from_com(double mass, const Vector3& c, const Matrix3& I_com) {
    SpatialInertia s;
    s.m = mass;
    s.h = mass * c;
    s.Ibar = I_com + mass * (c.squaredNorm() * Matrix3::Identity() - c * c.transpose());
    return s;
  }
  /// The momentum I V of a motion V = [v; w].
  Vector6 operator*(const Vector6& V) const {
    Vector6 f;
    f.head<3>() = m * V.head<3>() - h.cross(V.tail<3>());
    f.tail<3>() = h.cross(V.head<3>()) + Ibar * V.tail<3>();
    return f;
  }
  SpatialInertia& operator+=(const SpatialInertia& o) {
    m += o.m;
    h += o.h;
    Ibar += o.Ibar;
    return *this;
  }
  Matrix6 matrix() const {
    Matrix6 M;
    M << m * Matrix3::Identity(), -skew(h), skew(h), Ibar;
    return M;
  }
};

}  // namespace ffsr
