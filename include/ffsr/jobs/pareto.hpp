// ffsr/jobs/pareto.hpp -- the job `pareto`: the front of (M_ie, base angular rate jump at the impact) on
// the capture manifold at the global run's base pose (ffsr/optimize/pareto.hpp), for a scenario as the
// main job plans it, with the plain, paper's-method and global runs placed on the same axes; and that
// result as JSON (the keys and values of `ffsr-optimize pareto --json`) and the front as CSV (`--csv`).
// Component ffsr::scenario. Never prints.
#pragma once

#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/pareto.hpp"

#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace ffsr {

struct ParetoJobOptions {
  int levels = 30;  ///< epsilon levels of the sweep between the two ends
  int starts = 16;  ///< random starts of the two single-objective searches
};

struct ParetoJobResult {
  ParetoFront front;
  std::vector<ParetoPoint> runs;  ///< the plain run, the paper's method and the global run on the front's axes
  BasePose base;                  ///< the global run's base pose (the front's)
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
}

inline ParetoJobResult pareto(const Scenario& sc, const ParetoJobOptions& o) {
  check_pareto_job(o);
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
  const double e = single_body_restitution(setup.law);
  for (const CaptureResult* x : {&r.plain, &r.optimized, &g})
    out.runs.push_back(detail::pareto_point(*sc.model, data, sc.problem, setup, x->base, x->theta, e));
  out.base = g.base;
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
  return {{"version", version},
          {"scenario", sc.where},
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
