// ffsr/control/detumble_run.hpp -- the post-capture run: the grasp at the end of the approach, then the
// stack's full dynamics (ABA on the stack model) integrated with CVODE, the detumbling controller in the
// loop at a fixed tick (its command held over the tick), the series and its summary.
#pragma once

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/algorithm/grasp.hpp"
#include "ffsr/control/detumble_controller.hpp"
#include "ffsr/control/detumble_dynamics.hpp"
#include "ffsr/simulate/cvode.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <string>
#include <vector>

namespace ffsr {

/// The run's settings.
struct DetumbleRunOptions {
  double tick = 0.01;    ///< control period, s
  double horizon = 120;  ///< longest time to rest, s
  double dwell = 5;      ///< after the first tick at rest, the run goes on (holding) this long, s (>= 0)
  int record_every = 1;  ///< keep every k-th tick in the series (0: none)
  double rtol = 1e-12;   ///< CVODE
  double atol = 1e-15;   ///< CVODE, on positions, angles, rates and wheel momentum
};

/// Everything a post-capture run takes beside the stack and its start: the hardware's bounds, the law's
/// settings and the run's. A scenario's Detumble keys build it in one place (detumble_settings,
/// scenario/scenario.hpp); the detumble job, the global search's post-capture constraints and the
/// results hold it as built.
struct DetumbleSettings {
  DetumbleLimits limits;
  DetumbleOptions options;
  DetumbleRunOptions run;
};

/// One recorded tick (inertial frame unless said).
struct DetumbleSample {
  double t = 0;
  BasePose base;          ///< the base's pose
  Eigen::VectorXd theta;  ///< joint angles, rad
  Eigen::VectorXd theta_dot;
  /// the controller's command at the tick, held over it: the joint torques, the actuator's wrench
  /// about the base origin, the rates it measured (joint, gripper relative to the base, stack), status
  DetumbleCommand command;
  Vector3 gripper_force = Vector3::Zero();   ///< on the target by the gripper, N
  Vector3 gripper_moment = Vector3::Zero();  ///< the same, moment about the contact point, N m
  double base_attitude = 0;                  ///< rotation of the base since the grasp, rad
  Vector3 wheel_momentum = Vector3::Zero();  ///< stored in the wheels, base frame, N m s
  double energy = 0;                         ///< the stack's kinetic energy, J
  Vector6 momentum = Vector6::Zero();        ///< stack + wheels [P; L about o]
};

/// The figures of a post-capture run that a constraint or a table reads: the run's result holds them,
/// the global search's post-capture figures (jobs/detail/post_capture.hpp) too.
struct DetumbleSummary {
  bool at_rest = false;
  double time_to_rest = 0;         ///< first tick at rest (the horizon if never)
  double peak_joint_torque = 0;    ///< N m
  int peak_joint = -1;             ///< its joint (coordinate)
  double peak_gripper_force = 0;   ///< N
  double peak_gripper_moment = 0;  ///< N m
};

struct DetumbleRunResult : DetumbleSummary {
  /// the hold after rest: the largest rate (joint, gripper relative to the base and, with
  /// stop_stack_spin, the stack's) over the dwell's ticks, and whether every one was at rest
  double dwell_peak_rate = 0;
  bool dwell_at_rest = false;
  double base_attitude_excursion = 0;            ///< largest rotation of the base since the grasp, rad
  double peak_wheel_momentum = 0;                ///< largest stored component, N m s
  Vector3 wheel_momentum_end = Vector3::Zero();  ///< base frame
  double momentum_drift = 0;  ///< largest |h(t) - h(0)| / |h(0)| (stack + wheels; not with thrusters)
  double energy_start = 0, energy_end = 0;
  double joint_work = 0;  ///< sum over ticks of tau . (theta(t+) - theta(t)): exact for held torques
  double max_energy_balance =
      0;  ///< largest |T_k+1 - T_k - W_k| / T(0) over the ticks (without wheels/thrusters)
  long ticks = 0, steps = 0, faults = 0;
  std::vector<DetumbleSample> series;
};

/// The grasp at the end of the approach: the robot at (base, theta) with its contact point moving at
/// `approach_speed` along the target's normal under zero total momentum (approach_joint_rates, as the
/// multibody contact run starts), the target (its state at the capture) placed with its contact point
/// on the frame's origin. Returns grasp() of that state.
inline GraspResult grasp_at_capture(const Model& model, int frame, const BasePose& base,
                                    const Eigen::VectorXd& theta, Target target, double approach_speed) {
  Data d(model);
  forward_kinematics(model, d, base, theta);
  const Eigen::VectorXd qd =
      approach_joint_rates(model, d, base, theta, frame, target.normal_world(), approach_speed);
  Eigen::VectorXd v(model.nv());
  v << base_velocity_from_momentum(model, d, qd), qd;
  target.position = frame_pose(model, d, frame).p - target.offset_world();
  return grasp(model, d, base, theta, v, frame, target);
}


/// The bound that cannot stop the stack's spin (DetumbleInfeasibleError::bound).
enum class DetumbleBound {
  Actuator,        ///< no base actuator (the stack's angular momentum is conserved)
  WheelMomentum,   ///< the reaction wheels cannot store the stack's angular momentum
  ActuatorTorque,  ///< the actuator's torque (wheels or thrusters) needs longer than the horizon
  Tick,            ///< the tick is longer than the stack's fastest rate allows (detumble_longest_tick)
};

/// check_detumble_feasible's refusal: an InputError that says which bound is too small, so that a
/// caller can name the setting of that bound.
class DetumbleInfeasibleError : public InputError {
 public:
  DetumbleInfeasibleError(DetumbleBound b, const std::string& what) : InputError(what), bound(b) {}
  DetumbleBound bound;
};

/// The largest angle (rad) the stack may turn in one tick at its fastest rate: the command is held over
/// the tick, computed from the state at its start (the velocity terms, the hold, the gripper's load).
inline constexpr double kDetumbleTickAngle = 0.15;

/// The stack's fastest rate at `s` (rad/s): the largest joint rate, the gripper's angular rate relative
/// to the base, the base's angular rate; and which (`what`: "joint 'name'", "the gripper relative to
/// the base", "the base").
inline double detumble_fastest_rate(const Model& stack, int gripper, const DetumbleState& s, std::string* what) {
  const int n = stack.n();
  Data d(stack);
  forward_kinematics(stack, d, s.base, s.theta);
  frame_jacobian(stack, d, gripper);
  const Vector3 wrel = d.J.bottomRows<3>().rightCols(n) * s.v.tail(n);
  Eigen::Index k = 0;
  const double joint = n > 0 ? s.v.tail(n).cwiseAbs().maxCoeff(&k) : 0.0;
  const double rel = wrel.norm(), base = s.v.segment<3>(3).norm();
  const double fastest = std::max({joint, rel, base});
  if (what)
    *what = fastest == joint  ? detail::str("joint '", stack.joint(static_cast<int>(k)).name, "'")
            : fastest == rel ? std::string("the gripper relative to the base")
                             : std::string("the base");
  return fastest;
}

/// The longest tick the law supports from `s`: kDetumbleTickAngle over the stack's fastest rate
/// (infinity at rest). Under the law the rates fall from the start.
inline double detumble_longest_tick(const Model& stack, int gripper, const DetumbleState& s) {
  const double w = detumble_fastest_rate(stack, gripper, s, nullptr);
  return w > 0 ? kDetumbleTickAngle / w : std::numeric_limits<double>::infinity();
}

/// Refuses a tick longer than detumble_longest_tick with DetumbleInfeasibleError (DetumbleBound::Tick).
inline void check_detumble_tick(const Model& stack, int gripper, const DetumbleState& s, double tick) {
  std::string what;
  const double w = detumble_fastest_rate(stack, gripper, s, &what);
  if (tick * w <= kDetumbleTickAngle) return;
  throw DetumbleInfeasibleError(
      DetumbleBound::Tick,
      detail::str("detumble: the tick, ", tick, " s, is longer than the ", kDetumbleTickAngle / w,
                  " s this stack supports: the command is held over a tick, and at its fastest rate (",
                  what, ", ", w, " rad/s) the stack would turn more than ", kDetumbleTickAngle, " rad in one"));
}

/// Refuses a run that cannot stop the stack's spin, with DetumbleInfeasibleError naming L_c, the stack's
/// angular momentum about its centre of mass: without an actuator (L_c is conserved), with wheels that
/// cannot store it (|L_c| above sqrt(3) times the bound per axis), or when removing it needs longer than
/// the horizon at the actuator's largest torque (|L_c| / (sqrt(3) t_max)).
inline void check_detumble_feasible(const Model& stack, const DetumbleState& s, const DetumbleLimits& l,
                                    const DetumbleOptions& o, double horizon) {
  if (!o.stop_stack_spin) return;
  Data d(stack);
  crba(stack, d, s.base, s.theta);
  const double L = centroidal_momentum(stack, d, s.v).angular.norm();
  if (l.actuator == BaseActuator::None)
    throw DetumbleInfeasibleError(
        DetumbleBound::Actuator,
        detail::str("detumble: the stack's spin cannot be stopped without a base actuator: its "
                    "angular momentum about its centre of mass, ",
                    L, " N m s, is conserved (name reaction wheels or thrusters)"));
  const double tmax = l.actuator == BaseActuator::ReactionWheels ? l.wheel_torque : l.thruster_torque;
  const double axes = std::sqrt(3.0);
  if (l.actuator == BaseActuator::ReactionWheels && L > axes * l.wheel_momentum)
    throw DetumbleInfeasibleError(
        DetumbleBound::WheelMomentum,
        detail::str("detumble: the reaction wheels cannot store the stack's angular momentum: ", L,
                    " N m s about its centre of mass, at most ", axes * l.wheel_momentum, " N m s (",
                    l.wheel_momentum, " per axis)"));
  if (L / (axes * tmax) > horizon)
    throw DetumbleInfeasibleError(
        DetumbleBound::ActuatorTorque,
        detail::str("detumble: the base actuator's torque (", tmax, " N m per axis) needs at least ",
                    L / (axes * tmax), " s to remove the stack's angular momentum ", L,
                    " N m s; the horizon is ", horizon, " s"));
}

/// The post-capture run from `start` (the grasp's state on the stack model; see the top of the file).
/// `gripper` is the frame carrying `body` (the grasped target). The controller's command is computed
/// at each tick and held until the next; the run goes on for `run.dwell` after the first tick at rest
/// (the controller holding the stack), or stops at the horizon.
/// InputError for bad options; DetumbleInfeasibleError (check_detumble_feasible, run once) when the
/// actuator cannot stop the stack's spin within the horizon; IntegrationError from CVODE.
inline DetumbleRunResult run_detumble(const Model& stack, int gripper, const AttachedBody& body,
                                      const DetumbleState& start, const DetumbleLimits& limits,
                                      const DetumbleOptions& options, const DetumbleRunOptions& run);
/// The same with the settings as one value.
inline DetumbleRunResult run_detumble(const Model& stack, int gripper, const AttachedBody& body,
                                      const DetumbleState& start, const DetumbleSettings& settings) {
  return run_detumble(stack, gripper, body, start, settings.limits, settings.options, settings.run);
}

}  // namespace ffsr

#include "ffsr/control/detail/detumble_run.hxx"
