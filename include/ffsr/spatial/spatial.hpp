// ffsr/spatial/spatial.hpp -- small rotation and 6-vector helpers.
//
// Conventions (fixed here, once): 6-vectors are linear first, then angular, as in the paper.
// `aRb` maps coordinates of frame b to frame a; `o` is the inertial frame.
#pragma once

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

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
  // k = nearbyint(x 2/pi), rounded by adding and subtracting 1.5 2^52 (|x 2/pi| < 2^51: the same
  // round-to-nearest-even as nearbyint, which without SSE4.1 is a call into libm)
  constexpr double kRound = 0x1.8p52;
  const double k = (x * kTwoOverPi + kRound) - kRound;
  const double r = ((x - k * kP1) - k * kP2) - k * kP3;
  const double z = r * r;
  // sin r = r + r z (-1/3! + z (1/5! - ...)), cos r = 1 - z/2 + z^2 (1/4! - z (1/6! - ...)): the two
  // polynomials in z by Horner side by side, lane 0 sin's and lane 1 cos's (the same operations as
  // one at a time, two per instruction)
  using Pair = Eigen::Array2d;
  Pair poly(1.0 / 355687428096000, -1.0 / 6402373705728000);
  poly = Pair(-1.0 / 1307674368000, 1.0 / 20922789888000) + z * poly;
  poly = Pair(1.0 / 6227020800, -1.0 / 87178291200) + z * poly;
  poly = Pair(-1.0 / 39916800, 1.0 / 479001600) + z * poly;
  poly = Pair(1.0 / 362880, -1.0 / 3628800) + z * poly;
  poly = Pair(-1.0 / 5040, 1.0 / 40320) + z * poly;
  poly = Pair(1.0 / 120, -1.0 / 720) + z * poly;
  poly = Pair(-1.0 / 6, 1.0 / 24) + z * poly;
  const double ps = poly(0), pc = poly(1);
  const double sr = r + r * z * ps, cr = 1.0 - 0.5 * z + z * z * pc;
  // the quadrant without a branch (random angles mispredict a switch): s = sr, cr, -sr, -cr and
  // c = cr, -sr, -cr, sr for k mod 4 = 0..3, by selecting and flipping sign bits
  const auto quadrant = static_cast<std::uint64_t>(static_cast<long long>(k));
  std::uint64_t bs = 0, bc = 0;
  std::memcpy(&bs, &sr, sizeof bs);
  std::memcpy(&bc, &cr, sizeof bc);
  const std::uint64_t swap = std::uint64_t{0} - (quadrant & 1);  // all ones when odd
  std::uint64_t os = (bs & ~swap) | (bc & swap), oc = (bc & ~swap) | (bs & swap);
  os ^= (quadrant >> 1 & 1) << 63;
  oc ^= ((quadrant + 1) >> 1 & 1) << 63;
  std::memcpy(&s, &os, sizeof s);
  std::memcpy(&c, &oc, sizeof c);
}

/// ldlt_solve3's pivot at step k: the largest diagonal magnitude of the trailing corner (the first of
/// equals), whose row and column are swapped with k's in the lower triangle. Returns its index.
inline int ldlt3_pivot(double (&m)[3][3], int k) {
  int p = k;
  double big = std::abs(m[k][k]);
  for (int i = k + 1; i < 3; ++i)
    if (std::abs(m[i][i]) > big) {
      big = std::abs(m[i][i]);
      p = i;
    }
  if (p != k) {
    for (int j = 0; j < k; ++j) std::swap(m[k][j], m[p][j]);
    for (int i = p + 1; i < 3; ++i) std::swap(m[i][k], m[i][p]);
    std::swap(m[k][k], m[p][p]);
    for (int i = k + 1; i < p; ++i) std::swap(m[i][k], m[p][i]);
  }
  return p;
}

