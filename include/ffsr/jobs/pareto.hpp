// ffsr/jobs/pareto.hpp -- the job `pareto`: the front of (M_ie, base angular rate jump at the impact) on
// the capture manifold at the global run's base pose (ffsr/optimize/pareto.hpp), for a scenario as the
// main job plans it, with the plain, paper's-method and global runs placed on the same axes; and that
// result as JSON (the keys and values of `ffsr-optimize pareto --json`) and the front as CSV (`--csv`).
// Component ffsr::scenario. Never prints.
#pragma once

#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/jobs/detail/post_capture_front.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/pareto.hpp"

#include <algorithm>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace ffsr {

struct ParetoJobOptions {
  int levels = 30;  ///< epsilon levels of the sweep between the two ends
  int starts = 16;  ///< random starts of the two single-objective searches
  /// the second objective: base-rate (the impact's base-rate jump, the sweep's front), or a figure of
  /// the post-capture run (time-to-rest, peak-joint-torque, gripper-force, gripper-moment)
  std::string axis = "base-rate";
};

struct ParetoJobResult {
  ParetoFront front;
  std::vector<ParetoPoint>
      runs;       ///< the plain run, the paper's method and the global run on the front's axes
  BasePose base;  ///< the global run's base pose (the front's)
  std::string axis = "base-rate";
  /// a post-capture axis: its front over the global search's local optima and the sweep's points
  std::optional<PostCaptureFront> post_capture;
};

/// The options' own checks, each error naming the command's flag (--levels, --starts). InputError.
void check_pareto_job(const ParetoJobOptions& o);

/// The job: the main job's runs (global = true needed: InputError naming --global), then the front at
/// the global run's base pose, the paper's-method and global configurations as extra starts.
ParetoJobResult pareto(const Scenario& sc, const ParetoJobOptions& o);

/// The result as JSON: the keys and values of `ffsr-optimize pareto --json` (`version` as given;
/// `seconds` is the search's wall-clock time).
nlohmann::json pareto_json(const Scenario& sc, const ParetoJobResult& r, const std::string& version);

/// The front, one configuration per row, as the CSV of `ffsr-optimize pareto --csv`.
std::string pareto_csv(const ParetoFront& f);

inline void check_pareto_job(const ParetoJobOptions& o) {
  if (o.levels < 1) throw InputError(detail::str("--levels: must be >= 1, got ", o.levels));
  if (o.starts < 1) throw InputError(detail::str("--starts: must be >= 1, got ", o.starts));
  detail::check_pareto_axis(o.axis);
}

namespace detail {

/// The post-capture keys (Detumble) act on the post-capture axes only: a flag of one with the
/// base-rate axis is refused, naming it.
inline void check_pareto_post_capture_flags(const Scenario& sc, const std::string& axis) {
  if (axis != "base-rate") return;
  for (const ScenarioKey& key : scenario_keys())
    if (key.group == KeyGroup::Detumble && sc.keys.overridden.count(key.name))
      throw InputError(str("--", key.name,
                           ": acts on the post-capture axes of pareto only (--axis time-to-rest, "
                           "peak-joint-torque, gripper-force or gripper-moment), and the axis is base-rate"));
}

/// The post-capture front of the job (r: the main job's runs; f: the base-rate sweep at `base`).
inline PostCaptureFront pareto_post_capture(const Scenario& sc, const ScenarioResult& r, const ParetoFront& f,
                                            const CaptureSetup& setup, const std::string& axis, double e) {
  const PostCaptureScreen screen(sc, setup.capture.target, "--axis");
  const CaptureResult& g = r.global->result.run;
  std::vector<Eigen::VectorXd> thetas{g.theta};
  for (const CaptureBranch& b : r.global->branches) thetas.push_back(b.theta);
  for (const ParetoPoint& p : f.points) thetas.push_back(p.theta);
  PostCaptureFront out = post_capture_front(sc, setup, screen, axis, g.base, thetas, e);
  Data data(*sc.model);
  for (const CaptureResult* x : {&r.plain, &r.optimized, &g}) {
    const PostCaptureFigures fx = screen.figures(x->base, x->theta);
    out.runs.push_back({pareto_point(*sc.model, data, sc.problem, setup, x->base, x->theta, e), fx,
                        post_capture_value(fx, axis)});
  }
  return out;
}

}  // namespace detail

