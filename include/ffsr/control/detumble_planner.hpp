// ffsr/control/detumble_planner.hpp -- the time-optimal post-capture plan: the shortest time in which
// the stack (robot + grasped target, model/attach.hpp) can be brought to rest within the hardware's
// bounds, by direct multiple shooting solved with IPOPT.
//
// Transcription. N intervals of equal length h = T / N, T free. On each the controls are held (joint
// torques; the base actuator's command in the base frame: thrusters' force and moment, or the wheels'
// torque), and the stack's full dynamics (ABA on the stack, the ODE of control/detumble_run.hpp: base
// pose with a unit quaternion, joint angles, velocities, wheel momentum) is integrated by RK4 with a
// fixed number of substeps: x_k+1 = Phi(x_k, u_k, T). The NLP's variables are T, every node's state and
// every interval's controls (scaled by their bounds, so the box is [-1, 1] and held exactly); its
// constraints the continuity of the states (x_k+1 - Phi = 0), the gripper's force and moment in norm at
// every substep's end of every interval (the load with the interval's controls), the wheels' momentum
// per base axis at every node; the start node is fixed to the start, the end node within the rest test
// with a margin (kDetumblePlanRestMargin: each joint rate within margin rest / n; with stop_stack_spin
// each component of the base's angular velocity, and with thrusters of its linear velocity, within
// margin rest / sqrt(3)). The objective is T (plus an optional effort term). IPOPT (interior point,
// MUMPS) with a limited-memory SR1 Hessian; the constraints' Jacobian by forward differences over each interval's inputs (step
// sqrt(eps) max(1, |z|): about 1e-8 relative), computed interval by interval on a few threads; the
// values themselves are exact (the solver's feasibility is the integrator's).
//
// Initial guess: the detumbling law's run (control/detumble_controller.hpp) from the same start under
// the same bounds, on the same integrator, sampled at the nodes; its time to rest is the first T.
//
// Component ffsr::plan (IPOPT, Debian coinor-libipopt-dev).
#pragma once

#include "ffsr/control/detumble_replay.hpp"
#include "ffsr/detail/parallel.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include <chrono>
#include <limits>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

namespace ffsr {

/// The transcription's and the solver's settings.
struct DetumblePlanOptions {
  int intervals = 40;          ///< N
  /// RK4 steps per interval at first: a plan whose controls, re-run by CVODE, do not bring the stack to
  /// rest is solved again from itself with twice the steps (three times at most). Long plans of a spinning
  /// stack (T of 8-24 s on 40 intervals) need 4-8: at 2 the re-run of 14 of 20 start spins missed rest
  int substeps = 2;
  double effort_weight = 0;    ///< w: objective T + w h sum_k |u_k / bound|^2 (0: time only)
  double tolerance = 1e-8;     ///< the largest residual of the constraints (IPOPT constr_viol_tol)
  double optimality = 1e-5;    ///< IPOPT tol (the scaled optimality error)
  int max_iterations = 1500;
  int history = 20;            ///< the limited-memory Hessian's pairs
  bool adaptive_mu = false;     ///< IPOPT's adaptive barrier update (false: monotone)
  bool sr1 = true;              ///< the limited-memory Hessian by SR1 updates (false: BFGS)
  unsigned threads = 0;        ///< 0: the hardware's
  int print_level = 0;         ///< IPOPT's (0: silent)
  /// the largest joint rate at every node, rad/s (m/s prismatic; infinity: none). Time-optimal plans
  /// drive the joints hard: on the paper's 7-DOF stack to 60 deg/s for 0.13 s
  double max_joint_rate = std::numeric_limits<double>::infinity();
  /// The onboard controller's tick, s (0: none). A plan whose intervals come out shorter than the tick
  /// cannot be followed by a command held over a tick (DetumblePlanTracker refuses it): it is solved
  /// again from itself on N = ceil(T / tick) intervals with T >= N tick (the shortest time on them: T at
  /// that bound is the tick's grid, N + 1 intervals tried when N fails). When neither solves, the free
  /// plan is returned (free_duration 0, its intervals shorter than the tick).
  double tick = 0;
};

/// The plan ends within this fraction of the rest rate (every joint rate, and the rest test's norms):
/// at rest by the rest test with room for the re-run's integration error.
inline constexpr double kDetumblePlanRestMargin = 0.6;

namespace detail {

/// The NLP of the plan (see the top of the file).
class DetumblePlanNlp : public Ipopt::TNLP {
 public:
  using Index = Ipopt::Index;
  using Number = Ipopt::Number;