/// x = A^-1 b for a symmetric 3x3 matrix A (its lower triangle is read) by the operations of Eigen's
/// LDLT with diagonal pivoting (Eigen 3.4, A.ldlt().solve(b)) in the same order, so the same
/// numbers, without instantiating its templates in every translation unit. A zero pivot gives a
/// zero component, as Eigen's pseudo-inverse of D does.
inline Vector3 ldlt_solve3(const Matrix3& A, const Vector3& b) {
  double m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m[r][c] = A(r, c);
  int t[3] = {0, 1, 2};
  for (int k = 0; k < 3; ++k) {
    t[k] = ldlt3_pivot(m, k);
    double tmp[2];
    for (int j = 0; j < k; ++j) tmp[j] = m[j][j] * m[k][j];
    if (k == 1) {
      m[1][1] -= m[1][0] * tmp[0];
      m[2][1] -= m[2][0] * tmp[0];
    } else if (k == 2) {
      m[2][2] -= m[2][0] * tmp[0] + m[2][1] * tmp[1];
    }
    const double akk = m[k][k];
    const bool valid = std::abs(akk) > 0.0;
    if (k == 0 && !valid) {
      t[0] = 0, t[1] = 1, t[2] = 2;
      break;
    }
    if (valid)
      for (int i = k + 1; i < 3; ++i) m[i][k] /= akk;
  }
  double x[3] = {b(0), b(1), b(2)};
  for (int k = 0; k < 3; ++k) std::swap(x[k], x[t[k]]);  // P b
  x[1] -= m[1][0] * x[0];                                 // L^-1
  x[2] -= m[2][0] * x[0] + m[2][1] * x[1];
  for (int i = 0; i < 3; ++i) {  // D^-1 (its pseudo-inverse)
    if (std::abs(m[i][i]) > std::numeric_limits<double>::min())
      x[i] /= m[i][i];
    else
      x[i] = 0.0;
  }
  x[1] -= m[2][1] * x[2];  // L^-T
  x[0] -= m[1][0] * x[1] + m[2][0] * x[2];
  for (int k = 2; k >= 0; --k) std::swap(x[k], x[t[k]]);  // P^T
  return {x[0], x[1], x[2]};
}

/// The unit quaternion of the rotation matrix R by Shoemake's algorithm, with the operations of
/// Eigen's Quaternion(R) in its order (the same numbers without its templates).
inline Quaternion quaternion_from_rotation(const Matrix3& R) {
  double q[4];  // x, y, z, w as Eigen stores them
  double t = R(0, 0) + (R(1, 1) + R(2, 2));  // Eigen's unrolled trace
  if (t > 0.0) {
    t = std::sqrt(t + 1.0);
    q[3] = 0.5 * t;
    t = 0.5 / t;
    q[0] = (R(2, 1) - R(1, 2)) * t;
    q[1] = (R(0, 2) - R(2, 0)) * t;
    q[2] = (R(1, 0) - R(0, 1)) * t;
  } else {
    int i = 0;
    if (R(1, 1) > R(0, 0)) i = 1;
    if (R(2, 2) > R(i, i)) i = 2;
    const int j = (i + 1) % 3, k = (j + 1) % 3;
    t = std::sqrt(R(i, i) - R(j, j) - R(k, k) + 1.0);
    q[i] = 0.5 * t;
    t = 0.5 / t;
    q[3] = (R(k, j) - R(j, k)) * t;
    q[j] = (R(j, i) + R(i, j)) * t;
    q[k] = (R(k, i) + R(i, k)) * t;
  }
  return Quaternion(q[3], q[0], q[1], q[2]);
}

/// |v| of a 3-vector scaled by its largest magnitude (Eigen's stableNorm for one block, in its order):
/// no underflow for tiny components.
inline double stable_norm3(double x, double y, double z) {
  const double big = std::max(std::max(std::abs(x), std::abs(y)), std::abs(z));
  if (!(big > 0.0)) return big != big ? big : 0.0;
  double scale = big, inv = 1.0 / big;
  if (inv > std::numeric_limits<double>::max()) {
    inv = std::numeric_limits<double>::max();
    scale = 1.0 / inv;
  } else if (big > std::numeric_limits<double>::max()) {
    inv = 1.0;
    scale = big;
  }
  const double a = x * inv, b = y * inv, c = z * inv;
  return scale * std::sqrt((a * a + b * b) + c * c);
}
}  // namespace detail

