// ffsr/algorithm/momentum.hpp -- momentum, kinetic energy and base motion from momentum conservation.
#pragma once

#include "ffsr/algorithm/crba.hpp"

#include <array>
#include <vector>

namespace ffsr {

/// Velocity of every body (angular velocity and the velocity of its centre of mass, inertial
/// frame) by a forward pass over the tree. Reads the kinematics (forward_kinematics) and v.
/// Calls `visit(i, w_i, vc_i, c_i)` for each body, c_i the centre of mass in o. Does not allocate for
/// trees of up to 64 bodies (the velocities are kept on the stack; a larger tree takes one vector).
template <class Visit>
void for_each_body_velocity(const Model& model, const Data& data, const Eigen::Ref<const Eigen::VectorXd>& v,
                            Visit&& visit) {
  detail::require_size(v.size(), model.nv(), "body velocities", "v");
  const int nb = model.nb();
  // w_i and the velocity of the body point at the base origin, u_i (a spatial velocity about p0)
  constexpr int kOnStack = 64;
  std::array<Vector6, kOnStack> on_stack;
  std::vector<Vector6> on_heap;
  Vector6* Vs = on_stack.data();
  if (nb > kOnStack) {
    on_heap.resize(static_cast<size_t>(nb));
    Vs = on_heap.data();
  }
  Vs[0] = v.head<6>();
  for (int i = 1; i < nb; ++i)
    Vs[static_cast<size_t>(i)] =
        Vs[static_cast<size_t>(model.body(i).parent)] + data.S.col(i - 1) * v(6 + model.body(i).coord);
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Vector3 c = data.p[ui] + data.R[ui] * model.body(i).inertia.com;
    const Vector3 w = Vs[ui].tail<3>();
    const Vector3 vc = Vs[ui].head<3>() + w.cross(c - data.p[0]);
    visit(i, w, vc, c);
  }
}

/// Total momentum [P; L] of the system: linear momentum and angular momentum about the base frame
/// origin, inertial frame, summed body by body. Equals the first six rows of H v.
/// Reads the kinematics (forward_kinematics) and v. NumericalError when a finite v overflows it.
inline Vector6 momentum(const Model& model, const Data& data, const Eigen::Ref<const Eigen::VectorXd>& v) {
  Vector6 h = Vector6::Zero();
  for_each_body_velocity(model, data, v, [&](int i, const Vector3& w, const Vector3& vc, const Vector3& c) {
    const Inertia& in = model.body(i).inertia;
    const Matrix3& R = data.R[static_cast<size_t>(i)];
    h.head<3>() += in.mass * vc;
    h.tail<3>() += (c - data.p[0]).cross(in.mass * vc) + R * in.I * R.transpose() * w;
  });
  if (!h.allFinite() && v.allFinite())  // NaN in v propagates; finite v whose products overflow do not
    FFSR_THROW(NumericalError("momentum: the momentum overflows double precision"));
  return h;
}

/// The system's momentum about its centre of mass (inertial frame): the centre of mass c, the linear
/// momentum P = M v_c and the angular momentum about c,
///   L_c = sum_i R_i I_i R_i^T w_i + m_i (c_i - c) x (v_i - v_c),
/// which is conserved, as P is, when no external force acts. M is the total mass.
struct CentroidalMomentum {
  double mass = 0;
  Vector3 com = Vector3::Zero();      ///< c
  Vector3 linear = Vector3::Zero();   ///< P = M v_c
  Vector3 angular = Vector3::Zero();  ///< L_c, about c
};

/// The centroidal momentum from the base rows of H: [P; L_0] = H(0:6, :) v, the momentum about the
/// base frame origin p_0 (momentum()), M = H(0, 0), c - p_0 from the block M [c - p_0]x = H(3:6, 0:3),
/// and L_c = L_0 - (c - p_0) x P. Reads data.H (crba) and data.p[0]; no allocation. InputError for
/// a v of the wrong size.
inline CentroidalMomentum centroidal_momentum(const Model& model, const Data& data,
                                              const Eigen::Ref<const Eigen::VectorXd>& v) {
  detail::require_size(v.size(), model.nv(), "centroidal_momentum", "v");
  const Eigen::MatrixXd& H = data.H;
  Vector6 h;
  for (int k = 0; k < 6; ++k) h(k) = H.row(k).dot(v);
  CentroidalMomentum c;
  c.mass = H(0, 0);
  const Vector3 r(H(5, 1) / c.mass, H(3, 2) / c.mass, H(4, 0) / c.mass);  // c - p_0
  c.com = data.p[0] + r;
  c.linear = h.head<3>();
  c.angular = h.tail<3>() - r.cross(c.linear);
  return c;
}

namespace detail {

/// Total momentum [P; L] about the base frame origin (inertial axes) from what the articulated-body
/// algorithm's velocity pass left: the sum over the bodies of I_i V_i, both about p_0 in inertial axes.
/// Equals momentum() at the same state to rounding, without the kinematics again. Reads data.Ic (the
/// bodies alone, as detail::aba_velocity_pass writes it) and data.V.
inline Vector6 momentum_from_velocity_pass(const Model& model, const Data& data) {
  Vector6 h = Vector6::Zero();
  for (int i = 0; i < model.nb(); ++i) h += data.Ic[static_cast<size_t>(i)] * data.V[static_cast<size_t>(i)];
  return h;
}

}  // namespace detail

/// Kinetic energy, summed body by body: sum of 1/2 m |v_c|^2 + 1/2 w^T I w.
/// Reads the kinematics (forward_kinematics) and v. NumericalError when a finite v overflows it.
inline double kinetic_energy(const Model& model, const Data& data,
                             const Eigen::Ref<const Eigen::VectorXd>& v) {
  double T = 0;
  for_each_body_velocity(model, data, v, [&](int i, const Vector3& w, const Vector3& vc, const Vector3&) {
    const Inertia& in = model.body(i).inertia;
    const Matrix3& R = data.R[static_cast<size_t>(i)];
    T += 0.5 * in.mass * vc.squaredNorm() + 0.5 * w.dot(R * in.I * R.transpose() * w);
  });
  if (!std::isfinite(T) && v.allFinite())
    FFSR_THROW(NumericalError("kinetic_energy: the energy overflows double precision"));
  return T;
}

/// Base velocity [v0; w0] from momentum conservation: H_b x_b_dot + H_bm theta_dot = h, with h the
/// total momentum [P; L about the base frame origin] (zero by default).
/// Reads data.H (crba) and theta_dot. NumericalError when the finite inputs overflow it.
inline Vector6 base_velocity_from_momentum(const Model& model, const Data& data,
                                           const Eigen::Ref<const Eigen::VectorXd>& theta_dot,
                                           const Vector6& h = Vector6::Zero()) {
  detail::require_size(theta_dot.size(), model.n(), "base_velocity_from_momentum", "theta_dot");
  detail::require_finite_all(theta_dot, "base_velocity_from_momentum", "theta_dot");
  detail::require_finite_all(h, "base_velocity_from_momentum", "momentum");
  const Eigen::LLT<Matrix6> Hb(data.H.topLeftCorner<6, 6>());
  if (Hb.info() != Eigen::Success) FFSR_THROW(NumericalError("base_velocity_from_momentum: H_b is singular"));
  Vector6 xb = Hb.solve(h - data.H.topRightCorner(6, model.n()) * theta_dot);
  if (!xb.allFinite())
    FFSR_THROW(NumericalError("base_velocity_from_momentum: the base velocity overflows double precision"));
  return xb;
}

}  // namespace ffsr