  DetumblePlanNlp(const Model& stack, int gripper, const AttachedBody& body, const DetumbleState& start,
                  const DetumbleLimits& limits, const DetumbleOptions& options, double horizon,
                  const DetumblePlanOptions& po)
      : stack_(stack), gripper_(gripper), body_(body), limits_(limits), options_(options), po_(po),
        horizon_(horizon), n_(stack.n()), N_(po.intervals), S_(po.substeps) {
    ny_ = 16 + 2 * n_;
    wheels_ = limits.actuator == BaseActuator::ReactionWheels;
    thrusters_ = limits.actuator == BaseActuator::Thrusters;
    nu_ = n_ + (thrusters_ ? 6 : wheels_ ? 3 : 0);
    scale_.resize(nu_);
    scale_.head(n_) = limits.joint_torque;
    if (thrusters_) scale_.tail(6) << Vector3::Constant(limits.thruster_force), Vector3::Constant(limits.thruster_torque);
    if (wheels_) scale_.tail(3) = Vector3::Constant(limits.wheel_torque);
    n_grip_ = (std::isfinite(limits.gripper_force) ? 1 : 0) + (std::isfinite(limits.gripper_moment) ? 1 : 0);
    nz_ = ny_ + nu_ + 1;
    rest_ = kDetumblePlanRestMargin * options.rest_rate;
    {
      DetumbleSystem sys(stack);
      y0_ = sys.pack(start);
    }
    threads_ = po.threads > 0 ? po.threads : std::max(1u, std::thread::hardware_concurrency());
    threads_ = std::min<unsigned>(threads_, static_cast<unsigned>(N_));
    set_substeps(S_);
  }

  /// S RK4 steps per interval (the gripper's rows follow: one per substep's end).
  void set_substeps(int S) {
    S_ = S;
    nout_ = ny_ + (S_ + 1) * n_grip_;
    work_.clear();
    for (unsigned t = 0; t < threads_; ++t) work_.emplace_back(stack_, ny_, nz_, nout_);
    out_.assign(static_cast<size_t>(N_), Eigen::VectorXd(nout_));
    jac_.assign(static_cast<size_t>(N_), Eigen::MatrixXd(nout_, nz_));
    xc_.resize(0);
  }
  int substeps() const { return S_; }

  Index num_vars() const { return 1 + (N_ + 1) * ny_ + N_ * nu_; }
  Index oy(int k) const { return 1 + k * ny_; }
  Index ou(int k) const { return 1 + (N_ + 1) * ny_ + k * nu_; }
  int ny() const { return ny_; }
  const Model& stack() const { return stack_; }
  int nu() const { return nu_; }
  const Eigen::VectorXd& scale() const { return scale_; }