/// Rotation by `angle` about the unit vector `axis` (Rodrigues), without allocation.
inline Matrix3 rotation_about(const Vector3& axis, double angle) {
  double s = 0, c = 0;
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
/// Eigen::AngleAxisd(R).angle() by the same operations, without the templates of its conversions.
inline double rotation_angle(const Matrix3& R) {
  const Quaternion q = detail::quaternion_from_rotation(R);
  double n = std::sqrt((q.x() * q.x() + q.y() * q.y()) + q.z() * q.z());
  if (n < std::numeric_limits<double>::epsilon()) n = detail::stable_norm3(q.x(), q.y(), q.z());
  return n != 0.0 ? 2.0 * std::atan2(n, std::abs(q.w())) : 0.0;
}

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
  /// The momentum I V of a motion V = [v; w]: [m v - h x w; h x v + Ibar w]. (The hot kernels of
  /// this file are written out element by element: at -O2 GCC leaves Eigen's small fixed-size
  /// expressions as calls, about half of CRBA's instructions.)
  Vector6 operator*(const Vector6& V) const {
    const double v0 = V(0), v1 = V(1), v2 = V(2), w0 = V(3), w1 = V(4), w2 = V(5);
    const double h0 = h(0), h1 = h(1), h2 = h(2);
    Vector6 f;
    f(0) = m * v0 - (h1 * w2 - h2 * w1);
    f(1) = m * v1 - (h2 * w0 - h0 * w2);
    f(2) = m * v2 - (h0 * w1 - h1 * w0);
    f(3) = (h1 * v2 - h2 * v1) + (Ibar(0, 0) * w0 + Ibar(0, 1) * w1 + Ibar(0, 2) * w2);
    f(4) = (h2 * v0 - h0 * v2) + (Ibar(1, 0) * w0 + Ibar(1, 1) * w1 + Ibar(1, 2) * w2);
    f(5) = (h0 * v1 - h1 * v0) + (Ibar(2, 0) * w0 + Ibar(2, 1) * w1 + Ibar(2, 2) * w2);
    return f;
  }
  SpatialInertia& operator+=(const SpatialInertia& o) {
    m += o.m;
    h(0) += o.h(0);
    h(1) += o.h(1);
    h(2) += o.h(2);
    double* a = Ibar.data();
    const double* b = o.Ibar.data();
    a[0] += b[0];
    a[1] += b[1];
    a[2] += b[2];
    a[3] += b[3];
    a[4] += b[4];
    a[5] += b[5];
    a[6] += b[6];
    a[7] += b[7];
    a[8] += b[8];
    return *this;
  }
  /// The 6x6 matrix [m 1, -[h]x; [h]x, Ibar] written entry by entry into M (a Matrix6 or a 6x6 block
  /// of a larger matrix, such as H's base block): no zero fill first (a zero fill of a 6x6 and the
  /// copy of a temporary were a fifth of CRBA's own work at 3 joints).
  template <class Out>
  void store(Out&& M) const {
    const double h0 = h(0), h1 = h(1), h2 = h(2);
    M(0, 0) = m, M(1, 0) = 0.0, M(2, 0) = 0.0, M(3, 0) = 0.0, M(4, 0) = h2, M(5, 0) = -h1;
    M(0, 1) = 0.0, M(1, 1) = m, M(2, 1) = 0.0, M(3, 1) = -h2, M(4, 1) = 0.0, M(5, 1) = h0;
    M(0, 2) = 0.0, M(1, 2) = 0.0, M(2, 2) = m, M(3, 2) = h1, M(4, 2) = -h0, M(5, 2) = 0.0;
    M(0, 3) = 0.0, M(1, 3) = -h2, M(2, 3) = h1;
    M(0, 4) = h2, M(1, 4) = 0.0, M(2, 4) = -h0;
    M(0, 5) = -h1, M(1, 5) = h0, M(2, 5) = 0.0;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) M(3 + r, 3 + c) = Ibar(r, c);
  }
  Matrix6 matrix() const {
    Matrix6 M;
    store(M);
    return M;
  }
  /// The inertia of a body with mass `mass`, centre of mass `com` and inertia `I_com` about it (both
  /// in the body frame b), in the axes of a frame a about a point, given the rotation aRb and the body
  /// frame origin `r` relative to that point (in a): c = r + R com, Ibar = R I_com R^T + m (|c|^2 1 -
  /// c c^T) (RBDA 2.12 and 2.13). The rotation of I_com costs 27 + 18 products (12 when I_com is
  /// diagonal, as URDF inertias in principal axes are: two rank-one terms), and only the upper
  /// triangle is formed.
  static SpatialInertia from_body(double mass, const Vector3& com, const Matrix3& I_com, const Matrix3& R,
                                  const Vector3& r) {
    SpatialInertia s;
    s.set_body(mass, com, I_com, is_diagonal(I_com), R, r);
    return s;
  }
  /// True when the off-diagonal entries of I are zero (from_body's shortcut applies).
  static bool is_diagonal(const Matrix3& I) {
    return I(0, 1) == 0.0 && I(0, 2) == 0.0 && I(1, 2) == 0.0 && I(1, 0) == 0.0 && I(2, 0) == 0.0 &&
           I(2, 1) == 0.0;
  }
  /// This = from_body(mass, com, I_com, R, r), written in place, `diagonal` being is_diagonal(I_com)
  /// (fixed with the model: Model::inertia_diagonal).
  void set_body(double mass, const Vector3& com, const Matrix3& I_com, bool diagonal, const Matrix3& R,
                const Vector3& r) {
    SpatialInertia& s = *this;
    s.m = mass;
    const double c0 = r(0) + (R(0, 0) * com(0) + R(0, 1) * com(1) + R(0, 2) * com(2));
    const double c1 = r(1) + (R(1, 0) * com(0) + R(1, 1) * com(1) + R(1, 2) * com(2));
    const double c2 = r(2) + (R(2, 0) * com(0) + R(2, 1) * com(1) + R(2, 2) * com(2));
    const double mc0 = mass * c0, mc1 = mass * c1, mc2 = mass * c2;
    s.h = Vector3(mc0, mc1, mc2);
    const double mcc = mc0 * c0 + mc1 * c1 + mc2 * c2;  // m |c|^2
    double i00 = 0, i11 = 0, i22 = 0, i01 = 0, i02 = 0, i12 = 0;
    if (diagonal) {
      // R diag(d) R^T = d2 1 + (d0 - d2) r0 r0^T + (d1 - d2) r1 r1^T (r_k the columns of R, R R^T = 1):
      // two rank-one terms instead of a rotation (24 products per body instead of 33 with m c c^T)
      const double d2 = I_com(2, 2), e0 = I_com(0, 0) - d2, e1 = I_com(1, 1) - d2, dd = d2 + mcc;
      const double g0 = e0 * R(0, 0), g1 = e0 * R(1, 0), g2 = e0 * R(2, 0);
      const double k0 = e1 * R(0, 1), k1 = e1 * R(1, 1), k2 = e1 * R(2, 1);
      i00 = dd + ((g0 * R(0, 0) + k0 * R(0, 1)) - mc0 * c0);
      i11 = dd + ((g1 * R(1, 0) + k1 * R(1, 1)) - mc1 * c1);
      i22 = dd + ((g2 * R(2, 0) + k2 * R(2, 1)) - mc2 * c2);
      i01 = (g0 * R(1, 0) + k0 * R(1, 1)) - mc0 * c1;
      i02 = (g0 * R(2, 0) + k0 * R(2, 1)) - mc0 * c2;
      i12 = (g1 * R(2, 0) + k1 * R(2, 1)) - mc1 * c2;
    } else {
      double T[3][3];  // R I_com
      for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k)
          T[a][k] = R(a, 0) * I_com(0, k) + R(a, 1) * I_com(1, k) + R(a, 2) * I_com(2, k);
      i00 = T[0][0] * R(0, 0) + T[0][1] * R(0, 1) + T[0][2] * R(0, 2) - mc0 * c0 + mcc;
      i11 = T[1][0] * R(1, 0) + T[1][1] * R(1, 1) + T[1][2] * R(1, 2) - mc1 * c1 + mcc;
      i22 = T[2][0] * R(2, 0) + T[2][1] * R(2, 1) + T[2][2] * R(2, 2) - mc2 * c2 + mcc;
      i01 = T[0][0] * R(1, 0) + T[0][1] * R(1, 1) + T[0][2] * R(1, 2) - mc0 * c1;
      i02 = T[0][0] * R(2, 0) + T[0][1] * R(2, 1) + T[0][2] * R(2, 2) - mc0 * c2;
      i12 = T[1][0] * R(2, 0) + T[1][1] * R(2, 1) + T[1][2] * R(2, 2) - mc1 * c2;
    }
    double* I = s.Ibar.data();  // column-major, symmetric
    I[0] = i00, I[1] = i01, I[2] = i02;
    I[3] = i01, I[4] = i11, I[5] = i12;
    I[6] = i02, I[7] = i12, I[8] = i22;
  }
};

