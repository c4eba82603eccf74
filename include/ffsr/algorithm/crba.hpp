// ffsr/algorithm/crba.hpp -- the composite rigid body algorithm for the free-floating tree.
#pragma once

#include "ffsr/algorithm/kinematics.hpp"

#include <algorithm>

namespace ffsr {

namespace detail {

/// The inertia of body i in inertial axes about the base frame origin p_0 (10 parameters,
/// SpatialInertia::from_body). Reads the kinematics. Writes data.Ic[i] (the body alone).
inline void body_inertia(const Model& model, Data& data, int i) {
  const auto ui = static_cast<size_t>(i);
  const Inertia& in = model.body(i).inertia;
  data.Ic[ui].set_body(in.mass, in.com, in.I, model.inertia_diagonal(i), data.R[ui], data.p[ui] - data.p[0]);
}

/// body_inertia of every body. Writes data.Ic (the bodies alone, not yet composite).
inline void body_inertias(const Model& model, Data& data) {
  for (int i = 0; i < model.nb(); ++i) body_inertia(model, data, i);
}

/// The composite inertia of every body's subtree (body_inertias, then each body added into its
/// parent's from the leaves). Reads the kinematics. Writes data.Ic.
inline void composite_inertias(const Model& model, Data& data) {
  body_inertias(model, data);
  for (int i = model.nb() - 1; i > 0; --i)  // the children of i come after it: Ic_i is complete here
    data.Ic[static_cast<size_t>(model.body(i).parent)] += data.Ic[static_cast<size_t>(i)];
}

}  // namespace detail

/// Joint-space inertia matrix H (Eq. 1) of the free-floating system by the composite rigid body
/// algorithm (RBDA 6.2), with all spatial quantities in inertial axes about the base frame origin,
/// so that the base motion subspace is the identity and composite inertias add without transforms.
///
/// The composite inertias are 10-parameter objects (SpatialInertia: m, h, Ibar), summed from the
/// leaves; F_i = Ic_i S_i is the base rows of H's column of joint i, and H's entry between joint j and
/// a joint i of its subtree is S_j . F_i. With the depth-first numbering of a URDF model
/// (Model::depth_first: every subtree a contiguous range of bodies, no mimic joint), column j of H
/// below the diagonal is one matrix-vector product, the contiguous columns F_i of its subtree (in
/// data.Fc) times S_j, then zeros, each entry stored into row j too (Pinocchio's CRBA in the world
/// convention fills one triangle the same way). Other trees walk the ancestors of each body. Cost:
/// O(n) spatial operations and n d / 2 six-term dot products (d the depth); no allocation.
///
/// Reads base, theta. Writes the kinematics (forward_kinematics), data.Ic (composite), data.Fc and
/// data.H, the full symmetric (6+n)x(6+n) matrix in the coordinates of model.hpp (a coordinate that
/// drives several joints through mimics sums their entries: H = T^T H_full T). Returns data.H.
/// Throws NumericalError when H overflows (not finite).
inline const Eigen::MatrixXd& crba(const Model& model, Data& data, const BasePose& base,
                                   const Eigen::Ref<const Eigen::VectorXd>& theta) {
  forward_kinematics(model, data, base, theta);
  detail::composite_inertias(model, data);
  const int nb = model.nb();

  Eigen::MatrixXd& H = data.H;
  const Eigen::Index ld = H.rows();
  data.Ic[0].store(H.topLeftCorner<6, 6>());
  if (model.depth_first()) {
    // F_i = Ic_i S_i is the base rows of H's column of joint i and the base columns of its row
    for (int i = 1; i < nb; ++i) {
      const Vector6 F = data.Ic[static_cast<size_t>(i)] * Vector6(data.S.col(i - 1));
      double* col = H.data() + (5 + i) * ld;
      double* row = H.data() + (5 + i);
      double* Fi = data.Fc.col(i - 1).data();
      for (int k = 0; k < 6; ++k) {
        Fi[k] = F(k);
        col[k] = F(k);
        row[k * ld] = F(k);
      }
    }
    for (int j = 1; j < nb; ++j) {
      const int cj = 5 + j;  // H's index of joint j (coordinate j - 1)
      const double* Sj = data.S.col(j - 1).data();
      const double s0 = Sj[0], s1 = Sj[1], s2 = Sj[2], s3 = Sj[3], s4 = Sj[4], s5 = Sj[5];
      const int len = model.subtree_last(j) - j + 1;  // the subtree of j: bodies j..last
      // column cj from the diagonal down: S_j . F_i for the subtree (its contiguous columns of Fc;
      // independent iterations), then zeros for the other branches
      double* __restrict out = H.data() + cj + cj * ld;
      const double* __restrict F = data.Fc.col(j - 1).data();
      for (int i = 0; i < len; ++i, F += 6) {
        const double h = s0 * F[0] + s1 * F[1] + s2 * F[2] + s3 * F[3] + s4 * F[4] + s5 * F[5];
        out[i] = h;
        out[i * ld] = h;  // row cj from the diagonal on
      }
      for (int i = len; i < nb - j; ++i) {
        out[i] = 0.0;
        out[i * ld] = 0.0;
      }
    }
  } else {
    const int n = model.n();
    H.bottomRightCorner(n, n).setZero();
    H.topRightCorner(6, n).setZero();
    H.bottomLeftCorner(n, 6).setZero();
    for (int i = 1; i < nb; ++i) {
      const Vector6 F = data.Ic[static_cast<size_t>(i)] * Vector6(data.S.col(i - 1));
      data.Fc.col(i - 1) = F;
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
  // found by fuzz_urdf) overflow to inf/NaN here: an error, never a NaN answer downstream. Each entry
  // of H is an entry of Ic_0, a sum of entries of the F_i, or a sum of products S_j . F_i over distinct
  // pairs (i, j), each pair at most twice, so |entry| <= 2 sum|S| sum|F|: H is finite when those sums
  // and Ic_0's are finite and the bound is below the largest double (12 n + 13 numbers, not (6 + n)^2).
  // A NaN or an infinity makes its sum NaN or infinite, and the comparisons false.
  const SpatialInertia& I0 = data.Ic[0];
  const double sum_I0 = std::abs(I0.m) + I0.h.cwiseAbs().sum() + I0.Ibar.cwiseAbs().sum();
  const double sum_S = data.S.cwiseAbs().sum(), sum_F = data.Fc.cwiseAbs().sum();
  if (!(sum_I0 <= 1e300 && sum_S <= 1e300 && sum_F <= 1e300 && sum_S * sum_F <= 5e307))
    FFSR_THROW(NumericalError(
        detail::str("crba: the inertia matrix H is not finite: the model's lengths, masses or the "
                    "joint positions overflow double precision (",
                    model.source, ")")));
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
      FFSR_THROW(NumericalError(str(where, ": the inertia matrix is not positive definite (pivot ", j, ")")));
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
