// ffsr/algorithm/articulated_effective_mass.hpp -- the inverse effective mass (Eq. 4) in O(n) by
// articulated-body inertias, without forming H: the recursion behind integrated_effective_mass
// (effective_mass.hpp) and its gradient (effective_mass_gradient.hpp); and, for few joints, the
// composite route (the floating base's Schur complement over the composite inertias).
#pragma once

#include "ffsr/algorithm/joint_models.hpp"

namespace ffsr {
namespace detail {

/// Solves A x = b for a symmetric positive definite 6x6 A by Cholesky with fixed loop bounds (the
/// compiler unrolls it; Eigen's LLT<Matrix6> runs its generic loops: 6 % of the recursion's time at 14 joints).
/// The two substitutions multiply by the reciprocals of the pivots the factorization already formed
/// (6 divisions in all, not 18: the divisions are the latency of this chain of dependent operations).
/// Reads the lower triangle. False when A is not positive definite (x is then unspecified).
inline bool solve_spd6(const Matrix6& A, const Vector6& b, Vector6& x) {
  double L[6][6], inv[6];
  for (int j = 0; j < 6; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0.0)) return false;
    const double ljj = std::sqrt(d);
    inv[j] = 1.0 / ljj;
    L[j][j] = ljj;
    for (int i = j + 1; i < 6; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
      L[i][j] = s * inv[j];
    }
  }
  for (int i = 0; i < 6; ++i) {  // L z = b
    double s = b(i);
    for (int k = 0; k < i; ++k) s -= L[i][k] * x(k);
    x(i) = s * inv[i];
  }
  for (int i = 5; i >= 0; --i) {  // L^T x = z
    double s = x(i);
    for (int k = i + 1; k < 6; ++k) s -= L[k][i] * x(k);
    x(i) = s * inv[i];
  }
  return true;
}

/// x^T A^-1 x for a symmetric positive definite 6x6 A by the LDL^T factorization with fixed loop
/// bounds: with A = L D L^T (L unit lower triangular) and L y = x, x^T A^-1 x = sum_j y_j^2 / D_j.
/// No square root and no back substitution (solve_spd6 needs both for the solution itself): one
/// division per pivot. Reads the lower triangle. False when A is not positive definite (a pivot
/// D_j <= 0 or NaN; q is then unspecified).
inline bool inverse_quadratic_spd6(const Matrix6& A, const Vector6& x, double& q) {
  double L[6][6], D[6], inv[6], y[6];
  q = 0.0;
  for (int j = 0; j < 6; ++j) {
    double v[6];  // L_jk D_k
    double d = A(j, j);
    for (int k = 0; k < j; ++k) {
      // cppcheck-suppress uninitvar ; L[j][k] and D[k] for k < j were written at pivot k
      v[k] = L[j][k] * D[k];
      d -= L[j][k] * v[k];
    }
    if (!(d > 0.0)) return false;
    D[j] = d;
    inv[j] = 1.0 / d;
    for (int i = j + 1; i < 6; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * v[k];
      L[i][j] = s * inv[j];
    }
    double yj = x(j);
    // cppcheck-suppress uninitvar ; y[k] for k < j was written at pivot k
    for (int k = 0; k < j; ++k) yj -= L[j][k] * y[k];
    y[j] = yj;
    q += yj * yj * inv[j];
  }
  return true;
}

/// The adjugate of the symmetric 3x3 matrix with upper triangle m00 m01 m02 m11 m12 m22, as its upper
/// triangle a[0..5] (same order); returns the determinant. Sets `pd` false unless the leading minors
/// m00, m00 m11 - m01^2 and the determinant are positive (Sylvester's criterion).
inline double adjugate_sym3(double m00, double m01, double m02, double m11, double m12, double m22,
                            double (&a)[6], bool& pd) {
  a[0] = m11 * m22 - m12 * m12;
  a[1] = m02 * m12 - m01 * m22;
  a[2] = m01 * m12 - m02 * m11;
  a[3] = m00 * m22 - m02 * m02;
  a[4] = m01 * m02 - m00 * m12;
  a[5] = m00 * m11 - m01 * m01;
  const double det = (m00 * a[0] + m01 * a[1]) + m02 * a[2];
  pd = pd && m00 > 0.0 && a[5] > 0.0 && det > 0.0;
  return det;
}

