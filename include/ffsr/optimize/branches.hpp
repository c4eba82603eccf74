// ffsr/optimize/branches.hpp -- the branches of the capture manifold as a user sees them: each
// distinct local optimum of a manifold search (search_capture_manifold, global.hpp) with its M_ie,
// its objective, its orientation error and whether the approach reaches it from the initial
// configuration without a reconfiguration (docs/branches.md).
#pragma once

#include "ffsr/detail/parallel.hpp"
#include "ffsr/optimize/global.hpp"

#include <optional>
#include <vector>

// Reachable without reconfiguration: the reaching run of the global planner (the straight-line
// approach with the null space servoing to the branch, ServoPolicy, with the joint-rate limit of the
// options) from the initial configuration ends within 0.5 rad (every joint, configuration_distance)
// of the branch and stays within the joint limits. This is the test plan_capture_global's first
// shooting iteration applies to a goal: a run that ends on another component of the self-motion
// manifold (or, without a null space, on another inverse-kinematics solution) ends far from it.
// Cost: one integrate_capture per branch tested (the best `max_tested` branches; the rest are
// reported as not tested), on `threads` threads.

namespace ffsr {

/// One distinct local optimum of the capture manifold.
struct CaptureBranch {
  Eigen::VectorXd theta;         ///< rad
  double M_ie = 0;               ///< kg
  double objective = 0;          ///< as ManifoldPoint::objective
  double orientation_error = 0;  ///< angle between the end-effector's and the wanted orientation, rad
  double position_error = 0;     ///< distance from the capture point over the task's axes, m
  /// empty: not tested (beyond the best max_tested of capture_branches)
  std::optional<bool> reachable_without_reconfiguration;
};

/// Does the reaching run (see the notes after the includes) from pb.theta end on `goal`? Runs
/// integrate_capture once (series off); joint-limit and tracking failures count as not reached.
inline bool reaches_without_reconfiguration(const CaptureProblem& pb, const CaptureTask& task,
                                            const CaptureOptions& opt, const CaptureSetup& setup,
                                            const Eigen::VectorXd& goal) {
  CaptureOptions quiet = opt;
  quiet.record_series = false;
  quiet.progress = nullptr;
  quiet.gain = 0.0;
  ServoPolicy servo;
  servo.theta_goal = goal;
  try {
    const CaptureResult run = integrate_capture(pb, task, quiet, setup, servo, "capture_branches");
    return detail::configuration_distance(*pb.model, run.theta, goal) <= 0.5;
  } catch (const NumericalError&) {
    return false;
  }
}

/// The local optima of `search` (made at base pose `base`, sorted by objective) as branches, in the
/// same order: the orientation and position errors at `base`, and for the best `max_tested`
/// whether the approach reaches each from the initial configuration (reaches_without_reconfiguration;
/// one run each, on `threads` threads). Reads the model; runs crba per branch.
inline std::vector<CaptureBranch> capture_branches(const CaptureProblem& pb, const CaptureTask& task,
                                                   const CaptureOptions& opt, const CaptureSetup& setup,
                                                   const ManifoldSearchResult& search, const BasePose& base,
                                                   int max_tested = 6, unsigned threads = 1) {
  const Model& model = *pb.model;
  Data data(model);
  std::vector<CaptureBranch> out;
  for (const ManifoldPoint& p : search.local_optima) {
    CaptureBranch b;
    b.theta = p.theta;
    b.M_ie = p.M_ie;
    b.objective = p.objective;
    crba(model, data, base, p.theta);
    const Pose ee = frame_pose(model, data, pb.frame);
    b.orientation_error =
        task.kind == CaptureTask::Kind::Pose ? rotation_angle(setup.R_end * ee.R.transpose()) : 0.0;
    double e2 = 0;  // the task's position rows only (a planar task leaves z free)
    for (int r : setup.rows)
      if (r < 3) e2 += (ee.p(r) - setup.x_cap(r)) * (ee.p(r) - setup.x_cap(r));
    b.position_error = std::sqrt(e2);
    out.push_back(std::move(b));
  }
  const size_t tested = std::min(out.size(), static_cast<size_t>(std::max(max_tested, 0)));
  std::vector<char> reached(tested, 0);
  detail::parallel_for(tested, threads, [&](std::uint64_t i) {
    reached[i] = reaches_without_reconfiguration(pb, task, opt, setup, out[i].theta);
  });
  for (size_t i = 0; i < tested; ++i) out[i].reachable_without_reconfiguration = reached[i] != 0;
  return out;
}

}  // namespace ffsr
