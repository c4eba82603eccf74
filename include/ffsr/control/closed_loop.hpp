// ffsr/control/closed_loop.hpp -- the capture controller in a closed loop with the robot's full
// dynamics and a noisy target estimate. Component ffsr::cvode (SUNDIALS).
#pragma once

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/control/capture_controller.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <cstdint>
#include <vector>

// Plant: the free-floating robot, forward dynamics of Eq. 1 (H a = tau - C by the articulated-body
// algorithm, algorithm/aba.hpp; CRBA + RNEA + Cholesky for a model with mimic joints; no external
// force, no gravity unless the model has some), with the state
//   y = [p_0 - p_0(0) (3), phi_0 (3: base attitude as a rotation vector from the initial one),
//        theta (n), v_0 (3), omega_0 (3), theta_dot (n), z (n: the PI integrators)].
// Each joint has a rate loop: tau_k = sat(K_p,k (u_k - theta_dot_k) + K_i,k z_k, tau_max), z_k_dot =
// u_k - theta_dot_k while the torque is not saturated (conditional integration: no wind-up), u the
// controller's command held constant over a control period (zero-order hold).
// Integration (ClosedLoopOptions::integrator): the command jumps at every tick, so the right-hand
// side is smooth within a control period and jumps at its ends. The default, RungeKutta, is one
// continuous explicit integration whose steps end on the ticks: the Dormand-Prince 5(4) pair, its
// step size carried from tick to tick (one step per tick when the error allows), the error of each
// step kept below rtol |y_i| + atol (weighted RMS, as CVODE) by the embedded 4th-order solution, and
// the last stage of a tick reused for the first of the next (only the torques change there). A
// multistep method would carry its history across the jumps; CvodeRestart, CVODE (BDF) restarted at
// every tick, is kept as the reference it was measured against (docs/controller.md).
// Controller: CaptureController::step at the control rate on the true state (the measured state is
// exact: joint encoders and the base's attitude/position sensors are not modelled).
// Target estimate: at the estimate rate (from t = 0), the truth (propagate_target of the problem's
// target) plus independent Gaussian noise of the stated standard deviations: position (m, each
// axis), attitude (rad: a rotation exp([n]) with n ~ N(0, sigma^2 I) applied on the inertial side),
// velocity (m/s, each axis) and spin (rad/s, each axis of the target frame). Each estimate k draws
// from its own stream SampleStream(seed, k) (uncertainty/sampling.hpp): the same seed gives the same
// noise on every platform. update_target is called with it.
// Result at T: the end-effector position against the TRUE capture point, M_ie and the closed-form
// F_max at the reached configuration (true target at T), the largest joint torque, the largest
// tracking lag |u_k - theta_dot_k| at the end of a control period (the command held over it), the largest end-effector distance from the reference, the base's
// attitude change, and the largest |total momentum| (it is zero at the start and no external force
// acts, so anything else is integration error).