/// x^T A^-1 x for the articulated inertia A = [P X; X^T C] of the base (3x3 blocks, P and C
/// symmetric) and x = [a; b], by block elimination with adjugates and one division: with
/// S' = |P| C - X^T adj(P) X (|P| times the Schur complement of P) and y' = |P| b - X^T adj(P) a,
///   x^T A^-1 x = (a^T adj(P) a |S'| + y'^T adj(S') y') / (|P| |S'|).
/// inverse_quadratic_spd6's LDL^T takes six dependent divisions and a 6x6 copy; this is a third of
/// the recursion's time on the 3-DOF robot. When a leading minor is not positive (A not positive
/// definite, or NaN) or the determinants leave the normal range of doubles, the LDL^T decides.
inline bool inverse_quadratic_articulated(const ArticulatedInertia& A, const Vector6& x, double& q) {
  const Matrix3 &P = A.ll, &X = A.la, &C = A.aa;
  bool pd = true;
  double aP[6];
  const double dP = adjugate_sym3(P(0, 0), P(0, 1), P(0, 2), P(1, 1), P(1, 2), P(2, 2), aP, pd);
  const double G[3][3] = {{aP[0], aP[1], aP[2]}, {aP[1], aP[3], aP[4]}, {aP[2], aP[4], aP[5]}};
  double GX[3][3];  // adj(P) X, by columns
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) GX[c][r] = (G[r][0] * X(0, c) + G[r][1] * X(1, c)) + G[r][2] * X(2, c);
  auto sp = [&](int i, int j) {  // S'_ij
    return dP * C(i, j) - ((X(0, i) * GX[j][0] + X(1, i) * GX[j][1]) + X(2, i) * GX[j][2]);
  };
  double ya[3];  // adj(P) a
  for (int r = 0; r < 3; ++r) ya[r] = (G[r][0] * x(0) + G[r][1] * x(1)) + G[r][2] * x(2);
  const double t1 = (x(0) * ya[0] + x(1) * ya[1]) + x(2) * ya[2];
  double yp[3];
  for (int i = 0; i < 3; ++i) yp[i] = dP * x(3 + i) - ((X(0, i) * ya[0] + X(1, i) * ya[1]) + X(2, i) * ya[2]);
  double aS[6];
  const double dS = adjugate_sym3(sp(0, 0), sp(0, 1), sp(0, 2), sp(1, 1), sp(1, 2), sp(2, 2), aS, pd);
  const double t2 = yp[0] * (aS[0] * yp[0] + 2.0 * (aS[1] * yp[1] + aS[2] * yp[2])) +
                    yp[1] * (aS[3] * yp[1] + 2.0 * aS[4] * yp[2]) + aS[5] * yp[2] * yp[2];
  const double den = dP * dS;
  if (pd && den >= std::numeric_limits<double>::min() && den <= std::numeric_limits<double>::max()) {
    q = (t1 * dS + t2) / den;
    if (q >= 0.0 && q <= std::numeric_limits<double>::max()) return true;
  }
  return inverse_quadratic_spd6(A.matrix(), x, q);
}

