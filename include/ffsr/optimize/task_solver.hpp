// ffsr/optimize/task_solver.hpp -- the rate law of the capture approach (Eq. 30-31), one tick.
#pragma once

#include "ffsr/spatial/spatial.hpp"
#include "ffsr/errors.hpp"
#include "ffsr/model/model.hpp"
#include "ffsr/optimize/line_reference.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

//   theta_dot = J_t^+ (x_d_dot + k_p e) + alpha N qd_free,   N = E - J_t^+ J_t,
//
// J_t the task rows of the generalized Jacobian J_f (Eq. 29: x_dot = J_f theta_dot under zero
// momentum), J_t^+ its pseudo-inverse from the SVD J_t = U Sigma V^T: 1/sigma_i on the singular
// values above 1e-12, and damped least squares sigma_i / (sigma_i^2 + lambda^2) on all of them when
// the smallest falls below the threshold sigma_t, with lambda^2 = (1 - (sigma_min/sigma_t)^2)
// lambda_max^2 (zero at the threshold, lambda_max^2 at a singularity). N projects on the null space
// of J_t (E minus v_i v_i^T for every sigma_i > 1e-12), so J_t N = 0 and N N = N. alpha in [0, 1] is
// the largest factor that keeps every |theta_dot_k| <= the joint-rate limit (the task part is never
// scaled; alpha = 0 when the task part alone breaks the limit).
//
// TaskSolver holds its workspace, sized at construction (n joints, m task rows); solve() and
// add_null_space() then run without heap allocation (JacobiSVD on its preallocated storage), so an
// onboard controller can call them once per control tick.

namespace ffsr {

/// The commanded task velocity x_d_dot + k_p e of Eq. 30 as a 6-vector (linear first): the line
/// reference's velocity at t plus the feedback gain times the position error x_d - p_e and, for a
/// pose task, the angular velocity plus k_p log(R_d R_e^T); the angular part is zero otherwise.
/// Reads the reference and the end-effector pose `ee`.
inline Vector6 task_velocity_command(const LineReference& line, double t, const Pose& ee, double feedback,
                                     bool pose_task) {
  Vector3 xd, vd, wd;
  Matrix3 Rd;
  line.at(t, xd, vd, Rd, wd);
  Vector6 cmd;
  cmd.head<3>() = vd + feedback * (xd - ee.p);
  if (pose_task) {
    cmd.tail<3>() = wd + feedback * detail::rotation_log(Rd * ee.R.transpose());
  } else {
    cmd.tail<3>().setZero();
  }
  return cmd;
}

namespace detail {
/// The largest a <= 1 with |c_k + a b_k| <= L for every k (c the task rates, b the null-space rates);
/// negative when the task part alone breaks the limit (the caller clamps it to 0).
inline double null_space_scale(const Eigen::VectorXd& c, const Eigen::VectorXd& b, double L) {
  double a = 1.0;
  for (Eigen::Index k = 0; k < b.size(); ++k) {
    if (b(k) > 0)
      a = std::min(a, (L - c(k)) / b(k));
    else if (b(k) < 0)
      a = std::min(a, (-L - c(k)) / b(k));
  }
  return a;
}
}  // namespace detail

/// What one evaluation of the rate law gives.
struct TaskRates {
  Eigen::VectorXd theta_dot;  ///< joint rates (task part, plus the scaled null-space part once added)
  bool damped = false;        ///< the pseudo-inverse was damped (sigma_min < threshold)
  double sigma_min = 0;       ///< smallest singular value of J_t
  double lambda2 = 0;         ///< lambda^2 of the damped least squares (0: undamped)
  double null_scale = 1;      ///< alpha, the factor applied to the null-space rates (1: not scaled)
};

/// The task solver of Eq. 30-31 (see the notes after the includes).
class TaskSolver {
 public:
  /// n joints; `rows` the rows of J_f (0-2 linear, 3-5 angular) the task constrains;
  /// singular_value_threshold sigma_t (> 0) and max_damping lambda_max of the damped least squares.
  TaskSolver(int n, std::vector<int> rows, double singular_value_threshold, double max_damping)
      : TaskSolver(n, std::move(rows), 0, singular_value_threshold, max_damping) {}