namespace ffsr {

/// The joints' rate loops: PI on the rate error, gains scaled by each joint's inertia so that one
/// bandwidth fits every joint. With M the free-floating joint-space inertia H_mm - H_mb H_b^-1 H_bm
/// at the start, K_p,k = omega M_kk and K_i,k = omega^2 / 4 M_kk: a joint alone (M_kk theta_ddot =
/// tau) then has the closed-loop poles s = -omega / 2 (double: critically damped).
struct RateLoopGains {
  double bandwidth = 50.0;      ///< omega, rad/s
  double torque_limit = 100.0;  ///< N m, |tau_k| <= it
};

/// The noise of the target estimate, standard deviations (Gaussian, independent per axis).
struct EstimateNoise {
  double position = 0;          ///< m
  double attitude = 0;          ///< rad
  double velocity = 0;          ///< m/s
  double angular_velocity = 0;  ///< rad/s (target frame)
};

/// How the plant is integrated from tick to tick (see the notes after the includes).
enum class ClosedLoopIntegrator {
  RungeKutta,    ///< Dormand-Prince 5(4), one continuous integration, steps ending on the ticks
  CvodeRestart,  ///< CVODE (BDF, Newton, dense) restarted at every tick: the reference, slow
};

struct ClosedLoopOptions {
  double control_rate = 1000.0;  ///< Hz: controller ticks (zero-order hold in between)
  double estimate_rate = 5.0;    ///< Hz: target estimates (update_target)
  RateLoopGains loop;
  EstimateNoise noise;
  std::uint64_t seed = 1;
  ClosedLoopIntegrator integrator = ClosedLoopIntegrator::RungeKutta;
  /// Local error per step <= rtol |y_i| + atol (weighted RMS; both integrators). The defaults are the
  /// Runge-Kutta's, one step per 1 ms tick on the 7-DOF run: its capture error, M_ie and largest
  /// torque equal those of CVODE restarted per tick at 1e-9 and 1e-12 within 1e-6 m, 1e-6 and 1e-3
  /// relative (measured in docs/controller.md); the CvodeRestart reference is run at 1e-9 and 1e-12.
  double rtol = 1e-6;
  double atol = 1e-8;       ///< m, rad, m/s, rad/s
  double record_every = 0;  ///< s between recorded samples (0: none)
};

struct ClosedLoopSample {
  double t = 0;
  Eigen::VectorXd theta, theta_dot, command, torque;
  Vector3 end_effector = Vector3::Zero(), reference = Vector3::Zero();
  double momentum = 0;  ///< |total momentum| (|P| + |L|)
};

struct ClosedLoopResult {
  Eigen::VectorXd theta;  ///< reached configuration at T
  BasePose base;          ///< base pose at T
  Vector3 end_effector = Vector3::Zero();
  Vector3 capture_point = Vector3::Zero();  ///< the true target's contact point at T
  double capture_error = 0;                 ///< |p_e(T) - capture point|, m
  double M_ie = 0;                          ///< at the reached configuration (true target at T), kg
  double f_max_closed_form = 0;             ///< Eq. 24 at that M_ie, N
  double max_torque = 0;                    ///< largest |tau_k|, N m
  double max_tracking_lag = 0;              ///< largest |u_k - theta_dot_k| at the end of a tick, rad/s
  double max_reference_error = 0;           ///< largest |p_e - x_d| at the ticks, m
  double base_attitude_change = 0;          ///< rotation angle of the base from 0 to T, rad
  double base_position_change = 0;          ///< m
  double max_momentum = 0;                  ///< largest |P| + |L| at the ticks
  long ticks = 0, estimates = 0, fault_ticks = 0, damped_ticks = 0, rate_limited_ticks = 0;
  long saturated_ticks = 0;  ///< ticks with some joint's torque at the limit
  long integrator_steps = 0;  ///< accepted steps (RungeKutta) or CVODE's steps, over the run
  long rejected_steps = 0;    ///< RungeKutta: steps the error test refused and took again, shorter
  std::vector<ClosedLoopSample> series;
};

namespace detail {

/// The plant of the closed loop: the robot's dynamics with the PI rate loops (see the notes after the
/// includes).
struct ClosedLoopPlant {
  const Model& model;
  Data data;
  BasePose base0;
  int n;
  RateLoopGains gains;
  Eigen::VectorXd u, theta, v, tau, a, e, kp, ki;
  Eigen::VectorXd bias;  ///< C(q, v) at the state of the last dynamics() call (mimic joints)
  bool articulated;      ///< one body per coordinate: the articulated-body algorithm (else crba + rnea)

