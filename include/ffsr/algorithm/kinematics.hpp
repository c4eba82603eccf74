// ffsr/algorithm/kinematics.hpp -- forward kinematics of the free-floating tree.
#pragma once

#include "ffsr/model/data.hpp"

namespace ffsr {
namespace detail {

/// Checks the configuration arguments of a public entry point (sizes, finiteness, quaternion).
/// Returns the norm of the base quaternion.
inline double check_configuration(const Model& model, const BasePose& base,
                                  const Eigen::Ref<const Eigen::VectorXd>& theta, const char* where) {
  require_size(theta.size(), model.n(), where, "theta");
  require_finite_all(theta, where, "theta");
  require_finite_all(base.position, where, "base position");
  require_finite_all(base.orientation.coeffs(), where, "base orientation");
  const double qn = base.orientation.norm();
  if (qn < 1e-9) FFSR_THROW(InputError(str(where, ": base orientation quaternion has zero norm")));
  return qn;
}

/// A 3-vector as its first two entries in one pair (an Eigen::Vector2d: one SSE register) and its
/// third alone, loaded from and stored to memory in that same pattern. The kinematics keep the
/// columns of the rotations and the positions this way: a body's rotation, stored just before, is
/// then loaded by its child's step in the pattern it was stored in, which the processor forwards from
/// its store buffer (a load of two entries stored one at a time, as the compiler's own pairing of
/// scalar code makes, waits until the stores retire: about a sixth of the kinematics of a chain).
/// Each operation is the scalar one on each entry, in the same order: the same bits.
struct SplitColumn {
  Eigen::Vector2d top;  ///< entries 0 and 1
  double last = 0.0;    ///< entry 2
  SplitColumn() : top(Eigen::Vector2d::Zero()) {}
  SplitColumn(const Eigen::Vector2d& t, double l) : top(t), last(l) {}
  /// Column c of M.
  SplitColumn(const Matrix3& M, int c) : top(Eigen::Vector2d::Map(M.data() + 3 * std::ptrdiff_t{c})), last(M(2, c)) {}
  explicit SplitColumn(const Vector3& v) : top(Eigen::Vector2d::Map(v.data())), last(v(2)) {}
  SplitColumn operator*(double f) const { return {top * f, last * f}; }
  SplitColumn operator+(const SplitColumn& o) const { return {top + o.top, last + o.last}; }
  SplitColumn operator-(const SplitColumn& o) const { return {top - o.top, last - o.last}; }
  double entry(int r) const { return r == 2 ? last : top(r); }
  /// Into column c of M.
  void store(Matrix3& M, int c) const {
    Eigen::Vector2d::Map(M.data() + 3 * std::ptrdiff_t{c}) = top;
    M(2, c) = last;
  }
  void store(Vector3& v) const {
    Eigen::Vector2d::Map(v.data()) = top;
    v(2) = last;
  }
};

/// The columns C_c of A B, A given by its columns A0, A1, A2: C_c = (A0 B(0, c) + A1 B(1, c)) + A2 B(2, c)
/// (27 products, written out: Eigen's lazy 3x3 product is a call at -O2).
inline void multiply3(const SplitColumn& A0, const SplitColumn& A1, const SplitColumn& A2, const Matrix3& B,
                      SplitColumn (&C)[3]) {
  for (int c = 0; c < 3; ++c) C[c] = (A0 * B(0, c) + A1 * B(1, c)) + A2 * B(2, c);
}

}  // namespace detail

/// Forward kinematics (RBDA 4.1, in the inertial frame).
/// Reads base, theta. Writes data.base, data.R, data.p (every body frame in o), data.S (the joint
/// motion subspaces in inertial axes about the base frame origin, per unit rate of each body's
/// coordinate: mimic joints carry their multiplier) and data.sin_q, data.cos_q. The base quaternion
/// is normalized. Every joint's sine and cosine are computed first, in a pass of their own: each is
/// independent of the others, while the poses form a chain from the base, so the processor overlaps
/// the long polynomial evaluations instead of waiting for each on the chain.
inline void forward_kinematics(const Model& model, Data& data, const BasePose& base,
                               const Eigen::Ref<const Eigen::VectorXd>& theta) {
  const double qn = detail::check_configuration(model, base, theta, "forward_kinematics");
  data.base.position = base.position;
  data.base.orientation.coeffs() = base.orientation.coeffs() / qn;  // normalized(), its norm reused
  const Matrix3 R0 = data.base.orientation.toRotationMatrix();
  for (int c = 0; c < 3; ++c) detail::SplitColumn(R0, c).store(data.R[0], c);
  detail::SplitColumn(base.position).store(data.p[0]);
  const int nb = model.nb();
  for (int i = 1; i < nb; ++i) {
    const Body& b = model.body(i);
    if (b.joint.type == JointType::Revolute)
      detail::sin_cos(b.joint_position(theta), data.sin_q[static_cast<size_t>(i)],
                      data.cos_q[static_cast<size_t>(i)]);
  }
  using detail::SplitColumn;
  for (int i = 1; i < nb; ++i) {
    const Body& b = model.body(i);
    const detail::JointKinematics& jk = model.joint_kinematics(i);
    const auto ui = static_cast<size_t>(i);
    const auto pi = static_cast<size_t>(b.parent);
    const Matrix3& Rp = data.R[pi];
    const Vector3& t = b.tree.p;
    const SplitColumn P0(Rp, 0), P1(Rp, 1), P2(Rp, 2);
    const SplitColumn pj = SplitColumn(data.p[pi]) + ((P0 * t(0) + P1 * t(1)) + P2 * t(2));
    const int a = jk.axis;
    const bool revolute = b.joint.type == JointType::Revolute;
    // the joint frame in o, J = Rp tree.R, where it is needed: a joint origin without rotation (rpy
    // 0 0 0, most URDF joints) keeps the parent's axes; a revolute joint about a general axis folds
    // tree.R into its constants (JointKinematics)
    SplitColumn J[3] = {P0, P1, P2};
    if (!jk.tree_identity && (a >= 0 || !revolute)) detail::multiply3(P0, P1, P2, b.tree.R, J);
    // the joint axis in o: for an axis +-x, +-y or +-z (exactly +-1) a column of the joint frame, else
    // Rp (tree.R k)
    const SplitColumn z = a >= 0 ? J[a] * b.joint.axis(a) : (P0 * jk.z(0) + P1 * jk.z(1)) + P2 * jk.z(2);
    const double k = b.multiplier;
    double* S = data.S.col(i - 1).data();
    Matrix3& R = data.R[ui];
    if (revolute) {
      double s = data.sin_q[ui];
      const double c = data.cos_q[ui];
      if (a >= 0) {  // about +-x, +-y or +-z: a plane rotation of two columns (12 products)
        s *= b.joint.axis(a);
        const int c1 = jk.next1, c2 = jk.next2;
        J[a].store(R, a);
        (J[c1] * c + J[c2] * s).store(R, c1);
        (J[c2] * c - J[c1] * s).store(R, c2);
      } else {  // R = Rp (tree.R + s B + (1 - c) D): Rodrigues' formula with tree.R folded in
        const double u = 1.0 - c;
        Matrix3 M;
        const double *A = b.tree.R.data(), *B = jk.B.data(), *D = jk.D.data();
        for (int e = 0; e < 9; ++e) M.data()[e] = A[e] + (s * B[e] + u * D[e]);
        SplitColumn C[3];
        detail::multiply3(P0, P1, P2, M, C);
        for (int col = 0; col < 3; ++col) C[col].store(R, col);
      }
      pj.store(data.p[ui]);
      const double d0 = pj.entry(0) - data.p[0](0), d1 = pj.entry(1) - data.p[0](1),
                   d2 = pj.entry(2) - data.p[0](2);
      const double z0 = z.entry(0), z1 = z.entry(1), z2 = z.entry(2);
      S[0] = d1 * z2 - d2 * z1;  // (p_j - p_0) x z
      S[1] = d2 * z0 - d0 * z2;
      S[2] = d0 * z1 - d1 * z0;
      S[3] = z0;
      S[4] = z1;
      S[5] = z2;
      if (k != 1.0)  // a mimic joint's multiplier
        for (int e = 0; e < 6; ++e) S[e] *= k;
    } else {
      for (int col = 0; col < 3; ++col) J[col].store(R, col);
      const double q = b.joint_position(theta);
      (pj + z * q).store(data.p[ui]);
      S[0] = k * z.entry(0);
      S[1] = k * z.entry(1);
      S[2] = k * z.entry(2);
      S[3] = S[4] = S[5] = 0.0;
    }
  }
}

/// World pose of a frame after forward_kinematics. Reads data.R, data.p.
inline Pose frame_pose(const Model& model, const Data& data, int frame) {
  const Frame& f = model.frame(frame);
  const auto b = static_cast<size_t>(f.body);
  return {data.p[b] + data.R[b] * f.pose.p, data.R[b] * f.pose.R};
}

/// True when body `ancestor` is `body` or on its path to the base.
inline bool supports(const Model& model, int ancestor, int body) {
  for (int i = body; i >= 0; i = model.body(i).parent)
    if (i == ancestor) return true;
  return false;
}

}  // namespace ffsr
