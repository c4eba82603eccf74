// ffsr/control/detumble_replay.hpp -- the independent checks of a post-capture plan on the host: the
// plan's controls, each held over its interval as planned, re-run by CVODE on the stack's full dynamics
// (ABA), then the detumbling controller holding the stack for the dwell (replay_detumble_plan); and the
// post-capture run with the plan-tracking controller (run_detumble_tracking). Needs SUNDIALS.
#pragma once

#include "ffsr/control/detumble_plan.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/control/detumble_tracker.hpp"

#include <string>
#include <vector>

namespace ffsr {

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

/// The post-capture run (run_detumble's: CVODE on the stack's ABA, the command held over each tick, the
/// dwell after the first tick at rest) with DetumblePlanTracker following `plan` from `start` (the plan's
/// start). Its errors are run_detumble's.
inline DetumbleRunResult run_detumble_tracking(const Model& stack, int gripper, const AttachedBody& body,
                                               const DetumbleState& start, const DetumblePlan& plan,
                                               const DetumbleLimits& limits, const DetumbleOptions& options,
                                               const DetumbleRunOptions& run) {
  detail::check_detumble_run(stack, gripper, body, start, run);
  detail::check_detumble(stack, limits, options, "run_detumble_tracking");
  check_detumble_tick(stack, gripper, start, run.tick);
  DetumblePlanTracker tracker(stack, gripper, body, plan, limits, options, run.tick);
  return detail::run_detumble_loop(
      stack, gripper, body, start, limits, options, run, tracker.make_command(),
      [&](const DetumbleState& s, double t, DetumbleCommand& c) { tracker.step(s, t, c); });
}

}  // namespace ffsr

#include "ffsr/control/detail/detumble_replay.hxx"