  ClosedLoopPlant(const Model& m, const BasePose& b0, const Eigen::VectorXd& theta0, const RateLoopGains& g)
      : model(m),
        data(m),
        base0(b0),
        n(m.n()),
        gains(g),
        u(Eigen::VectorXd::Zero(n)),
        theta(n),
        v(6 + n),
        tau(Eigen::VectorXd::Zero(6 + n)),
        a(6 + n),
        e(n),
        kp(n),
        ki(n),
        bias(6 + n),
        articulated(m.nb() - 1 == m.n()) {
    base0.orientation.normalize();
    crba(model, data, base0, theta0);  // M = H_mm - H_mb H_b^-1 H_bm, its diagonal
    const Eigen::LLT<Matrix6> Hb(data.H.topLeftCorner<6, 6>());
    const Eigen::MatrixXd Hbm = data.H.topRightCorner(6, n);
    const Eigen::MatrixXd M = data.H.bottomRightCorner(n, n) - Hbm.transpose() * Hb.solve(Hbm);
    for (int k = 0; k < n; ++k) {
      kp(k) = g.bandwidth * M(k, k);
      ki(k) = 0.25 * g.bandwidth * g.bandwidth * M(k, k);
    }
  }
  Eigen::Index iv() const { return 6 + n; }
  Eigen::Index iz() const { return 12 + 2 * n; }
  BasePose base(const Eigen::Ref<const Eigen::VectorXd>& y) const {
    BasePose b;
    b.position = base0.position + y.segment<3>(0);
    b.orientation = Quaternion(rotation_from_vector(y.segment<3>(3)) * base0.orientation.toRotationMatrix());
    return b;
  }
  /// The joint torques of the rate loops at y (writes tau's joint part and e); true if one saturates.
  bool torques(const Eigen::Ref<const Eigen::VectorXd>& y) {
    e = u - y.segment(iv() + 6, n);
    bool sat = false;
    for (int k = 0; k < n; ++k) {
      const double t = kp(k) * e(k) + ki(k) * y(iz() + k);
      const double c = std::clamp(t, -gains.torque_limit, gains.torque_limit);
      sat = sat || c != t;
      tau(6 + k) = c;
    }
    return sat;
  }
  /// What of the dynamics does not depend on the command, at y. One body per coordinate (no mimic
  /// joint): the first half of the articulated-body algorithm (detail::aba_velocity_pass: kinematics,
  /// velocities, articulated inertias). With mimic joints: H (crba), its Cholesky factor (data.L)
  /// and the bias forces C (rnea). Writes data, theta, v (and bias). NumericalError if H is not
  /// positive definite.
  void dynamics(const Eigen::Ref<const Eigen::VectorXd>& y) {
    const BasePose b = base(y);
    theta = y.segment(6, n);
    v = y.segment(iv(), 6 + n);
    if (articulated) {
      aba_velocity_pass(model, data, b, theta, v);
      return;
    }
    crba(model, data, b, theta);
    bias = bias_forces(model, data, b, theta, v);
    detail::cholesky(data.H, data.L, "closed loop");
  }
  /// ydot at y with the command u, from the dynamics() of the same y: the forward dynamics
  /// a = H^-1 (tau - C) (the second half of the articulated-body algorithm, or the Cholesky solve
  /// with mimic joints) and the rate loops. Reads y, u, v and what dynamics() wrote. Writes tau, e,
  /// a (and data's fields of the articulated-body algorithm).
  void derivative(const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) {
    torques(y);
    if (articulated) {
      aba_acceleration_pass(model, data, v, tau, a);
    } else {
      a = tau - bias;
      detail::cholesky_solve(data.L, a);
    }
    ydot.segment<3>(0) = y.segment<3>(iv());
    ydot.segment<3>(3) = rotation_vector_rate(y.segment<3>(3), y.segment<3>(iv() + 3));
    ydot.segment(6, n) = y.segment(iv() + 6, n);
    ydot.segment(iv(), 6 + n) = a;
    for (int k = 0; k < n; ++k) {  // conditional integration: hold z while the torque is at the limit
      const bool at_limit = std::abs(tau(6 + k)) >= gains.torque_limit && tau(6 + k) * e(k) > 0;
      ydot(iz() + k) = at_limit ? 0.0 : e(k);
    }
  }
  /// The right-hand side f(y) with the command u.
  void rhs(const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) {
    dynamics(y);
    derivative(y, ydot);
  }
};

/// The target estimate k: the truth at t plus the noise of `o` from SampleStream(seed, k).
inline TargetEstimate noisy_estimate(const Target& truth, const ClosedLoopOptions& o, std::uint64_t k) {
  SampleStream s(o.seed, k);
  // the three draws in separate statements: the arguments of one call are evaluated in an order the
  // compiler chooses (GCC right to left, clang left to right), and the noise of a seed must not depend
  // on it. z, y, x: the order of the GCC builds that measured docs/controller.md's noise studies.
  auto gauss3 = [&](double sigma) {
    const double z = s.normal();
    const double y = s.normal();
    const double x = s.normal();
    return Vector3(sigma * x, sigma * y, sigma * z);
  };
  TargetEstimate e = target_estimate(truth);
  e.position += gauss3(o.noise.position);
  e.attitude = Quaternion(rotation_from_vector(gauss3(o.noise.attitude)) * truth.rotation());
  e.velocity += gauss3(o.noise.velocity);
  e.angular_velocity += gauss3(o.noise.angular_velocity);
  return e;
}

inline void check_closed_loop_options(const ClosedLoopOptions& o) {
  auto positive = [](double x, const char* what) {
    if (!std::isfinite(x) || x <= 0)
      throw InputError(str("closed loop: ", what, " must be positive, got ", x));
  };
  auto non_negative = [](double x, const char* what) {
    if (!std::isfinite(x) || x < 0) throw InputError(str("closed loop: ", what, " must be >= 0, got ", x));
  };
  positive(o.control_rate, "control rate");
  positive(o.estimate_rate, "estimate rate");
  positive(o.loop.bandwidth, "rate-loop bandwidth");
  positive(o.loop.torque_limit, "torque limit");
  non_negative(o.noise.position, "position noise");
  non_negative(o.noise.attitude, "attitude noise");
  non_negative(o.noise.velocity, "velocity noise");
  non_negative(o.noise.angular_velocity, "spin noise");
  positive(o.rtol, "rtol");
  positive(o.atol, "atol");
  non_negative(o.record_every, "record interval");
}

/// What a tick records into the result (statuses, reference error).
inline void record_tick(const ControlCommand& cmd, ClosedLoopResult& res) {
  ++res.ticks;
  if (cmd.status == ControlStatus::Fault) ++res.fault_ticks;
  if (cmd.status == ControlStatus::Damped) ++res.damped_ticks;
  if (cmd.status == ControlStatus::RateLimited) ++res.rate_limited_ticks;
  res.max_reference_error = std::max(res.max_reference_error, (cmd.end_effector - cmd.reference).norm());
}

}  // namespace detail

/// Runs the closed loop of `ctrl` (see the notes after the includes) from the problem's initial state at rest
/// over [0, T]. InputError for bad options; IntegrationError from CVODE; NumericalError when the
/// controller faults. The controller's plan is changed by the estimates (update_target).
template <class Policy>
ClosedLoopResult simulate_closed_loop(CaptureController<Policy>& ctrl, const ClosedLoopOptions& o);

}  // namespace ffsr

#include "ffsr/control/detail/closed_loop.hxx"
