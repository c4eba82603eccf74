// ffsr/algorithm/aba.hpp -- forward dynamics of the free-floating tree in O(n) by the
// articulated-body algorithm.
#pragma once

#include "ffsr/algorithm/articulated_effective_mass.hpp"

namespace ffsr {
namespace detail {

/// f = V x* (I V) - I a_g for the rigid-body inertia I (m, h, Ibar) and the motion V = [v; w], with
/// a_g = [g; 0]: the velocity-product force of the body and its weight (RBDA 2.74, 7.37), written out
/// element by element (at -O2 GCC leaves Eigen's small fixed-size expressions and the helpers of
/// spatial.hpp as calls). I V = [m v - h x w; h x v + Ibar w]; V x* f = [w x f_l; w x f_a + v x f_l].
inline void rigid_bias_force(const SpatialInertia& I, const Vector6& V, const Vector3& g, Vector6& f) {
  const double v0 = V(0), v1 = V(1), v2 = V(2), w0 = V(3), w1 = V(4), w2 = V(5);
  const double h0 = I.h(0), h1 = I.h(1), h2 = I.h(2), m = I.m;
  const Matrix3& J = I.Ibar;
  const double l0 = m * v0 - (h1 * w2 - h2 * w1), l1 = m * v1 - (h2 * w0 - h0 * w2),
               l2 = m * v2 - (h0 * w1 - h1 * w0);
  const double a0 = (h1 * v2 - h2 * v1) + (J(0, 0) * w0 + J(0, 1) * w1 + J(0, 2) * w2);
  const double a1 = (h2 * v0 - h0 * v2) + (J(1, 0) * w0 + J(1, 1) * w1 + J(1, 2) * w2);
  const double a2 = (h0 * v1 - h1 * v0) + (J(2, 0) * w0 + J(2, 1) * w1 + J(2, 2) * w2);
  f(0) = w1 * l2 - w2 * l1;
  f(1) = w2 * l0 - w0 * l2;
  f(2) = w0 * l1 - w1 * l0;
  f(3) = (w1 * a2 - w2 * a1) + (v1 * l2 - v2 * l1);
  f(4) = (w2 * a0 - w0 * a2) + (v2 * l0 - v0 * l2);
  f(5) = (w0 * a1 - w1 * a0) + (v0 * l1 - v1 * l0);
  if (g(0) != 0.0 || g(1) != 0.0 || g(2) != 0.0) {  // - I [g; 0] = -[m g; h x g]
    f(0) -= m * g(0);
    f(1) -= m * g(1);
    f(2) -= m * g(2);
    f(3) -= h1 * g(2) - h2 * g(1);
    f(4) -= h2 * g(0) - h0 * g(2);
    f(5) -= h0 * g(1) - h1 * g(0);
  }
}

/// c = V x (S qd) for the motion V = [v; w] and the joint motion S qd = [s_l; s_a] qd (RBDA 2.31):
/// [w x s_l + v x s_a; w x s_a] qd, written out.
inline void velocity_product(const Vector6& V, const double* S, double qd, Vector6& c) {
  const double v0 = V(0), v1 = V(1), v2 = V(2), w0 = V(3), w1 = V(4), w2 = V(5);
  const double l0 = S[0] * qd, l1 = S[1] * qd, l2 = S[2] * qd, a0 = S[3] * qd, a1 = S[4] * qd, a2 = S[5] * qd;
  c(0) = (w1 * l2 - w2 * l1) + (v1 * a2 - v2 * a1);
  c(1) = (w2 * l0 - w0 * l2) + (v2 * a0 - v0 * a2);
  c(2) = (w0 * l1 - w1 * l0) + (v0 * a1 - v1 * a0);
  c(3) = w1 * a2 - w2 * a1;
  c(4) = w2 * a0 - w0 * a2;
  c(5) = w0 * a1 - w1 * a0;
}

inline double dot6(const double* a, const double* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}

/// The part of the articulated-body algorithm that does not depend on the generalized forces
/// (RBDA 7.3 with the floating base of RBDA 9.4), in inertial axes about the base frame origin p_0,
/// as crba and the O(n) effective mass work, so that no transform is needed anywhere: the spatial
/// quantities of every body are expressed in one frame (fixed in o, momentarily at p_0 with o's axes).
/// With V_0 = [v_0; w_0] (the generalized base velocity: the velocity of the base-fixed point at p_0
/// and the angular velocity) and I_i body i's inertia (detail::body_inertias),
///   i = 1..:   V_i = V_parent + S_i qd_i,
///   every i:   F_i = V_i x* (I_i V_i) - I_i a_g     (velocity product and weight, a_g = [g; 0]),
///   i = n..1:  U_i = IA_i S_i,  D_i = S_i^T U_i,  IA_parent += IA_i - U_i U_i^T / D_i,
/// with IA_i starting as I_i (the recursion of detail::articulated_inertias, without the armature and
/// the composite inertias). Requires one body per coordinate (no mimic joint).
/// Reads base, theta, v. Writes the kinematics (forward_kinematics), data.Ic (the bodies alone),
/// data.V, data.F, data.IA, data.U, data.D. Throws NumericalError when a D_i is not positive.
inline void aba_velocity_pass(const Model& model, Data& data, const BasePose& base,
                              const Eigen::Ref<const Eigen::VectorXd>& theta,
                              const Eigen::Ref<const Eigen::VectorXd>& v) {
  forward_kinematics(model, data, base, theta);
  body_inertias(model, data);
  const int nb = model.nb();
  for (int k = 0; k < 6; ++k) data.V[0](k) = v(k);
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    Vector6& Vi = data.V[ui];
    if (i > 0) {
      const Vector6& Vp = data.V[static_cast<size_t>(model.body(i).parent)];
      const double* S = data.S.col(i - 1).data();
      const double qd = v(6 + model.body(i).coord);
      for (int k = 0; k < 6; ++k) Vi(k) = Vp(k) + S[k] * qd;
    }
    const SpatialInertia& I = data.Ic[ui];
    rigid_bias_force(I, Vi, model.gravity, data.F[ui]);
    data.IA[ui].set(I);
  }
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i);
    const Vector6 S = data.S.col(i - 1);
    const Vector6 U = data.IA[ui] * S;
    const double D = dot6(S.data(), U.data());
    if (!(D > 0.0))
      FFSR_THROW(NumericalError(str("aba: the articulated inertia is not positive definite (joint ", i, ")")));
    data.U[ui] = U;
    data.D(i - 1) = D;
    data.IA[static_cast<size_t>(model.body(i).parent)].add_projected(data.IA[ui], U, D);
  }
}

