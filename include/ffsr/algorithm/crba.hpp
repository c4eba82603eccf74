// ffsr/algorithm/crba.hpp -- the composite rigid body algorithm for the free-floating tree.
#pragma once

#include "ffsr/algorithm/kinematics.hpp"

#include <algorithm>

namespace ffsr {

namespace detail {

/// The inertia of every body in inertial axes about the base frame origin p_0 (10 parameters each,
/// SpatialInertia::from_body). Reads the kinematics. Writes data.Ic (the bodies alone, not yet
/// composite).
inline void body_inertias(const Model& model, Data& data) {
  const int nb = model.nb();
  const Vector3& p0 = data.p[0];
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    data.Ic[ui] = SpatialInertia::from_body(in.mass, in.com, in.I, data.R[ui], data.p[ui] - p0);
  }
}

/// The numbering of the tree: data.last[i] (the largest body index in the subtree of i) and
/// data.nsub[i] (its number of bodies), by one backward pass (a parent comes before its children).
/// Returns true when every subtree is the contiguous range [i, last[i]] (depth-first numbering, as
/// the URDF loader makes) and no joint is a mimic (body i drives coordinate i - 1).
inline bool contiguous_subtrees(const Model& model, Data& data) {
  const int nb = model.nb();
  for (int i = 0; i < nb; ++i) {
    data.last[static_cast<size_t>(i)] = i;
    data.nsub[static_cast<size_t>(i)] = 1;
  }
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i), up = static_cast<size_t>(model.body(i).parent);
    data.last[up] = std::max(data.last[up], data.last[ui]);
    data.nsub[up] += data.nsub[ui];
  }
  if (nb - 1 != model.n()) return false;
  for (int i = 0; i < nb; ++i)
    if (data.nsub[static_cast<size_t>(i)] != data.last[static_cast<size_t>(i)] - i + 1) return false;
  return true;
}

}  // namespace detail

/// Joint-space inertia matrix H (Eq. 1) of the free-floating system by the composite rigid body
/// algorithm (RBDA 6.2), with all spatial quantities in inertial axes about the base frame origin,
/// so that the base motion subspace is the identity and composite inertias add without transforms.
///
/// The composite inertias are 10-parameter objects (SpatialInertia: m, h, Ibar), summed from the
/// leaves; F_i = Ic_i S_i is one row of data.Fc, and H's entry between joint j and a joint i of its
/// subtree is S_j . F_i. With the depth-first numbering of a URDF model (every subtree a contiguous
/// range of bodies) and no mimic joint, column j of H below the diagonal is one matrix-vector product,
/// the contiguous rows F_i^T of its subtree times S_j, then zeros, each entry stored into row j too
/// (Pinocchio's CRBA in the world convention fills one triangle the same way). Other trees walk
/// the ancestors of each body. Cost: O(n) spatial operations and n d / 2 six-term dot products (d the
/// depth); no allocation.
///
/// Reads base, theta. Writes the kinematics (forward_kinematics), data.Ic (composite), data.Fc,
/// data.last, data.nsub and data.H, the full symmetric (6+n)x(6+n) matrix in the coordinates of
/// model.hpp (a coordinate that drives several joints through mimics sums their entries:
/// H = T^T H_full T). Returns data.H. Throws NumericalError when H overflows (not finite).
inline const Eigen::MatrixXd& crba(const Model& model, Data& data, const BasePose& base,
                                   const Eigen::Ref<const Eigen::VectorXd>& theta) {
  forward_kinematics(model, data, base, theta);
  detail::body_inertias(model, data);
  const int nb = model.nb();
  for (int i = nb - 1; i > 0; --i) {  // the children of i come after it: Ic_i is complete here
    const SpatialInertia& Ic = data.Ic[static_cast<size_t>(i)];
    data.Fc.row(i - 1) = (Ic * Vector6(data.S.col(i - 1))).transpose();
    data.Ic[static_cast<size_t>(model.body(i).parent)] += Ic;
  }

  Eigen::MatrixXd& H = data.H;
  const int n = model.n();
  data.Ic[0].store(H.topLeftCorner<6, 6>());
  if (detail::contiguous_subtrees(model, data)) {
    H.bottomLeftCorner(n, 6) = data.Fc.topRows(n);  // the joint rows of the base columns: F_i^T
    for (int j = 1; j < nb; ++j) {
      const int cj = 5 + j;  // H's index of joint j (coordinate j - 1)
      const double* Sj = data.S.col(j - 1).data();
      const double s0 = Sj[0], s1 = Sj[1], s2 = Sj[2], s3 = Sj[3], s4 = Sj[4], s5 = Sj[5];
      const int len = data.last[static_cast<size_t>(j)] - j + 1;  // the subtree of j: bodies j..last
      // column cj from the diagonal down: S_j . F_i for the subtree (a matrix-vector product over
      // its contiguous rows of Fc, independent iterations), then zeros for the other branches
      double* __restrict out = H.col(cj).data() + cj;
      const Eigen::Index ldf = data.Fc.rows();
      const double* __restrict F0 = data.Fc.data() + (j - 1);
      double* __restrict row = H.data() + cj + cj * H.rows();  // row cj from the diagonal on
      const Eigen::Index ld = H.rows();
      for (int i = 0; i < len; ++i) {
        const double h = s0 * F0[i] + s1 * F0[i + ldf] + s2 * F0[i + 2 * ldf] + s3 * F0[i + 3 * ldf] +
                         s4 * F0[i + 4 * ldf] + s5 * F0[i + 5 * ldf];
        out[i] = h;
        row[i * ld] = h;
      }
      for (int i = len; i < nb - j; ++i) {
        out[i] = 0.0;
        row[i * ld] = 0.0;
      }
    }
    H.topRightCorner(6, n) = data.Fc.topRows(n).transpose();  // the base rows: F_i
  } else {
    H.bottomRightCorner(n, n).setZero();
    H.topRightCorner(6, n).setZero();
    H.bottomLeftCorner(n, 6).setZero();
    for (int i = 1; i < nb; ++i) {
      const Vector6 F = data.Fc.row(i - 1).transpose();
      const int ci = 6 + model.body(i).coord;
      H(ci, ci) += data.S.col(i - 1).dot(F);
      for (int j = model.body(i).parent; j > 0; j = model.body(j).parent) {
        const int cj = 6 + model.body(j).coord;
        const double hij = data.S.col(j - 1).dot(F);
        H(cj, ci) += hij;  // both (i, j) and (j, i): twice on the diagonal when i and j share a coordinate
        H(ci, cj) += hij;
      }
      H.block<6, 1>(0, ci) += F;
      H.block<1, 6>(ci, 0) += F.transpose();
    }
  }
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
