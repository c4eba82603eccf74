// ffsr/jobs/detail/post_capture.hpp -- the post-capture phase of a scenario (its Detumble keys:
// detumble_settings) and the global run's post-capture constraints (max-time-to-rest,
// max-peak-joint-torque, max-gripper-force, max-gripper-moment): the grasp and the detumbling run at
// a candidate capture configuration, whether it meets them, and the best value the candidates reached.
// Component ffsr::scenario (and SUNDIALS: ffsr::cvode). docs/whole-capture.md.
#pragma once

#include "ffsr/algorithm/joint_models.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/detail/parallel.hpp"
#include "ffsr/model/attach.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace ffsr {

/// The limits and the law's settings of a scenario's Detumble keys for `model`: joint-torque-limit
/// (one value or one per joint; when not given, the URDF's <limit effort> of every joint), the base
/// actuator and its bounds (each needed by its actuator, refused without it, from a file too),
/// rest-rate-deg, stop-stack-spin. InputError naming the key.
inline void detumble_settings(const ScenarioKeys& k, const Model& model, DetumbleLimits& l,
                              DetumbleOptions& o) {
  using detail::str;
  for (const ScenarioKey& key : scenario_keys()) {  // the Detumble keys' own checks, and where they act
    if (key.group != KeyGroup::Detumble) continue;
    if (key.check) key.check(k);
    const std::string why = key.acts && k.given.count(key.name) ? key.acts(k) : "";
    if (!why.empty()) throw InputError(str("--", key.name, ": ", why));
  }
  if (k.joint_torque_limit.empty()) {
    l.joint_torque.resize(model.n());
    for (int j = 0; j < model.n(); ++j) {
      l.joint_torque(j) = model.joint(j).effort;
      if (!(l.joint_torque(j) > 0))
        throw InputError(
            str("--joint-torque-limit: not given, and the URDF gives no <limit effort> for joint '",
                model.joint(j).name, "'"));
    }
  } else {
    l.joint_torque = per_joint_values(k.joint_torque_limit, model, "--joint-torque-limit");
  }
  const auto needed = [&k](const char* name, double value) {
    if (!k.given.count(name))
      throw InputError(str("--", name, ": needed with base-actuator = ", k.base_actuator));
    return value;
  };
  if (k.base_actuator == "reaction-wheels") {
    l.actuator = BaseActuator::ReactionWheels;
    l.wheel_torque = needed("wheel-torque", k.wheel_torque);
    l.wheel_momentum = needed("wheel-momentum", k.wheel_momentum);
  } else if (k.base_actuator == "thrusters") {
    l.actuator = BaseActuator::Thrusters;
    l.thruster_force = needed("thruster-force", k.thruster_force);
    l.thruster_torque = needed("thruster-torque", k.thruster_torque);
  }
  o.rest_rate = k.rest_rate_deg * M_PI / 180.0;
  o.stop_stack_spin = k.stop_stack_spin;
}

/// The post-capture figures of one capture configuration that the constraints read.
struct PostCaptureFigures {
  bool at_rest = false;            ///< within detumble-horizon
  double time_to_rest = 0;         ///< s; the horizon when not at rest, infinity when not run
  double peak_joint_torque = 0;    ///< N m
  int peak_joint = -1;             ///< its joint (coordinate)
  double peak_gripper_force = 0;   ///< N
  double peak_gripper_moment = 0;  ///< N m
  std::string failure;             ///< not run: the base actuator cannot stop the stack's spin
};

/// The global run's post-capture constraints; 0: not set.
struct PostCaptureConstraints {
  double time_to_rest = 0, peak_joint_torque = 0, gripper_force = 0, gripper_moment = 0;
  bool any() const {
    return time_to_rest > 0 || peak_joint_torque > 0 || gripper_force > 0 || gripper_moment > 0;
  }
  /// The keys set, as flags joined by '/' ("--max-time-to-rest/--max-gripper-force").
  std::string flags() const {
    std::string out;
    const std::pair<double, const char*> keys[] = {{time_to_rest, "max-time-to-rest"},
                                                   {peak_joint_torque, "max-peak-joint-torque"},
                                                   {gripper_force, "max-gripper-force"},
                                                   {gripper_moment, "max-gripper-moment"}};
    for (const auto& [v, name] : keys)
      if (v > 0) out += (out.empty() ? "--" : "/--") + std::string(name);
    return out;
  }
};