/// The rest of the articulated-body algorithm for the generalized forces tau, after
/// aba_velocity_pass at the same state (which it does not change, so it can be called again with
/// other forces): with c_i = V_i x (S_i qd_i) the velocity-product acceleration of joint i and pA_i
/// starting as F_i,
///   i = n..1:  u_i = tau_i - S_i^T pA_i,  pA_parent += pA_i + IA_i c_i + U_i (u_i - U_i^T c_i) / D_i,
///   base:      A_0 = IA_0^-1 (tau_b - pA_0)   (tau_b the base wrench about p_0, inertial axes),
///   i = 1..:   qdd_i = (u_i - U_i^T (A_parent + c_i)) / D_i,  A_i = A_parent + c_i + S_i qdd_i.
/// A_0 is the spatial acceleration of the base; the generalized one has the classical acceleration of
/// the base origin, A_0's linear part + w_0 x v_0 (rnea uses the same relation the other way).
/// Reads v, tau, data.V, data.F, data.IA, data.U, data.D, data.S. Writes data.pA, data.A, data.u
/// and a (size 6+n). Throws NumericalError when IA_0 is not positive definite.
inline void aba_acceleration_pass(const Model& model, Data& data, const Eigen::Ref<const Eigen::VectorXd>& v,
                                  const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> a) {
  const int nb = model.nb();
  for (int i = 0; i < nb; ++i) data.pA[static_cast<size_t>(i)] = data.F[static_cast<size_t>(i)];
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i);
    const int k = model.body(i).coord;
    const double* S = data.S.col(i - 1).data();
    Vector6& c = data.A[ui];  // kept for the forward pass
    velocity_product(data.V[ui], S, v(6 + k), c);
    const Vector6& U = data.U[ui];
    Vector6& pA = data.pA[ui];
    const double u = tau(6 + k) - dot6(S, pA.data());
    data.u(i - 1) = u;
    const Vector6 Ic = data.IA[ui] * c;
    const double s = (u - dot6(U.data(), c.data())) / data.D(i - 1);
    Vector6& pp = data.pA[static_cast<size_t>(model.body(i).parent)];
    for (int j = 0; j < 6; ++j) pp(j) += pA(j) + Ic(j) + U(j) * s;
  }
  Vector6 rhs;
  for (int j = 0; j < 6; ++j) rhs(j) = tau(j) - data.pA[0](j);
  if (!solve_spd6(data.IA[0].matrix(), rhs, data.A[0]))
    FFSR_THROW(NumericalError("aba: the articulated inertia of the base is not positive definite"));
  for (int i = 1; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Vector6& Ap = data.A[static_cast<size_t>(model.body(i).parent)];
    Vector6& Ai = data.A[ui];  // c_i on entry
    for (int j = 0; j < 6; ++j) Ai(j) += Ap(j);
    const double qdd = (data.u(i - 1) - dot6(data.U[ui].data(), Ai.data())) / data.D(i - 1);
    const double* S = data.S.col(i - 1).data();
    for (int j = 0; j < 6; ++j) Ai(j) += S[j] * qdd;
    a(6 + model.body(i).coord) = qdd;
  }
  const Vector6& A0 = data.A[0];
  const double v0 = v(0), v1 = v(1), v2 = v(2), w0 = v(3), w1 = v(4), w2 = v(5);
  a(0) = A0(0) + (w1 * v2 - w2 * v1);  // the classical acceleration of the base origin: + w_0 x v_0
  a(1) = A0(1) + (w2 * v0 - w0 * v2);
  a(2) = A0(2) + (w0 * v1 - w1 * v0);
  a(3) = A0(3);
  a(4) = A0(4);
  a(5) = A0(5);
}

}  // namespace detail

