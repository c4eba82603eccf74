// ffsr/control/detumble_plan.hpp -- a post-capture plan (the time-optimal planner's result,
// control/detumble_planner.hpp) and its independent check: the plan's controls, each held over its
// interval as planned, re-run by CVODE on the stack's full dynamics (ABA), then the detumbling
// controller holding the stack for the dwell. Needs SUNDIALS only (the planner needs IPOPT).
#pragma once

#include "ffsr/control/detumble_run.hpp"

#include <string>
#include <vector>

namespace ffsr {

/// A plan on N intervals of equal length duration / N. Interval k holds its controls from t_k = k h to
/// t_k+1: the joint torques, and the base actuator's command in the base frame (thrusters: force and
/// moment about the base origin; reaction wheels: the torque on the base), held in the base frame (the
/// actuators turn with the base). The states are the plan's own (its integration of the dynamics).
struct DetumblePlan {
  double duration = 0;               ///< T, s: the stack at rest at T
  std::vector<DetumbleState> nodes;  ///< N + 1: the states at t_k (nodes[0] the start)
  std::vector<Eigen::VectorXd> tau;  ///< N: joint torques, N m
  std::vector<Vector6> base_wrench;  ///< N: [force; moment] in the base frame (zero without thrusters/wheels)
  /// the solver's account
  std::string status;          ///< IPOPT's return status ("Solve_Succeeded", ...)
  int iterations = 0;
  double constraint_violation = 0;  ///< the largest residual of the dynamics and path constraints
  double solve_seconds = 0;         ///< wall time of the solve (the warm start's run included)
  double warm_start_duration = 0;   ///< T of the initial guess (the feedback law's time to rest)
  int intervals() const { return static_cast<int>(tau.size()); }
  double interval() const { return intervals() > 0 ? duration / intervals() : 0.0; }
  /// the interval holding time t (the last one from T on)
  int interval_at(double t) const {
    const int N = intervals();
    const int k = static_cast<int>(std::floor(t / interval() + 1e-9));
    return std::clamp(k, 0, N - 1);
  }
};

/// The command of interval k at the state y (base orientation from y): joint torques, and the base
/// wrench in the inertial frame about the base origin, as the stack's ODE takes it.
inline void plan_command(const DetumblePlan& plan, int k, const Quaternion& base_orientation,
                         DetumbleCommand& c) {
  c.tau = plan.tau[static_cast<size_t>(k)];
  const Matrix3 R = base_orientation.normalized().toRotationMatrix();
  const Vector6& w = plan.base_wrench[static_cast<size_t>(k)];
  c.base_wrench << R * w.head<3>(), R * w.tail<3>();
}

/// The plan re-run (replay_detumble_plan): the series (one sample per tick, the plan's end, then the
/// dwell under the detumbling controller) and its summary; at_rest and time_to_rest are the rest test
/// at the plan's end T (every rate, and with stop_stack_spin the base's twist, at most rest_rate).
struct DetumblePlanRun : DetumbleRunResult {
  double end_joint_rate = 0;    ///< largest |qd| at T
  double end_base_rate = 0;     ///< |angular velocity of the base| at T
  double end_base_speed = 0;    ///< |velocity of the base origin| at T
  double end_relative_rate = 0; ///< |angular velocity of the gripper relative to the base| at T
  /// the largest excess over the bounds along the re-run's samples (joint torque, actuator per axis,
  /// wheel momentum per axis, gripper force and moment): <= 0 when every bound holds
  double worst_bound_excess = 0;
};

namespace detail {

/// The rates of the state y (the command's joint_rate, relative_rate, stack_rate fields) and the rest
/// test; the model's kinematics at y must be current in `d`.
inline void plan_rates(const Model& stack, Data& d, int gripper, const Eigen::VectorXd& v,
                       DetumbleCommand& c) {
  const int n = stack.n();
  frame_jacobian(stack, d, gripper);
  c.joint_rate = n > 0 ? v.tail(n).cwiseAbs().maxCoeff() : 0.0;
  c.relative_rate = (d.J.bottomRows<3>().rightCols(n) * v.tail(n)).norm();
  c.stack_rate = v.segment<3>(3).norm();
}

}  // namespace detail

/// Re-runs `plan` from its start node: CVODE on the stack's full dynamics (ABA) with each interval's
/// controls held (the joint torques, the actuator's wrench in the base frame, plan_command), a sample
/// every `run.tick` and at T; then, for `run.dwell`, the detumbling controller under `limits` and
/// `options` holding the stack. The summary's bounds are measured on the samples. InputError for a bad
/// plan or options; IntegrationError from CVODE.
inline DetumblePlanRun replay_detumble_plan(const Model& stack, int gripper, const AttachedBody& body,
                                            const DetumblePlan& plan, const DetumbleLimits& limits,
                                            const DetumbleOptions& options, const DetumbleRunOptions& run);

}  // namespace ffsr

#include "ffsr/control/detail/detumble_plan.hxx"
