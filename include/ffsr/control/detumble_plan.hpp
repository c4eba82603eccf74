// ffsr/control/detumble_plan.hpp -- a post-capture plan (the time-optimal planner's result,
// control/detumble_planner.hpp): its nodes and each interval's controls, the command of an interval,
// and the check of a plan's shape. Part of the onboard core (Eigen only): the plan-tracking controller
// (control/detumble_tracker.hpp) takes one; its re-run by CVODE is control/detumble_replay.hpp.
#pragma once

#include "ffsr/control/detumble_controller.hpp"

#include <algorithm>
#include <cmath>
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
  /// T of the plan with free intervals when this one was solved again on the controller's tick's grid
  /// (DetumblePlanOptions::tick), 0 when not; its iterations are counted in `iterations`
  double free_duration = 0;
  int substeps = 0;  ///< the planner's RK4 steps per interval (more than asked when a re-run missed rest)
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

namespace detail {

/// Throws InputError naming `w` unless the plan has N >= 1 intervals of a positive finite duration, N + 1
/// nodes, N finite joint torques of the stack's size and N finite base wrenches.
inline void check_detumble_plan(const Model& stack, const DetumblePlan& plan, const char* w) {
  const int N = plan.intervals();
  if (N < 1) FFSR_THROW(InputError(str(w, ": the plan has no interval")));
  if (!std::isfinite(plan.duration) || !(plan.duration > 0))
    FFSR_THROW(InputError(str(w, ": the plan's duration must be positive and finite, got ", plan.duration)));
  if (plan.nodes.size() != static_cast<size_t>(N) + 1 || plan.base_wrench.size() != static_cast<size_t>(N))
    FFSR_THROW(InputError(str(w, ": the plan needs N + 1 nodes and N base wrenches for its N = ", N,
                         " intervals, got ", plan.nodes.size(), " and ", plan.base_wrench.size())));
  for (int k = 0; k < N; ++k) {
    require_size(plan.tau[static_cast<size_t>(k)].size(), stack.n(), w, "the plan's joint torques");
    require_finite_all(plan.tau[static_cast<size_t>(k)], w, "the plan's joint torques");
    require_finite_all(plan.base_wrench[static_cast<size_t>(k)], w, "the plan's base wrench");
  }
}

}  // namespace detail

}  // namespace ffsr