  /// The initial guess (x of num_vars()).
  void set_guess(const Eigen::VectorXd& x) { guess_ = x; }
  /// T at least `T` (a plan on a tick's grid: N intervals no shorter than the tick) instead of 1 ms.
  void set_min_duration(double T) { min_duration_ = T; }
  /// T fixed to `T` (the tick's grid, from a plan on its intervals near it).
  void set_fixed_duration(double T) { min_duration_ = max_duration_ = T; }
  const Eigen::VectorXd& solution() const { return x_; }
  Ipopt::SolverReturn status() const { return status_; }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_h, IndexStyleEnum& style) override {
    n = num_vars();
    m = N_ * nout_ + (wheels_ ? 3 * N_ : 0);
    nnz_jac = N_ * (ny_ + nout_ * nz_) + (wheels_ ? 3 * N_ * ny_ : 0);
    nnz_h = 0;
    style = TNLP::C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* xl, Number* xu, Index m, Number* gl, Number* gu) override {
    constexpr double inf = 2e19;
    for (Index i = 0; i < n; ++i) {
      xl[i] = -inf;
      xu[i] = inf;
    }
    xl[0] = min_duration_ > 0 ? min_duration_ : 1e-3;
    xu[0] = max_duration_ > 0 ? max_duration_ : horizon_;
    for (Index i = 0; i < ny_; ++i) xl[oy(0) + i] = xu[oy(0) + i] = y0_(i);
    const Index e = oy(N_);
    // the end at rest by the rest test: each joint rate within rest / n (so that the gripper's rate
    // relative to the base, a sum of n joint rates about unit axes, is within rest too); with
    // stop_stack_spin each component of the base's angular velocity within rest / sqrt(3) (its norm
    // within rest), and with thrusters those of its linear velocity
    const double joint = rest_ / std::max(1, n_), axis = rest_ / std::sqrt(3.0);
    for (int j = 0; j < n_; ++j) {
      xl[e + 13 + n_ + j] = -joint;
      xu[e + 13 + n_ + j] = joint;
    }
    if (options_.stop_stack_spin)
      for (int j = thrusters_ ? 0 : 3; j < 6; ++j) {
        xl[e + 7 + n_ + j] = -axis;
        xu[e + 7 + n_ + j] = axis;
      }
    if (std::isfinite(po_.max_joint_rate))
      for (int k = 1; k < N_; ++k)
        for (int j = 0; j < n_; ++j) {
          xl[oy(k) + 13 + n_ + j] = -po_.max_joint_rate;
          xu[oy(k) + 13 + n_ + j] = po_.max_joint_rate;
        }
    for (int k = 0; k < N_; ++k)
      for (int j = 0; j < nu_; ++j) {
        xl[ou(k) + j] = -1;
        xu[ou(k) + j] = 1;
      }
    Index r = 0;
    for (int k = 0; k < N_; ++k) {
      for (int i = 0; i < ny_; ++i, ++r) gl[r] = gu[r] = 0;
      for (int i = ny_; i < nout_; ++i, ++r) {
        gl[r] = -inf;
        gu[r] = 1;
      }
    }
    for (; r < m; ++r) {  // the wheels' momentum per base axis over its bound
      gl[r] = -1;
      gu[r] = 1;
    }
    return true;
  }

  bool get_starting_point(Index n, bool, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    for (Index i = 0; i < n; ++i) x[i] = guess_(i);
    return true;
  }

  bool eval_f(Index n, const Number* x, bool, Number& f) override {
    f = x[0];
    if (po_.effort_weight > 0) {
      double s = 0;
      for (Index i = ou(0); i < n; ++i) s += x[i] * x[i];
      f += po_.effort_weight * x[0] / N_ * s;
    }
    return true;
  }

  bool eval_grad_f(Index n, const Number* x, bool, Number* g) override {
    for (Index i = 0; i < n; ++i) g[i] = 0;
    g[0] = 1;
    if (po_.effort_weight > 0) {
      double s = 0;
      for (Index i = ou(0); i < n; ++i) {
        s += x[i] * x[i];
        g[i] = 2 * po_.effort_weight * x[0] / N_ * x[i];
      }
      g[0] += po_.effort_weight / N_ * s;
    }
    return true;
  }

  bool eval_g(Index n, const Number* x, bool, Index m, Number* g) override {
    if (!evaluate(n, x, false)) return false;
    Index r = 0;
    for (int k = 0; k < N_; ++k) {
      const Eigen::VectorXd& o = out_[static_cast<size_t>(k)];
      for (int i = 0; i < ny_; ++i) g[r++] = x[oy(k + 1) + i] - o(i);
      for (int i = ny_; i < nout_; ++i) g[r++] = o(i);
    }
    if (wheels_)
      for (int k = 1; k <= N_; ++k) {
        const Vector3 w = wheel_rows(x + oy(k));
        for (int i = 0; i < 3; ++i) g[r++] = w(i);
      }
    (void)m;
    return true;
  }