/// The inverse of a rigid body's spatial inertia I = [m 1, -[h]x; [h]x, Ibar] (linear first, about a
/// reference point), by its centre of mass: with K = Ibar - (|h|^2 1 - h h^T) / m (the rotational
/// inertia about the centre of mass), I [v; w] = [a; b] gives w = K^-1 (b - h x a / m) and
/// v = (a + h x w) / m. K^-1 is its adjugate over its determinant. `ok` is false unless m and K are
/// positive definite with m, 1/m and |K| in the normal range of doubles.
struct RigidInverse {
  double im = 0.0, h0 = 0.0, h1 = 0.0, h2 = 0.0;
  double k[6] = {};  ///< K^-1, upper triangle k00 k01 k02 k11 k12 k22
  bool ok = false;
  explicit RigidInverse(const SpatialInertia& I) : h0(I.h(0)), h1(I.h(1)), h2(I.h(2)) {
    constexpr double lo = std::numeric_limits<double>::min(), hi = std::numeric_limits<double>::max();
    if (!(I.m >= lo && I.m <= hi)) return;
    im = 1.0 / I.m;
    const Matrix3& B = I.Ibar;
    bool pd = im <= hi;
    double a[6];
    const double det = adjugate_sym3(B(0, 0) - (h1 * h1 + h2 * h2) * im, B(0, 1) + h0 * h1 * im,
                                     B(0, 2) + h0 * h2 * im, B(1, 1) - (h0 * h0 + h2 * h2) * im,
                                     B(1, 2) + h1 * h2 * im, B(2, 2) - (h0 * h0 + h1 * h1) * im, a, pd);
    if (!pd || !(det >= lo && det <= hi)) return;
    const double id = 1.0 / det;
    for (int e = 0; e < 6; ++e) k[e] = a[e] * id;
    ok = true;
  }
  /// out = I^-1 x (6 entries each); returns x^T I^-1 x.
  double solve(const double* x, double* out) const {
    const double a0 = x[0], a1 = x[1], a2 = x[2];
    const double c0 = x[3] - (h1 * a2 - h2 * a1) * im, c1 = x[4] - (h2 * a0 - h0 * a2) * im,
                 c2 = x[5] - (h0 * a1 - h1 * a0) * im;
    const double w0 = (k[0] * c0 + k[1] * c1) + k[2] * c2, w1 = (k[1] * c0 + k[3] * c1) + k[4] * c2,
                 w2 = (k[2] * c0 + k[4] * c1) + k[5] * c2;
    const double v0 = (a0 + (h1 * w2 - h2 * w1)) * im, v1 = (a1 + (h2 * w0 - h0 * w2)) * im,
                 v2 = (a2 + (h0 * w1 - h1 * w0)) * im;
    out[0] = v0, out[1] = v1, out[2] = v2, out[3] = w0, out[4] = w1, out[5] = w2;
    return ((a0 * v0 + a1 * v1) + a2 * v2) + ((x[3] * w0 + x[4] * w1) + x[5] * w2);
  }
};

/// a . b for 6-vectors, summed in pairs (three independent chains)
inline double dot6_paired(const double* a, const double* b) {
  return ((a[0] * b[0] + a[1] * b[1]) + (a[2] * b[2] + a[3] * b[3])) + (a[4] * b[4] + a[5] * b[5]);
}

/// composite_inertias on a depth-first model, and F_i = Ic_i S_i into data.Fc as each Ic_i is
/// complete: each body's own inertia is formed at the step of its first child reached (a leaf's at
/// its own), where its independent operations fill the gaps of the chain of sums from the leaves.
/// Reads the kinematics. Writes data.Ic (composite) and data.Fc.
inline void composite_inertias_and_forces(const Model& model, Data& data) {
  const int nb = model.nb();
  if (nb == 1) body_inertia(model, data, 0);
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i);
    const int p = model.body(i).parent;
    if (model.subtree_last(i) == i) body_inertia(model, data, i);
    const Vector6 F = data.Ic[ui] * Vector6(data.S.col(i - 1));
    double* Fi = data.Fc.col(i - 1).data();
    for (int e = 0; e < 6; ++e) Fi[e] = F(e);
    if (model.subtree_last(i) == model.subtree_last(p)) body_inertia(model, data, p);
    data.Ic[static_cast<size_t>(p)] += data.Ic[ui];
  }
}

