// ffsr/optimize/base_attitude.hpp -- the reaction-null-space approach (Yoshida and Nenchev): the
// capture approach that keeps the base's angular velocity zero.
#pragma once

#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/errors.hpp"

#include <Eigen/SVD>

// Under zero total momentum the base velocity is a linear function of the joint rates,
// [v_0; w_0] = -H_b^-1 H_bm theta_dot (Eq. 2), so w_0 = -A theta_dot with A the three angular rows of
// H_b^-1 H_bm (data.HbInv_Hbm of generalized_jacobian). Holding the base attitude keeps Q^T A theta_dot
// = 0 with priority over the task (TaskSolver's extra rows): theta_dot = (J_t N_A)^+ (x_d_dot + k_p e)
// with N_A the projector on the null space of Q^T A, so w_0 = 0 at every evaluation (the attitude
// change over the run is integration error) also where J_t N_A is damped near an algorithmic
// singularity (the task then lags and the feedback catches up); the objective's gradient moves the
// arm in what null space is left. Q (3 x r) is a basis of the base angular velocities the arm can
// cause at the initial state (the range of A), scaled so that the held rows have unit singular
// values there: r = 3 for a spatial arm, r = 1 for a planar one (the normal of its plane).
//
// Freedom: the task's m rows plus the r attitude rows must leave at least one joint for the
// objective (m + r < n; m + r <= n for pure tracking, gain 0). The 7-DOF arm on a position task has
// 3 + 3 = 6 < 7; the planar 3-DOF arm has 2 + 1 = 3 = n: no freedom for the objective.

namespace ffsr {

/// The base angular velocity's rows of the zero-momentum map: w_0 = -A theta_dot, A (3 x n) the
/// angular rows of H_b^-1 H_bm. Reads data.HbInv_Hbm (generalized_jacobian).
inline auto base_angular_rows(const Data& data) { return data.HbInv_Hbm.bottomRows<3>(); }

/// Q (3 x r): a basis of the range of A at (base, theta) (the base angular velocities the arm can
/// cause), from the SVD A = U Sigma V^T: the left singular vectors of the singular values above 1e-9
/// times the largest, each divided by its singular value (Q = U_r Sigma_r^-1), so that the held rows
/// Q^T A have unit singular values there. A light arm on a heavy base has a small A; unscaled, its
/// rows would fall below the task solver's damping threshold and the damped least squares would
/// let the attitude drift. Runs generalized_jacobian. Writes data.
inline Eigen::MatrixXd base_attitude_directions(const Model& model, Data& data, const BasePose& base,
                                                const Eigen::Ref<const Eigen::VectorXd>& theta, int frame) {
  generalized_jacobian(model, data, base, theta, frame);
  const Eigen::MatrixXd A = base_angular_rows(data);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU);
  const auto& sv = svd.singularValues();
  Eigen::Index r = 0;
  while (r < sv.size() && sv(r) > 1e-9 * sv(0)) ++r;
  if (sv.size() == 0 || !(sv(0) > 0)) r = 0;
  return svd.matrixU().leftCols(r) * sv.head(r).cwiseInverse().asDiagonal();
}

/// How the freedom left by the task rows `Jt` (m x n) and the held rows `A` (r x n) is shared among
/// the joints: the diagonal of the projector on the null space of the stack [Jt; A], divided by its
/// trace (the shares sum to 1; all zero when the stack has full column rank). A joint with a share
/// near 1 is the only one the objective can move. On the paper's 7-DOF robot with a position task
/// the share of joint 7 is ~1: it turns the end-effector about its own axis and reacts on the base
/// only through the last link's axial inertia, so holding the base leaves joints 1-6 no freedom.
inline Eigen::VectorXd held_freedom_shares(const Eigen::Ref<const Eigen::MatrixXd>& Jt,
                                           const Eigen::Ref<const Eigen::MatrixXd>& A) {
  const Eigen::Index n = Jt.cols();
  Eigen::MatrixXd S(Jt.rows() + A.rows(), n);
  S << Jt, A;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(S, Eigen::ComputeFullV);
  const auto& sv = svd.singularValues();
  Eigen::Index rank = 0;
  while (rank < sv.size() && sv(rank) > 1e-9 * sv(0)) ++rank;
  Eigen::VectorXd shares = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = rank; i < n; ++i) shares += svd.matrixV().col(i).cwiseAbs2();
  return rank < n ? Eigen::VectorXd(shares / static_cast<double>(n - rank)) : shares;
}

/// The joints a task of `task_rows` rows needs with `attitude_rows` held base-attitude rows:
/// task_rows + attitude_rows, plus one when the objective is optimized (gain != 0).
inline int joints_needed_to_hold(int task_rows, int attitude_rows, bool optimize) {
  return task_rows + attitude_rows + (optimize ? 1 : 0);
}

}  // namespace ffsr