  bool eval_jac_g(Index n, const Number* x, bool, Index, Index nele, Index* row, Index* col,
                  Number* val) override {
    if (!x) return jacobian_structure(row, col) == nele;
    if (!evaluate(n, x, true)) return false;
    Index e = 0;
    for (int k = 0; k < N_; ++k) {
      const Eigen::MatrixXd& J = jac_[static_cast<size_t>(k)];
      for (int i = 0; i < nout_; ++i) {
        const double sign = i < ny_ ? -1.0 : 1.0;  // continuity rows: x_k+1 - Phi
        if (i < ny_) val[e++] = 1;
        for (int j = 0; j < nz_; ++j) val[e++] = sign * J(i, j);
      }
    }
    if (wheels_)
      for (int k = 1; k <= N_; ++k) {
        const Eigen::Matrix<double, 3, Eigen::Dynamic> W = wheel_jacobian(x + oy(k));
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < ny_; ++j) val[e++] = W(i, j);
      }
    return e == nele;
  }

  void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* x, const Number*, const Number*,
                         Index, const Number*, const Number*, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    status_ = status;
    x_ = Eigen::Map<const Eigen::VectorXd>(x, n);
  }

  /// Integrates interval k's dynamics from y with the scaled controls s over h: y at the end, and the
  /// gripper rows (|f|^2 / F^2, |m|^2 / M^2) at the start and every substep's end into `out`.
  struct Work {
    DetumbleSystem sys;
    detail::StackRk4 rk;  ///< the stages of detail::rk4_stack_step
    Eigen::VectorXd y, z, base, pert;
    DetumbleCommand cmd;
    Work(const Model& m, int ny, int nz, int nout) : sys(m), rk(ny), y(ny), z(nz), base(nout), pert(nout) {
      cmd.tau = Eigen::VectorXd::Zero(m.n());
    }
  };

  /// The command of the scaled controls s at the state y (base frame -> inertial).
  void command(const Eigen::Ref<const Eigen::VectorXd>& y, const Eigen::Ref<const Eigen::VectorXd>& s,
               DetumbleCommand& c) const {
    c.tau = s.head(n_).cwiseProduct(scale_.head(n_));
    const Matrix3 R = Quaternion(y(6), y(3), y(4), y(5)).normalized().toRotationMatrix();
    c.base_wrench.setZero();
    if (thrusters_) {
      c.base_wrench.head<3>() = R * s.segment<3>(n_).cwiseProduct(scale_.segment<3>(n_));
      c.base_wrench.tail<3>() = R * s.segment<3>(n_ + 3).cwiseProduct(scale_.segment<3>(n_ + 3));
    } else if (wheels_) {
      c.base_wrench.tail<3>() = R * s.segment<3>(n_).cwiseProduct(scale_.segment<3>(n_));
    }
  }

  void interval(Work& w, const Eigen::Ref<const Eigen::VectorXd>& z, Eigen::VectorXd& out) const {
    const auto y0 = z.head(ny_);
    const auto s = z.segment(ny_, nu_);
    const double dt = z(nz_ - 1) / N_ / S_;
    w.y = y0;
    int row = ny_;
    const auto grip = [&](const Eigen::VectorXd& y) {
      if (n_grip_ == 0) return;
      command(y, s, w.cmd);
      Vector3 f, m;
      w.sys.gripper_load(y, w.cmd, gripper_, body_, f, m);
      if (std::isfinite(limits_.gripper_force)) out(row++) = f.squaredNorm() / (limits_.gripper_force * limits_.gripper_force);
      if (std::isfinite(limits_.gripper_moment))
        out(row++) = m.squaredNorm() / (limits_.gripper_moment * limits_.gripper_moment);
    };
    grip(w.y);
    const auto f = [&](const Eigen::VectorXd& y, Eigen::VectorXd& yd) {
      command(y, s, w.cmd);
      w.sys.rhs(y, w.cmd, wheels_, yd);
    };
    for (int j = 0; j < S_; ++j) {
      detail::rk4_stack_step(w.rk, w.y, dt, f);
      grip(w.y);
    }
    out.head(ny_) = w.y;
  }

  /// One RK4 tick of the feedback law's command (held, inertial), for the initial guess.
  void step_held(Work& w, const DetumbleCommand& c, double dt, int substeps) const {
    const auto f = [&](const Eigen::VectorXd& y, Eigen::VectorXd& yd) { w.sys.rhs(y, c, wheels_, yd); };
    for (int j = 0; j < substeps; ++j) detail::rk4_stack_step(w.rk, w.y, dt / substeps, f);
  }

  Work& work0() { return work_.front(); }
  const Eigen::VectorXd& start() const { return y0_; }

  /// Largest |x_k+1 - Phi| and gripper excess at x.
  double violation(const Eigen::VectorXd& x) {
    Index n, m, nj, nh;
    IndexStyleEnum st;
    get_nlp_info(n, m, nj, nh, st);
    std::vector<Number> g(static_cast<size_t>(m)), gl(static_cast<size_t>(m)), gu(static_cast<size_t>(m)),
        xl(static_cast<size_t>(n)), xu(static_cast<size_t>(n));
    get_bounds_info(n, xl.data(), xu.data(), m, gl.data(), gu.data());
    eval_g(n, x.data(), true, m, g.data());
    double v = 0;
    for (Index r = 0; r < m; ++r) v = std::max({v, gl[r] - g[r], g[r] - gu[r]});
    return v;
  }

 private:
  /// The Jacobian's entries in eval_jac_g's order; returns their count.
  Index jacobian_structure(Index* row, Index* col) const {
    Index e = 0, r = 0;
    const auto entry = [&](Index c) {
      row[e] = r;
      col[e++] = c;
    };
    for (int k = 0; k < N_; ++k)
      for (int i = 0; i < nout_; ++i, ++r) {
        if (i < ny_) entry(oy(k + 1) + i);
        for (int j = 0; j < nz_; ++j) entry(zcol(k, j));
      }
    if (wheels_)
      for (int k = 1; k <= N_; ++k)
        for (int i = 0; i < 3; ++i, ++r)
          for (int j = 0; j < ny_; ++j) entry(oy(k) + j);
    return e;
  }

  /// The wheel rows' derivatives at the node y (forward differences over the quaternion and the
  /// wheels' momentum, the only entries they depend on).
  Eigen::Matrix<double, 3, Eigen::Dynamic> wheel_jacobian(const Number* y) const {
    Eigen::VectorXd yk = Eigen::Map<const Eigen::VectorXd>(y, ny_);
    Eigen::Matrix<double, 3, Eigen::Dynamic> W = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, ny_);
    const Vector3 w0 = wheel_rows(yk.data());
    for (int j : {3, 4, 5, 6, ny_ - 3, ny_ - 2, ny_ - 1}) {
      const double d = 1e-7 * std::max(1.0, std::abs(yk(j))), keep = yk(j);
      yk(j) += d;
      W.col(j) = (wheel_rows(yk.data()) - w0) / d;
      yk(j) = keep;
    }
    return W;
  }

  Index zcol(int k, int j) const {
    if (j < ny_) return oy(k) + j;
    if (j < ny_ + nu_) return ou(k) + (j - ny_);
    return 0;
  }

  Vector3 wheel_rows(const Number* y) const {
    const Matrix3 R = Quaternion(y[6], y[3], y[4], y[5]).normalized().toRotationMatrix();
    const Vector3 h(y[ny_ - 3], y[ny_ - 2], y[ny_ - 1]);
    return R.transpose() * h / limits_.wheel_momentum;
  }

  /// Every interval's outputs (and with `jacobian` their derivatives) at x; cached by x.
  bool evaluate(Index n, const Number* x, bool jacobian) {
    const Eigen::Map<const Eigen::VectorXd> xv(x, n);
    const bool same = xc_.size() == n && xc_ == xv;
    if (same && (have_jac_ || !jacobian)) return ok_;
    xc_ = xv;
    have_jac_ = jacobian;
    std::vector<char> ok(static_cast<size_t>(N_), 1);
    detail::parallel_chunks(static_cast<std::uint64_t>(N_), threads_, [&](unsigned t, std::uint64_t lo, std::uint64_t hi) {
      Work& w = work_[t];
      for (auto kk = lo; kk < hi; ++kk) {
        const int k = static_cast<int>(kk);
        w.z << xv.segment(oy(k), ny_), xv.segment(ou(k), nu_), xv(0);
        Eigen::VectorXd& o = out_[kk];
        interval(w, w.z, o);
        if (!o.allFinite()) {
          ok[kk] = 0;
          continue;
        }
        if (!jacobian) continue;
        Eigen::MatrixXd& J = jac_[kk];
        for (int j = 0; j < nz_; ++j) {
          const double keep = w.z(j), d = 1.49e-8 * std::max(1.0, std::abs(keep));
          w.z(j) = keep + d;
          interval(w, w.z, w.pert);
          w.z(j) = keep;
          J.col(j) = (w.pert - o) / d;
        }
        if (!J.allFinite()) ok[kk] = 0;
      }
    });
    ok_ = std::all_of(ok.begin(), ok.end(), [](char c) { return c != 0; });
    return ok_;
  }

  const Model& stack_;
  int gripper_;
  AttachedBody body_;
  DetumbleLimits limits_;
  DetumbleOptions options_;
  DetumblePlanOptions po_;
  double horizon_;
  int n_, N_, S_, ny_ = 0, nu_ = 0, nz_ = 0, nout_ = 0, n_grip_ = 0;
  double rest_ = 0, min_duration_ = 0, max_duration_ = 0;
  bool wheels_ = false, thrusters_ = false;
  Eigen::VectorXd scale_, y0_, guess_, x_, xc_;
  bool have_jac_ = false, ok_ = false;
  unsigned threads_ = 1;
  std::vector<Work> work_;
  std::vector<Eigen::VectorXd> out_;
  std::vector<Eigen::MatrixXd> jac_;
  Ipopt::SolverReturn status_ = Ipopt::UNASSIGNED;
};

