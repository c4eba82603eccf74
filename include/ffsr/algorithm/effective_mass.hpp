// ffsr/algorithm/effective_mass.hpp -- effective mass m_e (Eq. 4) and integrated effective mass M_ie (Eq. 14).
#pragma once

#include "ffsr/algorithm/crba.hpp"
#include "ffsr/model/target.hpp"

#include <algorithm>

namespace ffsr {
namespace detail {

/// w = J^T [f; m] for the origin of `frame` (J the 6x(6+n) point Jacobian, linear rows first): the
/// generalized force that a force f at the point and a couple m produce. A unit force u at the point
/// p_e + rho is the pair (u, rho x u). Reads the kinematics. Writes data.w.
inline void jacobian_transpose_times(const Model& model, Data& data, int frame, const Vector3& f,
                                     const Vector3& m) {
  const Vector3 pe = frame_pose(model, data, frame).p;
  if (!pe.allFinite())
    throw NumericalError(str("effective_mass: the position of frame '", model.frame(frame).name,
                             "' overflows double precision"));
  data.w.setZero();
  data.w.head<3>() = f;
  data.w.segment<3>(3) = (pe - data.p[0]).cross(f) + m;
  for (int i = model.frame(frame).body; i > 0; i = model.body(i).parent) {
    const auto S = data.S.col(i - 1);
    data.w(6 + model.body(i).coord) +=
        model.body(i).joint.type == JointType::Revolute
            ? S.tail<3>().dot((pe - data.p[static_cast<size_t>(i)]).cross(f)) + S.tail<3>().dot(m)
            : S.head<3>().dot(f);
  }
}

/// w = J_v^T u for the origin of `frame`: the generalized force that a unit force along u at the
/// point produces. Reads the kinematics. Writes data.w.
inline void linear_jacobian_transpose_times(const Model& model, Data& data, int frame, const Vector3& u) {
  jacobian_transpose_times(model, data, frame, u, Vector3::Zero());
}

inline void check_frame(const Model& model, int frame, const char* where) {
  if (frame < 0 || frame >= static_cast<int>(model.frames().size()))
    throw InputError(str(where, ": frame index ", frame, " out of range"));
}

inline void check_unit_direction(const Vector3& u, const char* where) {
  require_finite_all(u, where, "direction u");
  if (std::abs(u.norm() - 1.0) > 1e-9)
    throw InputError(str(where, ": direction u must be a unit vector, |u| = ", u.norm()));
}

}  // namespace detail

/// Inverse effective mass u^T J_v H^-1 J_v^T u (the denominator of Eq. 4) at the configuration of
/// the last crba, computed as |L^-1 w|^2 with H = L L^T and w = J_v^T u (one forward substitution).
/// Reads data.H and the kinematics. Writes data.L, data.w and data.y (= L^-1 w).
inline double inverse_effective_mass(const Model& model, Data& data, int frame, const Vector3& u) {
  detail::check_unit_direction(u, "effective_mass");
  detail::check_frame(model, frame, "effective_mass");
  detail::linear_jacobian_transpose_times(model, data, frame, u);
  detail::cholesky(data.H, data.L, "effective_mass");
  data.y = data.w;
  detail::cholesky_forward(data.L, data.y);
  return data.y.squaredNorm();
}

/// The robot's 6x6 inverse inertia at the origin of `frame`, Lambda^-1 = J H^-1 J^T (J the point
/// Jacobian of frame_jacobian, linear rows first, for the free-floating system: the base moves under
/// momentum conservation). For a unit force u at the point p_e + rho (rho in the inertial frame),
/// the robot's inverse effective mass is s^T Lambda^-1 s with s = [u; rho x u]; its top-left 3x3
/// block is G = J_v H^-1 J_v^T. Computed as Y^T Y with Y = L^-1 J^T (six forward substitutions),
/// symmetrized.
/// Reads data.H (crba) and the kinematics. Writes data.L, data.w and data.y.
inline Matrix6 inverse_inertia_matrix(const Model& model, Data& data, int frame) {
  detail::check_frame(model, frame, "inverse_inertia_matrix");
  detail::cholesky(data.H, data.L, "inverse_inertia_matrix");
  Eigen::Matrix<double, Eigen::Dynamic, 6> Y(data.H.rows(), 6);
  for (int k = 0; k < 6; ++k) {
    Vector6 e = Vector6::Unit(k);
    detail::jacobian_transpose_times(model, data, frame, e.head<3>(), e.tail<3>());
    data.y = data.w;
    detail::cholesky_forward(data.L, data.y);
    Y.col(k) = data.y;
  }
  const Matrix6 L = Y.transpose() * Y;
  return 0.5 * (L + L.transpose());  // exactly symmetric (the product's rounding is not)
}

/// Effective mass m_e = 1 / (u^T (J_v H^-1 J_v^T) u) of the free-floating robot at the origin of
/// `frame` along the unit inertial direction u (Eq. 4). Runs crba.
inline double effective_mass(const Model& model, Data& data, const BasePose& base,
                             const Eigen::Ref<const Eigen::VectorXd>& theta, int frame, const Vector3& u) {
  crba(model, data, base, theta);
  return 1.0 / inverse_effective_mass(model, data, frame, u);
}

/// Integrated effective mass (Eq. 14) from the robot's effective mass along u = R_t u_n:
/// M_ie = 1 / (1/m_e + 1/m_t + (r x u)^T I^-1 (r x u)), r = R_t r_tp, I = R_t I_t R_t^T.
inline double integrated_effective_mass(double m_e, const Target& target) {
  if (!(m_e > 0) || !std::isfinite(m_e))
    throw InputError(detail::str("integrated_effective_mass: m_e must be positive and finite, got ", m_e));
  return 1.0 / (1.0 / m_e + target.inverse_mass_along_normal());
}

/// Integrated effective mass (Eq. 14) of the robot at (base, theta) with the end-effector `frame`
/// touching `target` (its attitude gives u = R_t u_n). Runs crba. Does not validate the target on
/// every call: validate it once (Target::validate) when it is made.
inline double integrated_effective_mass(const Model& model, Data& data, const BasePose& base,
                                        const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                        const Target& target) {
  crba(model, data, base, theta);
  const double inv_me = inverse_effective_mass(model, data, frame, target.normal_world());
  return 1.0 / (inv_me + target.inverse_mass_along_normal());
}

}  // namespace ffsr

