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
  if (qn < 1e-9) throw InputError(str(where, ": base orientation quaternion has zero norm"));
  return qn;
}

/// C = A B for 3x3 matrices, written out (27 products; Eigen's lazy product is a call at -O2).
inline void multiply3(const Matrix3& A, const Matrix3& B, Matrix3& C) {
  for (int c = 0; c < 3; ++c) {
    const double b0 = B(0, c), b1 = B(1, c), b2 = B(2, c);
    C(0, c) = A(0, 0) * b0 + A(0, 1) * b1 + A(0, 2) * b2;
    C(1, c) = A(1, 0) * b0 + A(1, 1) * b1 + A(1, 2) * b2;
    C(2, c) = A(2, 0) * b0 + A(2, 1) * b1 + A(2, 2) * b2;
  }
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
  data.R[0] = data.base.orientation.toRotationMatrix();
  data.p[0] = base.position;
  const int nb = model.nb();
  for (int i = 1; i < nb; ++i) {
    const Body& b = model.body(i);
    if (b.joint.type == JointType::Revolute)
      detail::sin_cos(b.joint_position(theta), data.sin_q[static_cast<size_t>(i)],
                      data.cos_q[static_cast<size_t>(i)]);
  }
  for (int i = 1; i < nb; ++i) {
    const Body& b = model.body(i);
    const detail::JointKinematics& jk = model.joint_kinematics(i);
    const auto ui = static_cast<size_t>(i);
    const auto pi = static_cast<size_t>(b.parent);
    const Matrix3& Rp = data.R[pi];
    const Vector3& t = b.tree.p;
    const Vector3& pp = data.p[pi];
    const Vector3 pj(pp(0) + (Rp(0, 0) * t(0) + Rp(0, 1) * t(1) + Rp(0, 2) * t(2)),
                     pp(1) + (Rp(1, 0) * t(0) + Rp(1, 1) * t(1) + Rp(1, 2) * t(2)),
                     pp(2) + (Rp(2, 0) * t(0) + Rp(2, 1) * t(1) + Rp(2, 2) * t(2)));
    const int a = jk.axis;
    const bool revolute = b.joint.type == JointType::Revolute;
    // the joint frame in o, Rj = Rp tree.R, where it is needed: a joint origin without rotation (rpy
    // 0 0 0, most URDF joints) keeps the parent's axes; a revolute joint about a general axis folds
    // tree.R into its constants (JointKinematics)
    Matrix3 Rj;
    const Matrix3* J = &Rp;
    if (!jk.tree_identity && (a >= 0 || !revolute)) {
      detail::multiply3(Rp, b.tree.R, Rj);
      J = &Rj;
    }
    // the joint axis in o: for an axis +-x, +-y or +-z (exactly +-1) a column of the joint frame, else
    // Rp (tree.R k)
    Vector3 z;
    if (a >= 0) {
      z = b.joint.axis(a) * J->col(a);
    } else {
      const Vector3& zl = jk.z;
      z = Vector3(Rp(0, 0) * zl(0) + Rp(0, 1) * zl(1) + Rp(0, 2) * zl(2),
                  Rp(1, 0) * zl(0) + Rp(1, 1) * zl(1) + Rp(1, 2) * zl(2),
                  Rp(2, 0) * zl(0) + Rp(2, 1) * zl(1) + Rp(2, 2) * zl(2));
    }
    const double q = b.joint_position(theta), k = b.multiplier;
    double* S = data.S.col(i - 1).data();
    if (revolute) {
      Matrix3& R = data.R[ui];
      double s = data.sin_q[ui], c = data.cos_q[ui];
      if (a >= 0) {  // about +-x, +-y or +-z: a plane rotation of two columns (12 products)
        const Matrix3& Q = *J;
        s *= b.joint.axis(a);
        const int c1 = (a + 1) % 3, c2 = (a + 2) % 3;
        for (int r = 0; r < 3; ++r) {
          const double q1 = Q(r, c1), q2 = Q(r, c2);
          R(r, a) = Q(r, a);
          R(r, c1) = c * q1 + s * q2;
          R(r, c2) = c * q2 - s * q1;
        }
      } else {  // R = Rp (tree.R + s B + (1 - c) D): Rodrigues' formula with tree.R folded in
        const double u = 1.0 - c;
        Matrix3 M;
        const double *A = b.tree.R.data(), *B = jk.B.data(), *D = jk.D.data();
        for (int e = 0; e < 9; ++e) M.data()[e] = A[e] + (s * B[e] + u * D[e]);
        detail::multiply3(Rp, M, R);
      }
      data.p[ui] = pj;
      const double d0 = pj(0) - data.p[0](0), d1 = pj(1) - data.p[0](1), d2 = pj(2) - data.p[0](2);
      S[0] = d1 * z(2) - d2 * z(1);  // (p_j - p_0) x z
      S[1] = d2 * z(0) - d0 * z(2);
      S[2] = d0 * z(1) - d1 * z(0);
      S[3] = z(0);
      S[4] = z(1);
      S[5] = z(2);
      if (k != 1.0)  // a mimic joint's multiplier
        for (int e = 0; e < 6; ++e) S[e] *= k;
    } else {
      data.R[ui] = *J;
      data.p[ui] = pj + z * q;
      S[0] = k * z(0);
      S[1] = k * z(1);
      S[2] = k * z(2);
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
