// ffsr/algorithm/crba.hpp -- the composite rigid body algorithm for the free-floating tree.
#pragma once

#include "ffsr/algorithm/kinematics.hpp"

namespace ffsr {

/// Joint-space inertia matrix H (Eq. 1) of the free-floating system by the composite rigid body
/// algorithm (RBDA 6.2), with all spatial quantities in inertial axes about the base frame origin,
/// so that the base motion subspace is the identity and composite inertias add without transforms.
/// Reads base, theta. Writes the kinematics (forward_kinematics), data.Ic and data.H, the full
/// symmetric (6+n)x(6+n) matrix in the coordinates of model.hpp (a coordinate that drives several
/// joints through mimics sums their entries: H = T^T H_full T). Returns data.H. Throws NumericalError
/// when H overflows (not finite).
inline const Eigen::MatrixXd& crba(const Model& model, Data& data, const BasePose& base,
                                   const Eigen::Ref<const Eigen::VectorXd>& theta) {
  forward_kinematics(model, data, base, theta);
  const int nb = model.nb();
  const Vector3& p0 = data.p[0];
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    const Matrix3& Ri = data.R[ui];
    data.Ic[ui] =
        SpatialInertia::from_com(in.mass, data.p[ui] + Ri * in.com - p0, Ri * in.I * Ri.transpose());
  }
  for (int i = nb - 1; i > 0; --i)
    data.Ic[static_cast<size_t>(model.body(i).parent)] += data.Ic[static_cast<size_t>(i)];

  Eigen::MatrixXd& H = data.H;
  H.setZero();
  H.topLeftCorner<6, 6>() = data.Ic[0].matrix();
  for (int i = 1; i < nb; ++i) {
    const Vector6 S = data.S.col(i - 1);
    const Vector6 F = data.Ic[static_cast<size_t>(i)] * S;
    const int ci = 6 + model.body(i).coord;
    H(ci, ci) += S.dot(F);
    for (int j = model.body(i).parent; j > 0; j = model.body(j).parent) {
      const int cj = 6 + model.body(j).coord;
      const double hij = data.S.col(j - 1).dot(F);
      H(cj, ci) += hij;  // both (i, j) and (j, i): twice on the diagonal when i and j share a coordinate
      H(ci, cj) += hij;
    }
    H.block<6, 1>(0, ci) += F;
    H.block<1, 6>(ci, 0) += F.transpose();
  }
  // Entries between joints on different branches stay zero.
  // Finite but huge lengths, masses or prismatic positions (a joint origin of 1e186 m in a URDF,
  // found by fuzz_urdf) overflow to inf/NaN here: an error, never a NaN answer downstream. The sum of
  // the entries is not finite exactly when an entry is not, or when finite entries sum past 1.8e308
  // (an overflow too); Eigen's vectorized sum costs a third of the entry-by-entry test.
  if (!std::isfinite(H.sum()))
    throw NumericalError(
        detail::str("crba: the inertia matrix H is not finite: the model's lengths, masses or the "
                    "joint positions overflow double precision (",
                    model.source, ")"));
  return H;
}

namespace detail {

/// In-place Cholesky factorization L L^T = A of the lower triangle, without allocation.
/// Throws NumericalError when A is not positive definite.
inline void cholesky(const Eigen::MatrixXd& A, Eigen::MatrixXd& L, const char* where) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    double d = A(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!(d > 0.0))
      throw NumericalError(str(where, ": the inertia matrix is not positive definite (pivot ", j, ")"));
    const double ljj = std::sqrt(d);
    L(j, j) = ljj;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      double s = A(i, j);
      for (Eigen::Index k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s / ljj;
    }
  }
}

/// Forward substitution: solves L z = b in place (x holds b on entry, z on exit).
inline void cholesky_forward(const Eigen::MatrixXd& L, Eigen::VectorXd& x) {
  const Eigen::Index n = L.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    double s = x(i);
    for (Eigen::Index k = 0; k < i; ++k) s -= L(i, k) * x(k);
    x(i) = s / L(i, i);
  }
}

/// Back substitution: solves L^T y = z in place.
inline void cholesky_backward(const Eigen::MatrixXd& L, Eigen::VectorXd& x) {
  const Eigen::Index n = L.rows();
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    double s = x(i);
    for (Eigen::Index k = i + 1; k < n; ++k) s -= L(k, i) * x(k);
    x(i) = s / L(i, i);
  }
}

/// Solves L L^T x = b in place (x holds b on entry).
inline void cholesky_solve(const Eigen::MatrixXd& L, Eigen::VectorXd& x) {
  cholesky_forward(L, x);
  cholesky_backward(L, x);
}

}  // namespace detail
}  // namespace ffsr