/// w^T (H + diag(0, a))^-1 w for the generalized force w = J^T f of the spatial force f (about p_0,
/// inertial axes) on body `ee`, by the composite inertias and the floating base's Schur complement:
/// with H = [Ic_0 F; F^T H_m] (Ic_0 the composite inertia of the whole robot, a rigid body's, F_i =
/// Ic_i S_i) and w = [f; w_m] (w_m,i = S_i . f for the joints that support ee),
///   w^T H^-1 w = f^T Ic_0^-1 f + r^T M^-1 r,  M = H_m + diag(a) - F^T Ic_0^-1 F,  r = w_m - F^T Ic_0^-1 f,
/// M (n x n, the inertia of the joints with the base free) by an LDL^T with one division per pivot:
/// r^T M^-1 r = sum_j y_j^2 / D_j for L y = r. O(n^2) entries and an O(n^3) factorization, without
/// the recursion's 6x6 rank-one update per body: the faster route for few joints (see
/// kCompositeMaxJoints). Requires a depth-first model with one body per coordinate. Reads the
/// kinematics. Writes data.Ic (composite), data.Fc, data.L (Ic_0^-1 F in its top rows, M's upper
/// triangle below, reduced in place by the elimination) and data.y. False when Ic_0 or M is not
/// positive definite or the result is not a finite non-negative number (q is then unspecified): the
/// articulated route decides those cases.
inline bool inverse_form_composite(const Model& model, Data& data, int ee, const Vector6& f,
                                   const Eigen::VectorXd* armature, double& q) {
  composite_inertias_and_forces(model, data);
  const RigidInverse I0(data.Ic[0]);
  if (!I0.ok) return false;
  const int n = model.nb() - 1;
  const Eigen::Index ld = data.L.rows();
  double* const L = data.L.data() + 6 * ld;  // column j of the joints: G_j = Ic_0^-1 F_j, then M's column j
  double* const r = data.y.data() + 6;
  double g[6];
  q = I0.solve(f.data(), g);
  for (int j = 0; j < n; ++j) I0.solve(data.Fc.col(j).data(), L + j * ld);
  // M's upper triangle (M_ij, i <= j, in column j) and r: with T_i = S_i - G_i (G_i = Ic_0^-1 F_i),
  // M_ij = F_j . T_i for j in the subtree of i (the contiguous range i..last; S_i . F_j is H_m's entry)
  // and -F_j . G_i for the others; r_i = T_i . f for the joints that support ee (F_i . g = G_i . f) and
  // -G_i . f for the others
  for (int i = 0; i < n; ++i) {
    const double* Si = data.S.col(i).data();
    const double* Gi = L + i * ld;
    const double T[6] = {Si[0] - Gi[0], Si[1] - Gi[1], Si[2] - Gi[2],
                         Si[3] - Gi[3], Si[4] - Gi[4], Si[5] - Gi[5]};
    const int last = model.subtree_last(i + 1) - 1;
    for (int j = i; j <= last; ++j) L[j * ld + 6 + i] = dot6_paired(data.Fc.col(j).data(), T);
    for (int j = last + 1; j < n; ++j) L[j * ld + 6 + i] = -dot6_paired(data.Fc.col(j).data(), Gi);
    if (armature) L[i * ld + 6 + i] += (*armature)(i);
    r[i] = i + 1 <= ee && ee <= last + 1 ? dot6_paired(T, f.data()) : -dot6_paired(Gi, f.data());
  }
  // LDL^T by eliminating one pivot after the other (the Schur complement of each in the trailing
  // upper triangle, in place), r eliminated with them: r^T M^-1 r = sum_k r_k^2 / D_k, r_k and D_k as
  // pivot k is reached. The updates after a pivot are independent of each other, so that the chain
  // of dependent operations from one pivot to the next is a division, a product and a subtraction
  // (each diagonal entry as M_ii - M_ki^2 / D_k, M_ki^2 formed before the division; the row-by-row
  // order waited on each entry of a row before the next).
  double* const M = L + 6;  // M's column j at M + j ld
  for (int k = 0; k < n; ++k) {
    const double d = M[k * ld + k];
    if (!(d > 0.0)) return false;
    const double inv = 1.0 / d, rk = r[k];
    q += rk * rk * inv;
    for (int i = k + 1; i < n; ++i) {  // row i of the trailing triangle: M_ij -= (M_ki / D_k) M_kj
      const double mki = M[i * ld + k], ti = mki * inv;
      r[i] -= ti * rk;
      M[i * ld + i] -= (mki * mki) * inv;
      for (int j = i + 1; j < n; ++j) M[j * ld + i] -= ti * M[j * ld + k];
    }
  }
  return q >= 0.0 && q <= std::numeric_limits<double>::max();
}