inline const char* ipopt_status_name(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded: return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level: return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected: return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small: return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates: return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop: return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found: return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded: return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed: return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation: return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded: return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom: return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition: return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option: return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected: return "Invalid_Number_Detected";
    default: return "Internal_Error";
  }
}

}  // namespace detail

/// The solver did not reach a plan: IPOPT's status and the smallest constraint violation it reached.
class DetumblePlanError : public NumericalError {
 public:
  DetumblePlanError(const std::string& what, std::string st, double residual)
      : NumericalError(what), status(std::move(st)), best_residual(residual) {}
  std::string status;
  double best_residual;
};

/// The time-optimal plan from `start` (see the top of the file); `horizon` bounds T. With `warm`, its
/// nodes and controls (resampled to this plan's intervals) are the initial guess instead of the
/// feedback law's run. InputError for bad limits, options or start (and DetumbleInfeasibleError when
/// the actuator cannot stop the stack's spin within the horizon); DetumblePlanError when IPOPT does
/// not converge.
inline DetumblePlan plan_detumble(const Model& stack, int gripper, const AttachedBody& body,
                                  const DetumbleState& start, const DetumbleLimits& limits,
                                  const DetumbleOptions& options, double horizon,
                                  const DetumblePlanOptions& po = {}, const DetumblePlan* warm = nullptr);

}  // namespace ffsr

#include "ffsr/control/detail/detumble_planner.hxx"
