// ffsr/algorithm/articulated_effective_mass.hpp -- u^T J_v H^-1 J_v^T u in O(n) by articulated-body
// inertias, without forming H.
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"

namespace ffsr {
namespace detail {

/// Solves A x = b for a symmetric positive definite 6x6 A by Cholesky with fixed loop bounds (the
/// compiler unrolls it; Eigen's LLT<Matrix6> runs its generic loops: 6 % of the recursion's time at 14 joints).
/// Reads the lower triangle. False when A is not positive definite (x is then unspecified).
inline bool solve_spd6(const Matrix6& A, const Vector6& b, Vector6& x) {
  double L[6][6];
  for (int j = 0; j < 6; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0.0)) return false;
    const double ljj = std::sqrt(d), inv = 1.0 / ljj;
    L[j][j] = ljj;
    for (int i = j + 1; i < 6; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
      L[i][j] = s * inv;
    }
  }
  for (int i = 0; i < 6; ++i) {  // L z = b
    double s = b(i);
    for (int k = 0; k < i; ++k) s -= L[i][k] * x(k);
    x(i) = s / L[i][i];
  }
  for (int i = 5; i >= 0; --i) {  // L^T x = z
    double s = x(i);
    for (int k = i + 1; k < 6; ++k) s -= L[k][i] * x(k);
    x(i) = s / L[i][i];
  }
  return true;
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
/// finds the body accelerations it causes, and the result is f^T a_e (a_e the spatial acceleration
/// of that body). All quantities are in inertial axes about the base origin p_0, as in crba, so the
/// motion subspaces are data.S and inertias add without transforms:
///   backward, i = n..1:  U_i = IA_i S_i, D_i = S_i^T U_i, u_i = -S_i^T pA_i,
///                        IA_par += IA_i - U_i U_i^T / D_i, pA_par += pA_i + U_i u_i / D_i;
///   base:                a_0 = -IA_0^-1 pA_0;
///   forward, along the path from the base to the frame's body:
///                        a_i = a_par + S_i (u_i - U_i^T a_par) / D_i,
/// with IA_i the body inertias and pA = -f on the frame's body only. Cost: one 6x6 rank-one update
/// per body, one 6x6 Cholesky, no n x n matrix; it beats crba + dense Cholesky (O(n^2) + O(n^3))
/// from about kArticulatedMinJoints joints on (see integrated_effective_mass_fast).
/// Reads the kinematics (data.R, data.p, data.S). Writes data.IA, data.pA, data.U, data.D, data.u,
/// data.A. Allocation-free. Throws NumericalError when an articulated inertia is not positive definite.
inline double inverse_effective_mass_articulated(const Model& model, Data& data, int frame,
                                                 const Vector3& u) {
  detail::check_unit_direction(u, "effective_mass");
  if (frame < 0 || frame >= static_cast<int>(model.frames().size()))
    throw InputError(detail::str("effective_mass: frame index ", frame, " out of range"));
  const Vector3 pe = frame_pose(model, data, frame).p;
  if (!pe.allFinite())
    throw NumericalError(detail::str("effective_mass: the position of frame '", model.frame(frame).name,
                                     "' overflows double precision"));
  const int nb = model.nb();
  if (nb - 1 != model.n())  // a mimic joint couples bodies through one coordinate: not a tree recursion
    throw InputError(
        "inverse_effective_mass_articulated: the model has mimic joints; use inverse_effective_mass");
  const int ee = model.frame(frame).body;
  const Vector3& p0 = data.p[0];
  Vector6 f;
  f << u, (pe - p0).cross(u);
  for (int i = 0; i < nb; ++i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    const Matrix3& Ri = data.R[ui];
    data.IA[ui] =
        SpatialInertia::from_com(in.mass, data.p[ui] + Ri * in.com - p0, Ri * in.I * Ri.transpose()).matrix();
    data.pA[ui].setZero();
  }
  data.pA[static_cast<size_t>(ee)] = -f;
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i);
    const auto up = static_cast<size_t>(model.body(i).parent);
    const Vector6 S = data.S.col(i - 1);
    Vector6& U = data.U[ui];
    U.noalias() = data.IA[ui] * S;
    const double D = S.dot(U);
    if (!(D > 0.0))
      throw NumericalError(
          detail::str("effective_mass: the articulated inertia is not positive definite (joint ", i, ")"));
    data.D(i - 1) = D;
    const double ui_ = -S.dot(data.pA[ui]);
    data.u(i - 1) = ui_;
    data.IA[up].noalias() += data.IA[ui] - U * (U.transpose() / D);
    data.pA[up].noalias() += data.pA[ui] + U * (ui_ / D);
  }
  if (!detail::solve_spd6(data.IA[0], -data.pA[0], data.A[0]))
    throw NumericalError("effective_mass: the articulated inertia of the base is not positive definite");
  // forward pass along the path base -> ee only (the other bodies do not change f^T a_e): collect the
  // path in data.path from the leaf, then walk it from the base
  int len = 0;
  for (int i = ee; i > 0; i = model.body(i).parent) data.path[static_cast<size_t>(len++)] = i;
  for (int k = len - 1; k >= 0; --k) {
    const int i = data.path[static_cast<size_t>(k)];
    const auto ui = static_cast<size_t>(i);
    const Vector6& ap = data.A[static_cast<size_t>(model.body(i).parent)];
    const double qdd = (data.u(i - 1) - data.U[ui].dot(ap)) / data.D(i - 1);
    data.A[ui] = ap + data.S.col(i - 1) * qdd;
  }
  return f.dot(data.A[static_cast<size_t>(ee)]);
}

/// From this many joints on, integrated_effective_mass_fast uses the articulated-body recursion;
/// below, crba and the dense Cholesky solve are faster (measured with ffsr-bench; see the README).
inline constexpr int kArticulatedMinJoints = 8;

/// Integrated effective mass (Eq. 14) as integrated_effective_mass, by the faster of the two paths
/// for the model's size: crba + dense Cholesky below kArticulatedMinJoints joints, the O(n)
/// articulated-body recursion (inverse_effective_mass_articulated) from there on. The two agree to
/// rounding (tested to 1e-10 relative). Writes the kinematics and either data.H, data.L, data.w,
/// data.y (dense) or the articulated-body fields: do not rely on data.H afterwards.
inline double integrated_effective_mass_fast(const Model& model, Data& data, const BasePose& base,
                                             const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                             const Vector3& u, double target_inverse_mass) {
  if (model.n() < kArticulatedMinJoints || model.nb() - 1 != model.n()) {  // small, or mimic joints: dense
    crba(model, data, base, theta);
    return 1.0 / (inverse_effective_mass(model, data, frame, u) + target_inverse_mass);
  }
  forward_kinematics(model, data, base, theta);
  return 1.0 / (inverse_effective_mass_articulated(model, data, frame, u) + target_inverse_mass);
}

}  // namespace ffsr