/// The unit force u at the origin of `frame` as a spatial force about the base origin p_0 (inertial
/// axes, linear first): f = [u; (p_e - p_0) x u]. Checks u and the frame index. Reads the kinematics.
inline Vector6 unit_point_force(const Model& model, const Data& data, int frame, const Vector3& u) {
  check_unit_direction(u, "effective_mass");
  check_frame(model, frame, "effective_mass");
  const Frame& fr = model.frame(frame);
  const auto b = static_cast<size_t>(fr.body);
  const Vector3 pe = data.p[b] + data.R[b] * fr.pose.p;  // frame_pose's position, without its rotation
  if (!pe.allFinite())
    FFSR_THROW(NumericalError(str("effective_mass: the position of frame '", model.frame(frame).name,
                             "' overflows double precision")));
  Vector6 f;
  f << u, (pe - data.p[0]).cross(u);
  return f;
}

/// The backward pass of the articulated-body algorithm at rest (RBDA 7.3, floating base RBDA 9.4),
/// in inertial axes about p_0 so that no transform is needed: with IA_i starting as body i's own
/// inertia,
///   i = n..1:  U_i = IA_i S_i,  D_i = S_i^T U_i + a_i,  IA_parent += IA_i - U_i U_i^T / D_i,
/// where a_i is the armature of joint i (a reflected rotor inertia on H's diagonal; `armature` null
/// for none). A joint whose armature is infinite would pass IA_i unchanged: that is the Locked
/// model, which needs the composite inertia only (its callers sum it apart). Requires one body per
/// coordinate (no mimics). Reads the kinematics. Writes data.Ic (the bodies alone), data.IA, data.U,
/// data.D. Throws NumericalError when a D_i is not positive.
inline void articulated_inertias(const Model& model, Data& data, const Eigen::VectorXd* armature) {
  const int nb = model.nb();
  // On a depth-first model a body's articulated inertia starts at its first child reached (the last
  // child, whose subtree ends the body's): set_projected, without setting it first; leaves start
  // as their rigid inertia. Each body's own inertia is formed at that step (or a leaf's at its
  // own), where its independent operations fill the gaps of the recursion's chain. Other trees set
  // every body first.
  const bool df = model.depth_first();
  if (!df) {
    body_inertias(model, data);
    for (int i = 0; i < nb; ++i) data.IA[static_cast<size_t>(i)].set(data.Ic[static_cast<size_t>(i)]);
  } else if (nb == 1) {
    body_inertia(model, data, 0);
    data.IA[0].set(data.Ic[0]);
  }
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i);
    const int p = model.body(i).parent;
    const auto up = static_cast<size_t>(p);
    if (df && model.subtree_last(i) == i) {
      body_inertia(model, data, i);
      data.IA[ui].set(data.Ic[ui]);
    }
    const Vector6 S = data.S.col(i - 1);
    const Vector6 U = data.IA[ui] * S;
    const double D = S.dot(U) + (armature ? (*armature)(i - 1) : 0.0);
    if (!(D > 0.0))
      FFSR_THROW(NumericalError(
          str("effective_mass: the articulated inertia is not positive definite (joint ", i, ")")));
    data.U[ui] = U;
    data.D(i - 1) = D;
    if (df && model.subtree_last(i) == model.subtree_last(p)) {
      body_inertia(model, data, p);
      data.IA[up].set_projected(data.Ic[up], data.IA[ui], U, D);
    } else {
      data.IA[up].add_projected(data.IA[ui], U, D);
    }
  }
}