namespace ffsr {

namespace detail {
inline double inverse_inertia_form_gradient_factored(const Model& model, Data& data, int frame,
                                                     const Vector6& s, Eigen::Ref<Eigen::VectorXd> grad);
}  // namespace detail

/// Analytic gradient in the joint angles of the quadratic form q = s^T Lambda^-1 s of the robot's
/// inverse inertia at the origin of `frame` (inverse_inertia_matrix) for a constant s = [f; m] in the
/// inertial frame, at a fixed base pose. With w = J^T s, y = H^-1 w and q = w^T y:
///   dq/dtheta_k = 2 s . d(J y)/dtheta_k - y^T (dH/dtheta_k) y,
/// where y^T (dH/dtheta_k) y = 2 (V_k x S_k) . h_k (V_k the spatial velocity of body k and h_k the
/// spatial momentum of the subtree of k, both for the velocity y), and d(J y)/dtheta_k -- the change
/// of the end-effector's linear velocity at its origin and of its angular velocity -- follows from
/// moving the subtree of k by the twist S_k. O(n) after the Cholesky factorization. For s = [u; 0]
/// q is the inverse effective mass of Eq. 4; for s = [u; rho x u], that at the point p_e + rho
/// (rho held fixed in the inertial frame). Reads data.H (crba) and the kinematics. Writes data.L,
/// data.w, data.y, data.V, data.F, data.on_path and `grad` (size n). Returns q.
inline double inverse_inertia_form_gradient(const Model& model, Data& data, int frame, const Vector6& s,
                                            Eigen::Ref<Eigen::VectorXd> grad) {
  detail::require_size(grad.size(), model.n(), "inverse_inertia_form_gradient", "grad");
  detail::check_frame(model, frame, "inverse_inertia_form_gradient");
  detail::require_finite_all(s, "inverse_inertia_form_gradient", "s");
  detail::cholesky(data.H, data.L, "inverse_inertia_form_gradient");
  return detail::inverse_inertia_form_gradient_factored(model, data, frame, s, grad);
}

namespace detail {
/// Marks the bodies on the path from `body` to the base (the base included) in data.on_path.
inline void mark_path(const Model& model, Data& data, int body) {
  std::fill(data.on_path.begin(), data.on_path.end(), char(0));
  for (int i = body; i >= 0; i = model.body(i).parent) data.on_path[static_cast<size_t>(i)] = 1;
}

/// The gradient part of inverse_inertia_form_gradient for s = [u; mc], given y = H^-1 w in data.y
/// (whichever way it was solved): the velocities V_i and subtree momenta F_i of the bodies for the
/// generalized velocity y, then per joint k: 2 s . d(J y)/dtheta_k - 2 (V_k x S_k) . F_k. O(n).
/// Reads data.y and the kinematics. Writes data.V, data.F, data.on_path and grad (size n).
inline void inverse_inertia_form_gradient_from_y(const Model& model, Data& data, int frame, const Vector3& u,
                                                 const Vector3& mc, Eigen::Ref<Eigen::VectorXd> grad) {
  const int nb = model.nb();
  const Vector3& p0 = data.p[0];
  // velocities and momenta of the bodies for the generalized velocity y
  data.V[0] = data.y.head<6>();
  for (int i = 1; i < nb; ++i)
    data.V[static_cast<size_t>(i)] = data.V[static_cast<size_t>(model.body(i).parent)] +
                                     data.S.col(i - 1) * data.y(6 + model.body(i).coord);
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    data.F[ui] = SpatialInertia::from_body(in.mass, in.com, in.I, data.R[ui], data.p[ui] - p0) * data.V[ui];
  }
  for (int i = nb - 1; i > 0; --i)
    data.F[static_cast<size_t>(model.body(i).parent)] += data.F[static_cast<size_t>(i)];
  const int ee_body = model.frame(frame).body;
  mark_path(model, data, ee_body);
  const Vector3 pe = frame_pose(model, data, frame).p;
  const Vector6& Vee = data.V[static_cast<size_t>(ee_body)];
  grad.setZero();
  for (int i = 1; i < nb; ++i) {  // body i adds its part to the gradient entry of its coordinate
    const auto ui = static_cast<size_t>(i);
    const Vector6 S = data.S.col(i - 1);
    const double yHy = 2.0 * cross_motion(data.V[ui], S).dot(data.F[ui]);
    double sdv = 0.0;
    if (data.on_path[ui]) {  // joint i carries the end-effector
      const Vector6 X = cross_motion(S, Vee - data.V[ui]);  // d(V_ee)/dtheta_k, referred to p0
      const Vector3 dp = S.head<3>() + S.tail<3>().cross(pe - p0);
      sdv = u.dot(X.head<3>() + X.tail<3>().cross(pe - p0) + Vee.tail<3>().cross(dp)) + mc.dot(X.tail<3>());
    }
    grad(model.body(i).coord) += 2.0 * sdv - yHy;
  }
}

/// inverse_inertia_form_gradient with data.L already the Cholesky factor of data.H (callers that
/// evaluate several forms at one configuration factorize once). No argument checks.
inline double inverse_inertia_form_gradient_factored(const Model& model, Data& data, int frame,
                                                     const Vector6& s, Eigen::Ref<Eigen::VectorXd> grad) {
  const Vector3 u = s.head<3>(), mc = s.tail<3>();
  detail::jacobian_transpose_times(model, data, frame, u, mc);
  data.y = data.w;
  detail::cholesky_forward(data.L, data.y);
  const double q = data.y.squaredNorm();
  detail::cholesky_backward(data.L, data.y);  // y = H^-1 w
  inverse_inertia_form_gradient_from_y(model, data, frame, u, mc, grad);
  return q;
}
}  // namespace detail

/// Analytic gradient of the integrated effective mass with respect to the joint angles, at a fixed
/// base pose and for a fixed inertial contact direction u and target inverse mass along the normal
/// (Target::inverse_mass_along_normal): with 1/m_e = q(u) of inverse_inertia_form_gradient for
/// s = [u; 0], dM_ie = -M_ie^2 d(1/m_e). Runs crba. Writes data.H, data.L, data.w, data.y, data.V,
/// data.F and `grad` (size n). Returns M_ie.
inline double integrated_effective_mass_gradient(const Model& model, Data& data, const BasePose& base,
                                                 const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                                 const Vector3& u, double target_inverse_mass,
                                                 Eigen::Ref<Eigen::VectorXd> grad) {
  detail::require_size(grad.size(), model.n(), "integrated_effective_mass_gradient", "grad");
  detail::check_unit_direction(u, "effective_mass");
  crba(model, data, base, theta);
  Vector6 s;
  s << u, Vector3::Zero();
  const double inv_me = inverse_inertia_form_gradient(model, data, frame, s, grad);
  const double M = 1.0 / (inv_me + target_inverse_mass);
  grad *= -M * M;
  return M;
}

}  // namespace ffsr