/// The constraints a scenario's keys set.
inline PostCaptureConstraints post_capture_constraints(const ScenarioKeys& k) {
  return {k.max_time_to_rest, k.max_peak_joint_torque, k.max_gripper_force, k.max_gripper_moment};
}

/// Whether the figures meet the constraints: at rest within the horizon, each bound that is set.
inline bool meets(const PostCaptureFigures& f, const PostCaptureConstraints& c) {
  const auto within = [](double value, double bound) { return !(bound > 0) || value <= bound; };
  return f.at_rest && f.failure.empty() && within(f.time_to_rest, c.time_to_rest) &&
         within(f.peak_joint_torque, c.peak_joint_torque) && within(f.peak_gripper_force, c.gripper_force) &&
         within(f.peak_gripper_moment, c.gripper_moment);
}

/// The post-capture phase at (base, theta) as the detumble job runs it: grasp_at_capture (the contact
/// point moving at `approach_speed` along the target's normal, `target` its state at the capture),
/// the target attached at `frame`, run_detumble without series. Reads `model` only.
inline PostCaptureFigures post_capture_figures(const Model& model, int frame, const DetumbleLimits& limits,
                                               const DetumbleOptions& options, DetumbleRunOptions run,
                                               const BasePose& base, const Eigen::VectorXd& theta,
                                               const Target& target, double approach_speed) {
  PostCaptureFigures f;
  const GraspResult grasp = grasp_at_capture(model, frame, base, theta, target, approach_speed);
  const Model stack = attach_body(model, model.frame(frame).name, grasp.body);
  const DetumbleState start{base, theta, grasp.v_after, Vector3::Zero()};
  try {
    check_detumble_feasible(stack, start, limits, options, run.horizon);
  } catch (const InputError& e) {
    f.failure = e.what();
    f.time_to_rest = std::numeric_limits<double>::infinity();
    return f;
  }
  run.record_every = 0;
  const DetumbleRunResult r = run_detumble(stack, frame, grasp.body, start, limits, options, run);
  f.at_rest = r.at_rest;
  f.time_to_rest = r.time_to_rest;
  f.peak_joint_torque = r.peak_joint_torque;
  f.peak_joint = r.peak_joint;
  f.peak_gripper_force = r.peak_gripper_force;
  f.peak_gripper_moment = r.peak_gripper_moment;
  return f;
}

/// The post-capture constraints of a scenario as the global search's candidate constraint
/// (GlobalCaptureOptions::admit): each batch of candidates run in parallel (post_capture_figures),
/// the least value of each figure over every candidate kept for the message when none meets them.
class PostCaptureScreen {
 public:
  /// `target`: the target at the capture time. InputError naming the first constraint key when the
  /// Detumble keys do not give a post-capture run (no joint torque limit, say) or a bound cannot bind.
  /// `who`: the flag the errors name (default: the first constraint key).
  PostCaptureScreen(const Scenario& sc, const Target& target, std::string who = "")
      : model_(sc.model.get()),
        frame_(sc.problem.frame),
        target_(target),
        speed_(sc.problem.approach_speed),
        constraints_(post_capture_constraints(sc.keys)) {
    using detail::str;
    const std::string first =
        who.empty() ? constraints_.flags().substr(0, constraints_.flags().find('/')) : std::move(who);
    try {
      detumble_settings(sc.keys, *model_, limits_, options_);
    } catch (const InputError& e) {
      throw InputError(str(first,
                           ": the post-capture constraints need the post-capture run, and its keys "
                           "do not give it: ",
                           e.what()));
    }
    run_.tick = sc.keys.detumble_tick;
    run_.horizon = sc.keys.detumble_horizon;
    if (constraints_.peak_joint_torque >= limits_.joint_torque.maxCoeff())
      throw InputError(str("--max-peak-joint-torque: ", constraints_.peak_joint_torque,
                           " N m is not below the largest joint torque limit (",
                           limits_.joint_torque.maxCoeff(),
                           " N m): the controller keeps every torque within its limit, so it cannot bind"));
    if (constraints_.time_to_rest > run_.horizon)
      throw InputError(str("--max-time-to-rest: ", constraints_.time_to_rest,
                           " s is beyond detumble-horizon (", run_.horizon, " s), where the run stops"));
  }