/// The rest of the articulated-body algorithm for the spatial force f on body `ee` and no joint
/// torque, after articulated_inertias: the bias forces along the path from `ee` to the base,
///   pA = -f on ee;  u_i = -S_i^T pA_i,  pA_parent = pA_i + U_i u_i / D_i  (only the path carries one).
/// Returns f^T a_ee = w^T (H + diag(0, a))^-1 w for w the generalized force of f (a_ee the
/// acceleration of body ee). `all` false: as the sum of the squared innovations over their
/// variances, sum_path u_i^2 / D_i + pA_0^T IA_0^-1 pA_0 (the articulated-body recursion factors
/// H^-1 as a Kalman filter factors a covariance: Rodriguez, Jain and Kreutz-Delgado 1991), so no
/// acceleration is formed. `all` true: the base acceleration a_0 = -IA_0^-1 pA_0 and the
/// accelerations a_i = a_parent + S_i qdd_i, qdd_i = (u_i - U_i^T a_parent) / D_i, of every body
/// (with u_i = 0 off the path); then data.y = [a_0; qdd] = (H + diag(0, a))^-1 J^T f and the result
/// is f^T a_ee. Reads data.IA, data.U, data.D, data.S. Writes data.path, data.u (and data.on_path,
/// data.A and data.y when `all`). Throws NumericalError when IA_0 is not positive definite.
inline double articulated_solve(const Model& model, Data& data, int ee, const Vector6& f, bool all) {
  const int nb = model.nb();
  int len = 0;
  for (int i = ee; i > 0; i = model.body(i).parent) data.path[static_cast<size_t>(len++)] = i;
  Vector6 pA = -f;
  double q = 0.0;
  // from ee towards the base; the next body's innovation ahead of pA's update, u_next = -S_next . pA -
  // (S_next . U_i) s_i, so that from one s_i to the next the chain of dependent operations is a product
  // and a subtraction (each 1 / D_i and the dot products wait for nothing on it)
  double u_k = len > 0 ? -data.S.col(data.path[0] - 1).dot(pA) : 0.0;
  for (int k = 0; k < len; ++k) {
    const int i = data.path[static_cast<size_t>(k)];
    const Vector6& Ui = data.U[static_cast<size_t>(i)];
    const double si = u_k * (1.0 / data.D(i - 1));
    data.u(i - 1) = u_k;
    q += u_k * si;
    if (k + 1 < len) {
      const auto Sn = data.S.col(data.path[static_cast<size_t>(k) + 1] - 1);
      u_k = -Sn.dot(pA) - Sn.dot(Ui) * si;
    }
    pA.noalias() += Ui * si;
  }
  if (!all) {
    double q0 = 0.0;
    if (!inverse_quadratic_articulated(data.IA[0], pA, q0))
      FFSR_THROW(NumericalError("effective_mass: the articulated inertia of the base is not positive definite"));
    return q + q0;
  }
  if (!solve_spd6(data.IA[0].matrix(), -pA, data.A[0]))
    FFSR_THROW(NumericalError("effective_mass: the articulated inertia of the base is not positive definite"));
  std::fill(data.on_path.begin(), data.on_path.end(), char(0));
  for (int k = 0; k < len; ++k) data.on_path[static_cast<size_t>(data.path[static_cast<size_t>(k)])] = 1;
  data.y.head<6>() = data.A[0];
  for (int i = 1; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Vector6& ap = data.A[static_cast<size_t>(model.body(i).parent)];
    const double u_i = data.on_path[ui] ? data.u(i - 1) : 0.0;
    const double qdd = (u_i - data.U[ui].dot(ap)) / data.D(i - 1);
    data.A[ui] = ap + data.S.col(i - 1) * qdd;
    data.y(5 + i) = qdd;
  }
  return f.dot(data.A[static_cast<size_t>(ee)]);
}

/// The locked robot's inverse form f^T Ic_0^-1 f (Ic_0 = H_bb, the composite inertia of the whole
/// robot about p_0, in data.Ic[0]); writes y_b = Ic_0^-1 f.
inline double locked_inverse_form_composite(const Data& data, const Vector6& f, Vector6& yb) {
  if (!solve_spd6(data.Ic[0].matrix(), f, yb))
    FFSR_THROW(NumericalError("effective_mass: the locked robot's inertia is not positive definite"));
  return f.dot(yb);
}

