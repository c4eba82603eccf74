// ffsr/jobs/detail/post_capture.hpp -- the global run's post-capture constraints (max-time-to-rest,
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

/// The post-capture figures of one capture configuration that the constraints read: the run's summary
/// (at rest within detumble-horizon; time_to_rest the horizon when not at rest, infinity when not run).
struct PostCaptureFigures : DetumbleSummary {
  std::string failure;  ///< not run: the base actuator cannot stop the stack's spin
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
inline PostCaptureFigures post_capture_figures(const Model& model, int frame, DetumbleSettings settings,
                                               const BasePose& base, const Eigen::VectorXd& theta,
                                               const Target& target, double approach_speed) {
  PostCaptureFigures f;
  const GraspResult grasp = grasp_at_capture(model, frame, base, theta, target, approach_speed);
  const Model stack = attach_body(model, model.frame(frame).name, grasp.body);
  const DetumbleState start{base, theta, grasp.v_after, Vector3::Zero()};
  settings.run.record_every = 0;
  try {  // the run checks its feasibility first
    static_cast<DetumbleSummary&>(f) = run_detumble(stack, frame, grasp.body, start, settings);
  } catch (const DetumbleInfeasibleError& e) {
    f.failure = e.what();
    f.time_to_rest = std::numeric_limits<double>::infinity();
  }
  return f;
}

namespace detail {

/// InputError naming grasp-after (located in the file) when the scenario's stack holds its target
/// (grasp-after = held) and `what` starts from a capture instead.
inline void refuse_held(const Scenario& s, const std::string& what) {
  if (holds_target(s.keys))
    throw InputError(located_key_message(
        s.keys, str("--grasp-after: held starts from the scenario's start state (joints-deg, base-position, "
                    "base-rpy-deg and the start-* rates), and ",
                    what, " starts from a capture")));
}

}  // namespace detail

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
    detail::refuse_held(sc, "the global search's post-capture constraints");
    const std::string first =
        who.empty() ? constraints_.flags().substr(0, constraints_.flags().find('/')) : std::move(who);
    try {
      settings_ = detumble_settings(sc.keys, *model_);
    } catch (const InputError& e) {
      throw InputError(str(first,
                           ": the post-capture constraints need the post-capture run, and its keys "
                           "do not give it: ",
                           e.what()));
    }
    const Eigen::VectorXd& joint_torque = settings_.limits.joint_torque;
    if (constraints_.peak_joint_torque >= joint_torque.maxCoeff())
      throw InputError(str("--max-peak-joint-torque: ", constraints_.peak_joint_torque,
                           " N m is not below the largest joint torque limit (",
                           joint_torque.maxCoeff(),
                           " N m): the controller keeps every torque within its limit, so it cannot bind"));
    if (constraints_.time_to_rest > settings_.run.horizon)
      throw InputError(str("--max-time-to-rest: ", constraints_.time_to_rest,
                           " s is beyond detumble-horizon (", settings_.run.horizon,
                           " s), where the run stops"));
  }

  /// The figures at each configuration at `base`, on all cores (not counted).
  std::vector<PostCaptureFigures> figures(const BasePose& base,
                                          const std::vector<Eigen::VectorXd>& thetas) const {
    std::vector<PostCaptureFigures> f(thetas.size());
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    detail::parallel_for(thetas.size(), threads, [&](std::uint64_t i) {
      f[i] = post_capture_figures(*model_, frame_, settings_, base, thetas[i], target_, speed_);
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
    return post_capture_figures(*model_, frame_, settings_, base, theta, target_, speed_);
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
               evaluated_, " candidate runs, ", at_rest_, " at rest within detumble-horizon ",
               settings_.run.horizon,
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
  DetumbleSettings settings_;
  int evaluated_ = 0, admitted_ = 0, at_rest_ = 0;
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  PostCaptureFigures least_{{false, kNone, kNone, -1, kNone, kNone}, ""};
};

}  // namespace ffsr