  /// The same with `extra_rows` (>= 0) further constraint rows held at zero velocity with priority
  /// over the task (the base-attitude rows of the reaction-null-space approach): call the solve()
  /// that takes them.
  TaskSolver(int n, std::vector<int> rows, int extra_rows, double singular_value_threshold,
             double max_damping)
      : rows_(std::move(rows)),
        extra_(extra_rows),
        threshold_(singular_value_threshold),
        max_damping_(max_damping),
        Jt_(static_cast<Eigen::Index>(rows_.size()) + std::max(extra_rows, 0), n),
        xdot_(static_cast<Eigen::Index>(rows_.size()) + std::max(extra_rows, 0)),
        Jpinv_(n, static_cast<Eigen::Index>(rows_.size()) + std::max(extra_rows, 0)),
        N_(n, n),
        svd_(static_cast<Eigen::Index>(rows_.size()) + std::max(extra_rows, 0), n,
             Eigen::ComputeFullU | Eigen::ComputeFullV) {
    if (n < 1 || rows_.empty()) FFSR_THROW(InputError("TaskSolver: needs at least one joint and one task row"));
    if (extra_rows < 0) FFSR_THROW(InputError("TaskSolver: the number of extra rows must be >= 0"));
    if (extra_rows > 0) {
      svd_extra_ =
          Eigen::JacobiSVD<Eigen::MatrixXd>(extra_rows, n, Eigen::ComputeFullU | Eigen::ComputeFullV);
      svd_task_ = Eigen::JacobiSVD<Eigen::MatrixXd>(static_cast<Eigen::Index>(rows_.size()), n,
                                                    Eigen::ComputeFullU | Eigen::ComputeFullV);
      NA_.resize(n, n);
      JtN_.resize(static_cast<Eigen::Index>(rows_.size()), n);
    }
    for (int r : rows_)
      if (r < 0 || r > 5) FFSR_THROW(InputError(detail::str("TaskSolver: task row ", r, " is not in 0..5")));
    out_.theta_dot.resize(n);
    N_.setIdentity();
  }

  int joints() const { return static_cast<int>(N_.rows()); }
  int task_rows() const { return static_cast<int>(rows_.size()); }
  int extra_rows() const { return extra_; }

  /// One evaluation: selects the task rows of `Jf` (6 x n) and of `cmd`, factorizes, writes the
  /// task joint rates J_t^+ cmd_t and the singular-value report into the result; with
  /// `with_projector` also the null-space projector N (projector()). Reads Jf, cmd. No allocation.
  const TaskRates& solve(const Eigen::Ref<const Eigen::MatrixXd>& Jf, const Vector6& cmd,
                         bool with_projector) {
    if (extra_ > 0) FFSR_THROW(InputError("TaskSolver: built with extra rows; pass them to solve()"));
    select_task_rows(Jf, cmd);
    return factorize(with_projector);
  }

  /// One evaluation with the extra rows `A` (extra_rows() x n) held at zero velocity with priority
  /// over the task: with N_A the projector on the null space of A, theta_dot = (J_t N_A)^+ cmd_t (so
  /// A theta_dot = 0 exactly, also where J_t N_A is damped), N = N_A minus the task directions of
  /// J_t N_A (the null space of the stack [J_t; A]); sigma_min and the damping are those of J_t N_A.
  /// task_jacobian() is the stack. Reads Jf, cmd, A. No allocation.
  const TaskRates& solve(const Eigen::Ref<const Eigen::MatrixXd>& Jf, const Vector6& cmd, bool with_projector,
                         const Eigen::Ref<const Eigen::MatrixXd>& A) {
    if (A.rows() != extra_ || A.cols() != Jt_.cols())
      FFSR_THROW(InputError(detail::str("TaskSolver: the extra rows are ", A.rows(), "x", A.cols(), ", expected ",
                                   extra_, "x", Jt_.cols())));
    const int m = task_rows();
    select_task_rows(Jf, cmd);
    Jt_.bottomRows(extra_) = A;
    xdot_.tail(extra_).setZero();
    svd_extra_.compute(A);
    NA_.setIdentity();
    for (Eigen::Index i = 0; i < svd_extra_.singularValues().size(); ++i)
      if (svd_extra_.singularValues()(i) > 1e-12)
        NA_.noalias() -= svd_extra_.matrixV().col(i) * svd_extra_.matrixV().col(i).transpose();
    JtN_.noalias() = Jt_.topRows(m) * NA_;
    svd_task_.compute(JtN_);
    const auto& sv = svd_task_.singularValues();
    set_damping(sv(sv.size() - 1));
    Jpinv_.setZero();
    for (Eigen::Index i = 0; i < sv.size(); ++i)
      Jpinv_.leftCols(m).noalias() +=
          pinv_gain(sv(i)) * svd_task_.matrixV().col(i) * svd_task_.matrixU().col(i).transpose();
    out_.theta_dot.noalias() = Jpinv_ * xdot_;
    if (with_projector) {
      N_ = NA_;
      for (Eigen::Index i = 0; i < sv.size(); ++i)
        if (sv(i) > 1e-12)
          N_.noalias() -= svd_task_.matrixV().col(i) * svd_task_.matrixV().col(i).transpose();
    }
    return out_;
  }