  /// The figures at each configuration at `base`, on all cores (not counted).
  std::vector<PostCaptureFigures> figures(const BasePose& base,
                                          const std::vector<Eigen::VectorXd>& thetas) const {
    std::vector<PostCaptureFigures> f(thetas.size());
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    detail::parallel_for(thetas.size(), threads, [&](std::uint64_t i) {
      f[i] = post_capture_figures(*model_, frame_, limits_, options_, run_, base, thetas[i], target_, speed_);
    });
    return f;
  }

  std::vector<char> operator()(const BasePose& base, const std::vector<Eigen::VectorXd>& thetas) {
    const std::vector<PostCaptureFigures> f = figures(base, thetas);
    std::vector<char> ok(thetas.size());
    for (size_t i = 0; i < f.size(); ++i) {
      ok[i] = meets(f[i], constraints_);
      account(f[i], ok[i] != 0);
    }
    return ok;
  }

  /// The figures at one configuration (not counted).
  PostCaptureFigures figures(const BasePose& base, const Eigen::VectorXd& theta) const {
    return post_capture_figures(*model_, frame_, limits_, options_, run_, base, theta, target_, speed_);
  }

  const PostCaptureConstraints& constraints() const { return constraints_; }
  int evaluated() const { return evaluated_; }
  int admitted() const { return admitted_; }

  /// Why no candidate met the constraints: the keys, the candidates run, the least value reached of
  /// each constrained figure beside its bound.
  std::string shortfall() const {
    using detail::str;
    std::string best;
    const auto add = [&best](double bound, const char* what, double value, const char* unit) {
      if (!(bound > 0)) return;
      std::ostringstream o;
      o << std::setprecision(4) << (best.empty() ? "" : ", ") << what << " " << value << " " << unit
        << " (limit " << bound << ")";
      best += o.str();
    };
    add(constraints_.time_to_rest, "time to rest", least_.time_to_rest, "s");
    add(constraints_.peak_joint_torque, "peak joint torque", least_.peak_joint_torque, "N m");
    add(constraints_.gripper_force, "peak gripper force", least_.peak_gripper_force, "N");
    add(constraints_.gripper_moment, "peak gripper moment", least_.peak_gripper_moment, "N m");
    return str(constraints_.flags(),
               ": no capture configuration of the global search meets the post-capture ", "constraints (",
               evaluated_, " candidate runs, ", at_rest_, " at rest within detumble-horizon ", run_.horizon,
               " s); the least each candidate reached: ", best);
  }

 private:
  void account(const PostCaptureFigures& f, bool ok) {
    ++evaluated_;
    admitted_ += ok;
    if (!f.failure.empty()) return;
    at_rest_ += f.at_rest;
    if (f.at_rest) least_.time_to_rest = std::min(least_.time_to_rest, f.time_to_rest);
    least_.peak_joint_torque = std::min(least_.peak_joint_torque, f.peak_joint_torque);
    least_.peak_gripper_force = std::min(least_.peak_gripper_force, f.peak_gripper_force);
    least_.peak_gripper_moment = std::min(least_.peak_gripper_moment, f.peak_gripper_moment);
  }

  const Model* model_;  ///< the scenario's, which outlives the search
  int frame_;
  Target target_;
  double speed_;
  PostCaptureConstraints constraints_;
  DetumbleLimits limits_;
  DetumbleOptions options_;
  DetumbleRunOptions run_;
  int evaluated_ = 0, admitted_ = 0, at_rest_ = 0;
  PostCaptureFigures least_{
      false, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
      -1,    std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
      ""};
};

}  // namespace ffsr
