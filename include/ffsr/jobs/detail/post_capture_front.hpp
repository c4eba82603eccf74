// ffsr/jobs/detail/post_capture_front.hpp -- the post-capture axes of the job `pareto` (--axis
// time-to-rest, peak-joint-torque, gripper-force, gripper-moment): the non-dominated set of (M_ie, a
// figure of the detumble run) over a candidate set at the global run's base pose (docs/whole-capture.md).
#pragma once

#include "ffsr/jobs/detail/post_capture.hpp"
#include "ffsr/optimize/pareto.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace ffsr {

/// A candidate capture configuration with its post-capture figures and the axis' value.
struct PostCaptureFrontPoint {
  ParetoPoint point;  ///< theta, M_ie and the impact's base rate at the front's base pose
  PostCaptureFigures figures;
  double value = 0;  ///< the axis' figure (s, N m or N)
};

/// The non-dominated set of (M_ie, value) over the candidates: the global search's local optima (every
/// branch) and the points of the (M_ie, base rate) sweep, each run through the post-capture phase.
struct PostCaptureFront {
  std::string axis;
  std::vector<PostCaptureFrontPoint> points;  ///< non-dominated, M_ie increasing (value decreasing)
  size_t knee = 0;                            ///< index in points
  int candidates = 0, at_rest = 0;            ///< candidate runs, and those at rest within the horizon
  std::vector<PostCaptureFrontPoint> runs;    ///< the plain, paper's-method and global runs
};

namespace detail {

/// The axes of `pareto` (base-rate: the impact's, ParetoFront) and their units.
inline const std::vector<std::string>& pareto_axes() {
  static const std::vector<std::string> a{"base-rate", "time-to-rest", "peak-joint-torque", "gripper-force",
                                          "gripper-moment"};
  return a;
}
inline const char* pareto_axis_unit(const std::string& axis) {
  return axis == "time-to-rest" ? "s" : axis == "gripper-force" ? "N" : axis == "base-rate" ? "deg/s" : "N m";
}
inline void check_pareto_axis(const std::string& axis) {
  const auto& a = pareto_axes();
  if (std::find(a.begin(), a.end(), axis) == a.end())
    throw InputError(
        str("--axis: expected base-rate, time-to-rest, peak-joint-torque, gripper-force or "
            "gripper-moment, got '",
            axis, "'"));
}

/// The axis' figure; infinity when the run is not at rest (such a candidate is on no front).
inline double post_capture_value(const PostCaptureFigures& f, const std::string& axis) {
  if (!f.at_rest || !f.failure.empty()) return std::numeric_limits<double>::infinity();
  return axis == "time-to-rest"        ? f.time_to_rest
         : axis == "peak-joint-torque" ? f.peak_joint_torque
         : axis == "gripper-force"     ? f.peak_gripper_force
                                       : f.peak_gripper_moment;
}

/// The knee of a front sorted by M_ie: the point farthest from the line through its ends, in the
/// objectives normalized by the ends' spans (0 with fewer than three points).
inline size_t post_capture_knee(const std::vector<PostCaptureFrontPoint>& p) {
  if (p.size() < 3) return 0;
  const double m0 = p.front().point.M_ie, m1 = p.back().point.M_ie, v0 = p.front().value, v1 = p.back().value;
  size_t knee = 0;
  double far = -1;
  for (size_t i = 0; i < p.size(); ++i) {
    const double x = (p[i].point.M_ie - m0) / (m1 - m0), y = (p[i].value - v1) / (v0 - v1);
    const double d = std::abs(x + y - 1) / std::sqrt(2.0);  // the ends are (0, 1) and (1, 0)
    if (d > far) {
      far = d;
      knee = i;
    }
  }
  return knee;
}

}  // namespace detail

/// The front of `axis` at `base`: each candidate (restitution `e` for the base rate) run through the
/// post-capture phase by `screen`, the non-dominated set of (M_ie, value) over those at rest (a value
/// equal to a lower-M_ie point's within 1e-9 relative is dominated). Runs crba per candidate.
inline PostCaptureFront post_capture_front(const Scenario& sc, const CaptureSetup& setup,
                                           const PostCaptureScreen& screen, const std::string& axis,
                                           const BasePose& base, const std::vector<Eigen::VectorXd>& thetas,
                                           double e) {
  PostCaptureFront out;
  out.axis = axis;
  const std::vector<PostCaptureFigures> f = screen.figures(base, thetas);
  Data data(*sc.model);
  std::vector<PostCaptureFrontPoint> all;
  for (size_t i = 0; i < thetas.size(); ++i) {
    ++out.candidates;
    const double v = detail::post_capture_value(f[i], axis);
    if (!std::isfinite(v)) continue;
    ++out.at_rest;
    all.push_back({detail::pareto_point(*sc.model, data, sc.problem, setup, base, thetas[i], e), f[i], v});
  }
  if (all.empty())
    throw InputError(detail::str("--axis: no candidate of the ", axis,
                                 " front is at rest within detumble-horizon (", out.candidates,
                                 " candidate runs)"));
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& a, const auto& b) { return a.point.M_ie < b.point.M_ie; });
  for (const PostCaptureFrontPoint& p : all)
    if (out.points.empty() || p.value < out.points.back().value * (1 - 1e-9)) out.points.push_back(p);
  out.knee = detail::post_capture_knee(out.points);
  return out;
}

}  // namespace ffsr