/// Forward dynamics a = H^-1 (tau - C(q, v)) of Eq. 1 in O(n) by the articulated-body algorithm
/// (RBDA 7.3, floating base RBDA 9.4), without forming H: the same accelerations as
/// forward_dynamics (CRBA, RNEA bias, Cholesky) to rounding. tau holds the generalized forces (base
/// wrench at the base origin in o, then joint torques); gravity is the model's. The two halves,
/// detail::aba_velocity_pass (kinematics, velocities, articulated inertias: everything tau does
/// not change) and detail::aba_acceleration_pass (the forces), can be called apart, the second one
/// several times for other forces at the same state. Cost per body: one symmetric rank-one update of
/// a 6x6 articulated inertia, a few 6-vector products; one 6x6 Cholesky at the base; no allocation.
/// Reads base, theta, v, tau. Writes the kinematics, data.Ic (bodies alone), data.V, data.F,
/// data.IA, data.U, data.D, data.pA, data.A, data.u and a (resized to 6+n). Throws InputError for
/// bad sizes, non-finite values or a model with mimic joints (use forward_dynamics), NumericalError
/// when the articulated inertias are not positive definite or the accelerations overflow.
inline void aba(const Model& model, Data& data, const BasePose& base, const Eigen::Ref<const Eigen::VectorXd>& theta,
                const Eigen::Ref<const Eigen::VectorXd>& v, const Eigen::Ref<const Eigen::VectorXd>& tau,
                Eigen::VectorXd& a) {
  if (model.nb() - 1 != model.n())
    FFSR_THROW(InputError("aba: the model has mimic joints; use forward_dynamics"));
  detail::require_size(v.size(), model.nv(), "aba", "v");
  detail::require_size(tau.size(), model.nv(), "aba", "tau");
  detail::require_finite_all(v, "aba", "v");
  detail::require_finite_all(tau, "aba", "tau");
  a.resize(model.nv());
  detail::aba_velocity_pass(model, data, base, theta, v);
  detail::aba_acceleration_pass(model, data, v, tau, a);
  if (!a.allFinite()) FFSR_THROW(NumericalError("aba: the accelerations overflow double precision"));
}

}  // namespace ffsr
