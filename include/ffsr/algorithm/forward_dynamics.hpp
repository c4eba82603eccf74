// ffsr/algorithm/forward_dynamics.hpp -- generalized accelerations of the free-floating tree.
#pragma once

#include "ffsr/algorithm/crba.hpp"
#include "ffsr/algorithm/rnea.hpp"

namespace ffsr {

/// Forward dynamics a = H^-1 (tau - C(q, v)) of Eq. 1 (RBDA 6.1: CRBA, RNEA bias, Cholesky).
/// tau holds the generalized forces (base wrench at the base origin in o, then joint torques), for
/// instance J_bm^T F_e for an external wrench F_e at a frame.
/// Reads base, theta, v, tau. Writes what crba and rnea write, data.L, and a. Throws NumericalError
/// if H is not positive definite or the accelerations overflow double precision.
inline void forward_dynamics(const Model& model, Data& data, const BasePose& base,
                             const Eigen::Ref<const Eigen::VectorXd>& theta,
                             const Eigen::Ref<const Eigen::VectorXd>& v,
                             const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::VectorXd& a) {
  detail::require_size(tau.size(), model.nv(), "forward_dynamics", "tau");
  detail::require_finite_all(tau, "forward_dynamics", "tau");
  crba(model, data, base, theta);
  a = tau - bias_forces(model, data, base, theta, v);
  detail::cholesky(data.H, data.L, "forward_dynamics");
  detail::cholesky_solve(data.L, a);
  if (!a.allFinite()) throw NumericalError("forward_dynamics: the accelerations overflow double precision");
}

}  // namespace ffsr