/// An articulated-body inertia (RBDA 7.1): a symmetric 6x6 matrix about a reference point, linear
/// first, held as its blocks [ ll la ; la^T aa ] (ll and aa symmetric, stored whole so that Eigen's
/// fixed-size 3x3 expressions unroll). A rigid body's inertia is the special case ll = m 1,
/// la = -[h]x, aa = Ibar; the recursion of the articulated-body algorithm turns it into a general one.
struct ArticulatedInertia {
  Matrix3 ll = Matrix3::Zero(), la = Matrix3::Zero(), aa = Matrix3::Zero();

  ArticulatedInertia() = default;
  explicit ArticulatedInertia(const SpatialInertia& I) { set(I); }
  /// This = the rigid-body inertia I.
  void set(const SpatialInertia& I) {
    double* L = ll.data();
    L[0] = L[4] = L[8] = I.m;
    L[1] = L[2] = L[3] = L[5] = L[6] = L[7] = 0.0;
    double* X = la.data();  // -[h]x, column-major
    X[0] = 0.0, X[1] = -I.h(2), X[2] = I.h(1);
    X[3] = I.h(2), X[4] = 0.0, X[5] = -I.h(0);
    X[6] = -I.h(1), X[7] = I.h(0), X[8] = 0.0;
    aa = I.Ibar;
  }
  /// The force IA V of a motion V = [v; w]: [ll v + la w; la^T v + aa w].
  Vector6 operator*(const Vector6& V) const {
    const double v0 = V(0), v1 = V(1), v2 = V(2), w0 = V(3), w1 = V(4), w2 = V(5);
    Vector6 f;
    f(0) = ll(0, 0) * v0 + ll(0, 1) * v1 + ll(0, 2) * v2 + la(0, 0) * w0 + la(0, 1) * w1 + la(0, 2) * w2;
    f(1) = ll(1, 0) * v0 + ll(1, 1) * v1 + ll(1, 2) * v2 + la(1, 0) * w0 + la(1, 1) * w1 + la(1, 2) * w2;
    f(2) = ll(2, 0) * v0 + ll(2, 1) * v1 + ll(2, 2) * v2 + la(2, 0) * w0 + la(2, 1) * w1 + la(2, 2) * w2;
    f(3) = la(0, 0) * v0 + la(1, 0) * v1 + la(2, 0) * v2 + aa(0, 0) * w0 + aa(0, 1) * w1 + aa(0, 2) * w2;
    f(4) = la(0, 1) * v0 + la(1, 1) * v1 + la(2, 1) * v2 + aa(1, 0) * w0 + aa(1, 1) * w1 + aa(1, 2) * w2;
    f(5) = la(0, 2) * v0 + la(1, 2) * v1 + la(2, 2) * v2 + aa(2, 0) * w0 + aa(2, 1) * w1 + aa(2, 2) * w2;
    return f;
  }
  /// One symmetric 3x3 block M (column-major) of add_projected: M += C - s u^T with s = u / D, the upper
  /// triangle computed and mirrored.
  static void add_symmetric_projected(double* M, const double* C, double u0, double u1, double u2, double s0,
                                      double s1, double s2) {
    M[0] += C[0] - s0 * u0;
    M[3] += C[3] - s0 * u1;
    M[6] += C[6] - s0 * u2;
    M[4] += C[4] - s1 * u1;
    M[7] += C[7] - s1 * u2;
    M[8] += C[8] - s2 * u2;
    M[1] = M[3], M[2] = M[6], M[5] = M[7];
  }
  /// This += c - U U^T / D (the articulated inertia a child passes to its parent across a joint
  /// with U = IA_c S, D = S^T U, RBDA 7.3). The symmetric blocks get their upper triangle computed
  /// and mirrored, so they stay exactly symmetric.
  void add_projected(const ArticulatedInertia& c, const Vector6& U, double D) {
    const double inv = 1.0 / D;
    const double u0 = U(0), u1 = U(1), u2 = U(2), u3 = U(3), u4 = U(4), u5 = U(5);
    const double s0 = u0 * inv, s1 = u1 * inv, s2 = u2 * inv, s3 = u3 * inv, s4 = u4 * inv, s5 = u5 * inv;
    add_symmetric_projected(ll.data(), c.ll.data(), u0, u1, u2, s0, s1, s2);
    double* X = la.data();
    const double* cX = c.la.data();
    X[0] += cX[0] - s0 * u3, X[1] += cX[1] - s1 * u3, X[2] += cX[2] - s2 * u3;
    X[3] += cX[3] - s0 * u4, X[4] += cX[4] - s1 * u4, X[5] += cX[5] - s2 * u4;
    X[6] += cX[6] - s0 * u5, X[7] += cX[7] - s1 * u5, X[8] += cX[8] - s2 * u5;
    add_symmetric_projected(aa.data(), c.aa.data(), u3, u4, u5, s3, s4, s5);
  }
  /// This = the rigid-body inertia I + c - U U^T / D, the same operations as set(I) followed by
  /// add_projected(c, U, D) (the same bits) without writing this twice and reading it back: for a
  /// body's first child in the recursion, whose articulated inertia starts its own.
  void set_projected(const SpatialInertia& I, const ArticulatedInertia& c, const Vector6& U, double D) {
    const double inv = 1.0 / D;
    const double u0 = U(0), u1 = U(1), u2 = U(2), u3 = U(3), u4 = U(4), u5 = U(5);
    const double s0 = u0 * inv, s1 = u1 * inv, s2 = u2 * inv, s3 = u3 * inv, s4 = u4 * inv, s5 = u5 * inv;
    const double h0 = I.h(0), h1 = I.h(1), h2 = I.h(2);
    double* L = ll.data();
    const double* cL = c.ll.data();
    L[0] = I.m + (cL[0] - s0 * u0);
    L[3] = cL[3] - s0 * u1;
    L[6] = cL[6] - s0 * u2;
    L[4] = I.m + (cL[4] - s1 * u1);
    L[7] = cL[7] - s1 * u2;
    L[8] = I.m + (cL[8] - s2 * u2);
    L[1] = L[3], L[2] = L[6], L[5] = L[7];
    double* X = la.data();  // -[h]x + c.la - s u_angular^T, column-major
    const double* cX = c.la.data();
    X[0] = cX[0] - s0 * u3, X[1] = -h2 + (cX[1] - s1 * u3), X[2] = h1 + (cX[2] - s2 * u3);
    X[3] = h2 + (cX[3] - s0 * u4), X[4] = cX[4] - s1 * u4, X[5] = -h0 + (cX[5] - s2 * u4);
    X[6] = -h1 + (cX[6] - s0 * u5), X[7] = h0 + (cX[7] - s1 * u5), X[8] = cX[8] - s2 * u5;
    double* A = aa.data();
    const double* cA = c.aa.data();
    const double* B = I.Ibar.data();
    A[0] = B[0] + (cA[0] - s3 * u3);
    A[3] = B[3] + (cA[3] - s3 * u4);
    A[6] = B[6] + (cA[6] - s3 * u5);
    A[4] = B[4] + (cA[4] - s4 * u4);
    A[7] = B[7] + (cA[7] - s4 * u5);
    A[8] = B[8] + (cA[8] - s5 * u5);
    A[1] = A[3], A[2] = A[6], A[5] = A[7];
  }
  Matrix6 matrix() const {
    Matrix6 M;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) {
        M(r, c) = ll(r, c);
        M(r, 3 + c) = la(r, c);
        M(3 + c, r) = la(r, c);
        M(3 + r, 3 + c) = aa(r, c);
      }
    return M;
  }
};

}  // namespace ffsr