 private:
  void select_task_rows(const Eigen::Ref<const Eigen::MatrixXd>& Jf, const Vector6& cmd) {
    const int m = task_rows();
    for (int r = 0; r < m; ++r) {
      Jt_.row(r) = Jf.row(rows_[static_cast<size_t>(r)]);
      xdot_(r) = cmd(rows_[static_cast<size_t>(r)]);
    }
  }

  /// The report and the damping of the last factorization from its smallest singular value.
  void set_damping(double sigma_min) {
    out_.sigma_min = sigma_min;
    out_.lambda2 = 0;
    out_.damped = false;
    out_.null_scale = 1;
    if (out_.sigma_min < threshold_) {
      const double r = out_.sigma_min / threshold_;
      out_.lambda2 = (1 - r * r) * max_damping_ * max_damping_;
      out_.damped = true;
    }
  }
  /// The factor of a singular value in the (damped) pseudo-inverse.
  double pinv_gain(double sigma) const {
    return out_.lambda2 > 0 ? sigma / (sigma * sigma + out_.lambda2) : (sigma > 1e-12 ? 1.0 / sigma : 0.0);
  }

  const TaskRates& factorize(bool with_projector) {
    svd_.compute(Jt_);
    const auto& sv = svd_.singularValues();
    set_damping(sv(sv.size() - 1));
    Jpinv_.setZero();
    for (Eigen::Index i = 0; i < sv.size(); ++i) {
      const double g = pinv_gain(sv(i));
      Jpinv_.noalias() += g * svd_.matrixV().col(i) * svd_.matrixU().col(i).transpose();
    }
    out_.theta_dot.noalias() = Jpinv_ * xdot_;
    if (with_projector) {
      // from the right singular vectors of the non-negligible singular values
      N_.setIdentity();
      for (Eigen::Index i = 0; i < sv.size(); ++i)
        if (sv(i) > 1e-12) N_.noalias() -= svd_.matrixV().col(i) * svd_.matrixV().col(i).transpose();
    }
    return out_;
  }

 public:
  /// Adds the null-space rates `qd_null` (already projected, N applied) to the task rates of the
  /// last solve(), scaled in place by the largest alpha in [0, 1] with |theta_dot_k + alpha
  /// qd_null_k| <= max_joint_rate for every k (max_joint_rate 0: not limited, alpha = 1). Writes
  /// qd_null (scaled) and the result's theta_dot and null_scale. No allocation.
  const TaskRates& add_null_space(Eigen::VectorXd& qd_null, double max_joint_rate) {
    if (max_joint_rate > 0) {
      out_.null_scale = std::max(detail::null_space_scale(out_.theta_dot, qd_null, max_joint_rate), 0.0);
      qd_null *= out_.null_scale;
    }
    out_.theta_dot += qd_null;
    return out_;
  }

  /// The null-space projector N of the last solve() with the projector (identity before any).
  const Eigen::MatrixXd& projector() const { return N_; }
  /// The pseudo-inverse J_t^+ (n x m) of the last solve().
  const Eigen::MatrixXd& pseudo_inverse() const { return Jpinv_; }
  /// The task rows J_t (m x n; with the extra rows below them) of the last solve().
  const Eigen::MatrixXd& task_jacobian() const { return Jt_; }
  /// The result of the last solve() / add_null_space().
  const TaskRates& rates() const { return out_; }

 private:
  std::vector<int> rows_;
  int extra_ = 0;  ///< constraint rows below the task rows (held at zero velocity)
  double threshold_, max_damping_;
  Eigen::MatrixXd Jt_;
  Eigen::VectorXd xdot_;
  Eigen::MatrixXd Jpinv_, N_;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd_;
  // extra rows (held with priority): their SVD and projector N_A, J_t N_A and its SVD
  Eigen::JacobiSVD<Eigen::MatrixXd> svd_extra_, svd_task_;
  Eigen::MatrixXd NA_, JtN_;
  TaskRates out_;
};

}  // namespace ffsr