inline ParetoJobResult pareto(const Scenario& sc, const ParetoJobOptions& o) {
  check_pareto_job(o);
  detail::check_pareto_post_capture_flags(sc, o.axis);
  if (!sc.keys.global) throw InputError("--global: pareto needs the global run's base pose (global = true)");
  ScenarioRunOptions ro;
  const ScenarioResult r = run_scenario(sc, ro);
  const CaptureResult& g = r.global->result.run;
  const CaptureSetup setup = prepare_capture(sc.problem, sc.task, sc.capture);
  ParetoOptions po;
  po.levels = o.levels;
  po.starts = o.starts;
  po.seed = sc.seed;
  ParetoJobResult out;
  out.front = pareto_front(sc.problem, sc.task, setup, g.base, po, {r.optimized.theta, g.theta});
  Data data(*sc.model);
  const double e = single_body_restitution(setup.capture.law);
  for (const CaptureResult* x : {&r.plain, &r.optimized, &g})
    out.runs.push_back(detail::pareto_point(*sc.model, data, sc.problem, setup, x->base, x->theta, e));
  out.base = g.base;
  out.axis = o.axis;
  if (o.axis != "base-rate")
    out.post_capture = detail::pareto_post_capture(sc, r, out.front, setup, o.axis, e);
  return out;
}

namespace detail {

constexpr double kParetoDeg = 180.0 / M_PI;

inline nlohmann::json pareto_point_json(const ParetoPoint& p) {
  return {{"integrated_effective_mass", p.M_ie},
          {"base_angular_rate_jump_deg_s", p.base_rate * kParetoDeg},
          {"capture_configuration_deg", vector_json(Eigen::VectorXd(p.theta * kParetoDeg))}};
}

}  // namespace detail

namespace detail {

/// A point of a post-capture front: M_ie, the axis' value, the impact's base rate, every figure.
inline nlohmann::json post_capture_point_json(const Scenario& sc, const PostCaptureFrontPoint& p) {
  nlohmann::json j = pareto_point_json(p.point);
  j["value"] = std::isfinite(p.value) ? nlohmann::json(p.value) : nlohmann::json(nullptr);
  j["at_rest"] = p.figures.at_rest;
  j["time_to_rest"] = p.figures.time_to_rest;
  j["peak_joint_torque"] = p.figures.peak_joint_torque;
  j["peak_joint"] = p.figures.peak_joint >= 0 ? sc.model->joint(p.figures.peak_joint).name : "";
  j["peak_gripper_force"] = p.figures.peak_gripper_force;
  j["peak_gripper_moment"] = p.figures.peak_gripper_moment;
  return j;
}

/// The post-capture front as JSON: the axis, its unit, the points, the knee, the candidates, the runs.
inline nlohmann::json post_capture_front_json(const Scenario& sc, const PostCaptureFront& f) {
  nlohmann::json pts = nlohmann::json::array();
  for (const PostCaptureFrontPoint& p : f.points) pts.push_back(post_capture_point_json(sc, p));
  const char* names[] = {"baseline", "optimized", "global"};
  nlohmann::json runs;
  for (size_t i = 0; i < f.runs.size(); ++i) runs[names[i]] = post_capture_point_json(sc, f.runs[i]);
  return {{"axis", f.axis},       {"unit", pareto_axis_unit(f.axis)}, {"front", pts},
          {"knee_index", f.knee}, {"candidates", f.candidates},       {"candidates_at_rest", f.at_rest},
          {"runs", runs}};
}

}  // namespace detail

