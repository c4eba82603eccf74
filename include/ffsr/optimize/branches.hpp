// ffsr/optimize/branches.hpp -- the branches of the capture manifold as a user sees them: each
// distinct local optimum of a manifold search (search_capture_manifold, global.hpp) with its M_ie,
// its objective, its orientation error and whether the approach reaches it from the initial
// configuration without a reconfiguration (docs/branches.md).
#pragma once

#include "ffsr/detail/parallel.hpp"
#include "ffsr/optimize/global.hpp"

#include <algorithm>
#include <cmath>
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

namespace detail {

/// Puts the ties of a search's sorted local optima in a fixed order (docs/branches.md): neighbours whose
/// M_ie and objective are both within a relative 1e-9 are tied (the optima of a joint the objective
/// does not depend on differ only by SLSQP's roundoff, ~1e-11), and tied optima go by configuration,
/// joint by joint, a joint's values within 1e-5 (rad or m) counting as equal (SLSQP leaves ~1e-7 rad).
/// So rounding-level changes keep the order. The rest of the order stays (by objective; multibody-force:
/// by M_ie). Insertion sort: the tolerance comparison is not a strict weak order, and ties are few.
inline void order_ties(std::vector<ManifoldPoint>& p) {
  const auto close = [](double a, double b) {
    return std::abs(b - a) <= 1e-9 * std::max(std::abs(a), std::abs(b));
  };
  const auto tied = [&](const ManifoldPoint& a, const ManifoldPoint& b) {
    return close(a.M_ie, b.M_ie) && close(a.objective, b.objective);
  };
  const auto before = [](const ManifoldPoint& a, const ManifoldPoint& b) {
    for (Eigen::Index i = 0; i < std::min(a.theta.size(), b.theta.size()); ++i)
      if (std::abs(a.theta(i) - b.theta(i)) > 1e-5) return a.theta(i) < b.theta(i);
    return false;
  };
  for (size_t first = 0; first < p.size();) {
    size_t end = first + 1;
    while (end < p.size() && tied(p[end - 1], p[end])) ++end;
    for (size_t i = first + 1; i < end; ++i)
      for (size_t j = i; j > first && before(p[j], p[j - 1]); --j) std::swap(p[j], p[j - 1]);
    first = end;
  }
}

}  // namespace detail

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
/// same order but for ties, which go in a fixed order (order_ties): the orientation and position
/// errors at `base`, and for the best `max_tested` whether the approach reaches each from the initial
/// configuration (reaches_without_reconfiguration; one run each, on `threads` threads). Reads the
/// model; runs crba per branch.
inline std::vector<CaptureBranch> capture_branches(const CaptureProblem& pb, const CaptureTask& task,
                                                   const CaptureOptions& opt, const CaptureSetup& setup,
                                                   const ManifoldSearchResult& search, const BasePose& base,
                                                   int max_tested = 6, unsigned threads = 1) {
  const Model& model = *pb.model;
  Data data(model);
  std::vector<CaptureBranch> out;
  std::vector<ManifoldPoint> optima = search.local_optima;
  detail::order_ties(optima);
  for (const ManifoldPoint& p : optima) {
    CaptureBranch b;
    b.theta = p.theta;
    b.M_ie = p.M_ie;
    b.objective = p.objective;
    crba(model, data, base, p.theta);
    const Pose ee = frame_pose(model, data, pb.frame);
    b.orientation_error =
        task.kind == CaptureTask::Kind::Pose ? rotation_angle(setup.capture.R_end * ee.R.transpose()) : 0.0;
    double e2 = 0;  // the task's position rows only (a planar task leaves z free)
    for (int r : setup.rows)
      if (r < 3) e2 += (ee.p(r) - setup.capture.x_cap(r)) * (ee.p(r) - setup.capture.x_cap(r));
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