inline const Eigen::VectorXd* armature_of(const Model& model, const ContactJoints& joints) {
  if (joints.model != JointModel::Armature) return nullptr;
  require_size(joints.armature.size(), model.n(), "effective_mass", "armature");
  return &joints.armature;
}

}  // namespace detail

/// Inverse effective mass u^T J_v H^-1 J_v^T u (the denominator of Eq. 4) of the free-floating robot
/// at the origin of `frame`, in O(n) by the articulated-body algorithm (RBDA 7.3, with the floating
/// base of RBDA 9.4), at the configuration of the last forward_kinematics (or crba).
///
/// The identity: a unit force u applied at the frame origin p_e of the robot at rest, with no joint
/// torques, gives the generalized acceleration qdd = H^-1 J_v^T u, and the point p_e accelerates
/// along u at u^T J_v qdd, the wanted quantity. The external force is the spatial force
/// f = [u; (p_e - p_0) x u] on the frame's body; the articulated-body algorithm at zero velocity
/// would find the body accelerations it causes, and the result is f^T a_e (a_e the spatial
/// acceleration of that body), which its backward pass already gives as a sum of squares (see
/// detail::articulated_solve). All quantities are in inertial axes about the base origin p_0, as in
/// crba, so the motion subspaces are data.S and inertias add without transforms
/// (detail::articulated_inertias, detail::articulated_solve): one symmetric rank-one update of a 6x6
/// articulated inertia (kept as 3x3 blocks) per body, bias forces only along the path from the
/// frame's body to the base, one 6x6 LDL^T factorization at the base, no n x n matrix.
/// Reads the kinematics (data.R, data.p, data.S). Writes data.Ic (the bodies alone), data.IA, data.U,
/// data.D, data.u, data.path. Allocation-free. Throws InputError for a model with mimic joints
/// (use inverse_effective_mass), NumericalError when an articulated inertia is not positive definite.
inline double inverse_effective_mass_articulated(const Model& model, Data& data, int frame,
                                                 const Vector3& u) {
  const Vector6 f = detail::unit_point_force(model, data, frame, u);
  if (model.nb() - 1 != model.n())  // a mimic joint couples bodies through one coordinate: not a tree recursion
    FFSR_THROW(InputError(
        "inverse_effective_mass_articulated: the model has mimic joints; use inverse_effective_mass"));
  detail::articulated_inertias(model, data, nullptr);
  return detail::articulated_solve(model, data, model.frame(frame).body, f, false);
}

/// The same inverse effective mass under the joint model `joints` (joint_models.hpp), in O(n):
/// Free as above; Armature with the armature a_i added to each D_i (the recursion's form of
/// H + diag(0, a)); Locked from the composite inertia of the whole robot, f^T Ic_0^-1 f (the 6x6
/// H_bb, without the joint rows of H). Equal to inverse_effective_mass(model, data, frame, u, joints)
/// after crba to rounding. Reads the kinematics. Writes data.Ic (composite when Locked, else the bodies
/// alone) and, unless Locked, the fields of the recursion as above.
inline double inverse_effective_mass_articulated(const Model& model, Data& data, int frame, const Vector3& u,
                                                 const ContactJoints& joints) {
  const Vector6 f = detail::unit_point_force(model, data, frame, u);
  if (model.nb() - 1 != model.n())
    FFSR_THROW(InputError(
        "inverse_effective_mass_articulated: the model has mimic joints; use inverse_effective_mass"));
  if (joints.model == JointModel::Locked) {
    detail::composite_inertias(model, data);
    Vector6 yb;
    return detail::locked_inverse_form_composite(data, f, yb);
  }
  detail::articulated_inertias(model, data, detail::armature_of(model, joints));
  return detail::articulated_solve(model, data, model.frame(frame).body, f, false);
}

}  // namespace ffsr