inline nlohmann::json pareto_json(const Scenario& sc, const ParetoJobResult& r, const std::string& version) {
  using detail::kParetoDeg;
  using detail::pareto_point_json;
  const ParetoFront& f = r.front;
  nlohmann::json pts = nlohmann::json::array();
  for (const ParetoPoint& p : f.points) pts.push_back(pareto_point_json(p));
  const Eigen::Vector4d q = r.base.orientation.coeffs();
  const char* names[] = {"baseline", "optimized", "global"};
  const ScenarioRow rows[] = {ScenarioRow::Plain, ScenarioRow::Optimized, ScenarioRow::Global};
  nlohmann::json rj;
  for (size_t i = 0; i < r.runs.size(); ++i) {
    rj[names[i]] = pareto_point_json(r.runs[i]);
    rj[names[i]]["keys_not_applied"] = keys_not_applied(sc.keys, rows[i]);  // as the main job's rows
  }
  nlohmann::json j = {{"version", version},
                      {"scenario", sc.where},
                      {"axis", r.axis},
                      {"base_position", detail::vector_json(Eigen::VectorXd(r.base.position))},
                      {"base_quaternion_wxyz", {q(3), q(0), q(1), q(2)}},
                      {"front", pts},
                      {"min_mass_end", pareto_point_json(f.min_mass)},
                      {"min_rate_end", pareto_point_json(f.min_rate)},
                      {"knee", pareto_point_json(f.points[f.knee])},
                      {"knee_index", f.knee},
                      {"hypervolume_kg_deg_s", f.hypervolume * kParetoDeg},
                      {"hypervolume_normalized", f.hypervolume_normalized},
                      {"runs", rj},
                      {"evaluations", f.evaluations},
                      {"seconds", f.seconds}};
  if (r.post_capture) j["post_capture"] = detail::post_capture_front_json(sc, *r.post_capture);
  return j;
}

/// A post-capture front, one configuration per row, as the CSV of `ffsr-optimize pareto --axis A --csv`:
/// index, M_ie, the axis' value (its name with the unit), the impact's base rate, knee, the joints.
inline std::string post_capture_front_csv(const PostCaptureFront& f) {
  using detail::kParetoDeg;
  std::string column = f.axis + "_" + detail::pareto_axis_unit(f.axis);
  std::replace(column.begin(), column.end(), '-', '_');
  std::replace(column.begin(), column.end(), ' ', '_');
  std::ostringstream out;
  out << std::setprecision(12) << "index,M_ie_kg," << column << ",base_rate_deg_s,knee";
  for (Eigen::Index k = 0; k < f.points.front().point.theta.size(); ++k) out << ",theta" << k + 1 << "_deg";
  out << "\n";
  for (size_t i = 0; i < f.points.size(); ++i) {
    const ParetoPoint& p = f.points[i].point;
    out << i << "," << p.M_ie << "," << f.points[i].value << "," << p.base_rate * kParetoDeg << ","
        << (i == f.knee ? 1 : 0);
    for (Eigen::Index k = 0; k < p.theta.size(); ++k) out << "," << p.theta(k) * kParetoDeg;
    out << "\n";
  }
  return out.str();
}

inline std::string pareto_csv(const ParetoFront& f) {
  using detail::kParetoDeg;
  std::ostringstream out;
  out << std::setprecision(12) << "index,M_ie_kg,base_rate_deg_s,knee";
  for (Eigen::Index k = 0; k < f.points.front().theta.size(); ++k) out << ",theta" << k + 1 << "_deg";
  out << "\n";
  for (size_t i = 0; i < f.points.size(); ++i) {
    const ParetoPoint& p = f.points[i];
    out << i << "," << p.M_ie << "," << p.base_rate * kParetoDeg << "," << (i == f.knee ? 1 : 0);
    for (Eigen::Index k = 0; k < p.theta.size(); ++k) out << "," << p.theta(k) * kParetoDeg;
    out << "\n";
  }
  return out.str();
}

}  // namespace ffsr
