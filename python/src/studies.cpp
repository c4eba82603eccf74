// python/src/studies.cpp -- the command's jobs over many configurations or samples as methods of
// ffsr.Scenario: map() (a grid of joint angles), robust() (Monte Carlo over the [uncertainty] table)
// and pareto() (the front of M_ie against the base's rate jump). Each result's to_dict() is the
// command's --json for the same scenario and flags.
#include "arguments.hpp"
#include "bindings.hpp"
#include "job_helpers.hpp"

#include "ffsr/jobs/map.hpp"
#include "ffsr/jobs/pareto.hpp"
#include "ffsr/jobs/robust.hpp"

#include <nanobind/stl/optional.h>
#include <nanobind/stl/vector.h>

namespace ffsr::python {
namespace {

using namespace nb::literals;

/// map's points (one row per point of the shard, in the grid's numbering) and the command's JSON.
struct MapRunResult {
  std::optional<MapRun> run;
  Eigen::MatrixXd angles_deg;  ///< points x varied joints
  Eigen::VectorXd M_ie, f_max;
  std::string json;
};

using RobustRunResult = JobRun<RobustSummary>;
using ParetoRun = JobRun<ParetoJobResult>;

/// The map job into `r`: each block of points into its rows, on the thread that computed it (the rows
/// are disjoint).
void run_map(const Scenario& sc, const MapJobOptions& o, MapRunResult& r) {
  const MapPlan plan = plan_map(sc, o);
  const auto rows = static_cast<Eigen::Index>(plan.count());
  const size_t k = plan.grid.axes.size();
  r.angles_deg.resize(rows, static_cast<Eigen::Index>(k));
  r.M_ie.resize(rows);
  r.f_max.resize(rows);
  MapSink sink;
  sink.evaluated = [&r, &plan, k](unsigned, const MapBlock& b) {
    for (std::uint64_t i = 0; i < b.count; ++i) {
      const auto row = static_cast<Eigen::Index>(b.first - plan.first + i);
      for (size_t a = 0; a < k; ++a)
        r.angles_deg(row, static_cast<Eigen::Index>(a)) = b.angles_deg[i * k + a];
      r.M_ie(row) = b.M_ie[i];
      r.f_max(row) = b.f_max[i];
    }
  };
  r.run.emplace(evaluate_map(sc, plan, sink));
  r.json = map_json(sc, *r.run, FFSR_VERSION).dump();
}

/// The robust job's options as the command checks its flags, before anything is planned.
RobustJobOptions robust_options(const std::string& force_model, std::uint64_t shard_k, std::uint64_t shard_n,
                                int threads) {
  RobustJobOptions job;
  job.force_model = robust_force_model(force_model);
  if (shard_n < 1) throw InputError("--shard: N must be at least 1");
  if (shard_k >= shard_n)
    throw InputError(
        detail::str("--shard: K must be less than N (K counts from 0), got ", shard_k, "/", shard_n));
  job.shard_k = shard_k;
  job.shard_n = shard_n;
  if (threads < 1 || threads > 1024)
    throw InputError(detail::str("--threads: must be in [1, 1024], got ", threads));
  job.threads = threads;
  return job;
}

/// The configurations robust evaluates: the one given (deg, m, deg), else the ones the main job plans.
std::vector<RobustConfiguration> robust_configurations(const Scenario& rsc,
                                                       const std::optional<std::vector<double>>& joints_deg,
                                                       const std::vector<double>& base_position,
                                                       const std::vector<double>& base_rpy_deg) {
  if (joints_deg) return {given_robust_configuration(*rsc.model, *joints_deg, base_position, base_rpy_deg)};
  return planned_robust_configurations(rsc);
}

}  // namespace

void bind_map(nb::module_& m) {
  job_result_class<MapRunResult>(
      m, "MapResult",
      "M_ie (Eq. 14) and the closed-form F_max (Eq. 24) over a grid of joint angles (ffsr-optimize map),\n"
      "one row per point of the shard in the grid's numbering (the last varied joint fastest): the rows\n"
      "of the command's --csv. to_dict() is the command's --json (the grid and the extremes).")
      .def_prop_ro(
          "angles_deg",
          [](nb::handle self) { return view(nb::cast<const MapRunResult&>(self).angles_deg, self); },
          "The varied joints' angles of each point, deg, shape (points, varied joints).",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "M_ie", [](nb::handle self) { return view(nb::cast<const MapRunResult&>(self).M_ie, self); },
          "M_ie of each point under the scenario's joint model (contact-joints), kg.",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "f_max", [](nb::handle self) { return view(nb::cast<const MapRunResult&>(self).f_max, self); },
          "The closed-form F_max of each point (Eq. 24), N.", nb::rv_policy::automatic)
      .def_prop_ro(
          "points", [](const MapRunResult& r) { return r.run->plan.grid.size; },
          "The points of the whole grid.")
      .def_prop_ro(
          "first", [](const MapRunResult& r) { return r.run->plan.first; },
          "The grid index of the shard's first point (its rows are [first, end)).")
      .def_prop_ro(
          "end", [](const MapRunResult& r) { return r.run->plan.end; }, "One past the shard's last point.");

  const MapJobOptions d;
  def_scenario_method(
      "map",
      [](const Scenario& sc, std::vector<int> vary, std::vector<double> range_deg,
         std::vector<double> step_deg, std::uint64_t shard_k, std::uint64_t shard_n, unsigned threads,
         std::uint64_t max_points) {
        require_capture_scenario(sc);
        MapJobOptions o;
        o.vary = std::move(vary);
        o.range_deg = std::move(range_deg);
        o.step_deg = std::move(step_deg);
        o.shard_k = shard_k;
        o.shard_n = shard_n;
        o.threads = threads;
        o.max_points = max_points;
        return run_job<MapRunResult>([&](MapRunResult& r) { run_map(sc, o, r); });
      },
      "vary"_a, "range_deg"_a = d.range_deg, "step_deg"_a = d.step_deg, "shard_k"_a = 0, "shard_n"_a = 1,
      "threads"_a = 0, "max_points"_a = d.max_points,
      "The job `map` (ffsr-optimize map --config FILE): M_ie (Eq. 14) under the scenario's joint model and\n"
      "the closed-form F_max (Eq. 24) over a grid of joint angles, the other joints at the scenario's\n"
      "joints-deg (the paper's Figures 8 and 9). vary: the joints, 1-based in URDF tree order; range_deg:\n"
      "[lo, hi) of every varied joint, or one pair per joint; step_deg: one step or one per joint; shard K\n"
      "of N of the points; threads: 0 for one per core (results do not depend on it); max_points: refuse\n"
      "larger grids. The keywords are the command's flags (an underscore for a dash).");
}

void bind_robust(nb::module_& m) {
  using Config = RobustConfigurationSummary;
  nb::class_<Config>(m, "RobustConfiguration",
                     "One capture configuration of the job robust: its F_max over the samples.")
      .def_ro("name", &Config::name, "plain, optimized, global, robust or given.")
      .def_prop_ro(
          "f_max", [](const Config& c) { return array_of(c.f_max); }, "Every sample's F_max, by index, N.",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "nominal_f_max", [](const Config& c) { return c.nominal.f_max; },
          "F_max on the nominal sample (no spread), N.")
      .def_prop_ro(
          "nominal_M_ie", [](const Config& c) { return c.nominal.M_ie; },
          "M_ie (Eq. 14) on the nominal sample, kg.")
      .def_prop_ro(
          "mean", [](const Config& c) { return c.summary.mean; }, "Mean F_max, N.")
      .def_prop_ro(
          "p50", [](const Config& c) { return c.summary.p50; }, "50th percentile, N.")
      .def_prop_ro(
          "p95", [](const Config& c) { return c.summary.p95; }, "95th percentile, N.")
      .def_prop_ro(
          "p99", [](const Config& c) { return c.summary.p99; }, "99th percentile, N.")
      .def_prop_ro(
          "max", [](const Config& c) { return c.summary.max; }, "Largest F_max, N.");

  job_result_class<RobustRunResult>(
      m, "RobustResult",
      "Monte Carlo of F_max over the scenario's [uncertainty] table (ffsr-optimize robust).\n"
      "to_dict() is the command's --json.")
      .def_prop_ro(
          "configurations", [](const RobustRunResult& r) { return r.result.configurations; },
          "One per capture configuration evaluated.")
      .def_prop_ro(
          "samples", [](const RobustRunResult& r) { return r.result.samples; },
          "Samples of the uncertainty table (all shards).")
      .def_prop_ro(
          "seed", [](const RobustRunResult& r) { return r.result.seed; }, "The samples' seed.");

  def_scenario_method(
      "robust",
      [](const Scenario& sc, const std::string& force_model, std::optional<std::uint64_t> samples,
         std::optional<std::uint64_t> seed, std::uint64_t shard_k, std::uint64_t shard_n, int threads,
         std::optional<std::vector<double>> capture_joints_deg, std::vector<double> capture_base_position,
         std::vector<double> capture_base_rpy_deg) {
        require_capture_scenario(sc);
        return run_job<RobustRunResult>([&](RobustRunResult& r) {
          // as the command: the table with the samples and seed given, the job's options, the scenario
          // (global runs with seed 1), checked before anything is planned
          if (samples && *samples < 1) throw InputError("--samples: must be at least 1, got 0");
          const UncertaintySpec spec = uncertainty_spec(sc.keys, samples, seed);
          const RobustJobOptions job = robust_options(force_model, shard_k, shard_n, threads);
          ScenarioKeys keys = sc.keys;
          robust_global_seed(keys);
          const Scenario rsc = build_scenario(std::move(keys));
          check_robust_job(rsc, job);
          const RobustRun run = run_robust(
              rsc, spec,
              robust_configurations(rsc, capture_joints_deg, capture_base_position, capture_base_rpy_deg),
              job);
          r.result = robust_summary(rsc, run, rsc.keys.file, FFSR_VERSION);
          r.json = r.result.to_json().dump();
        });
      },
      "force_model"_a = "exact", "samples"_a = nb::none(), "seed"_a = nb::none(), "shard_k"_a = 0,
      "shard_n"_a = 1, "threads"_a = 1, "capture_joints_deg"_a = nb::none(),
      "capture_base_position"_a = std::vector<double>{0, 0, 0},
      "capture_base_rpy_deg"_a = std::vector<double>{0, 0, 0},
      "The job `robust` (ffsr-optimize robust --config FILE): Monte Carlo of F_max over the scenario's\n"
      "[uncertainty] table for the configurations the main job plans (plain, optimized, global) or the one\n"
      "given (capture_joints_deg, deg). force_model: closed (Eq. 24), exact (Eq. 16) or multibody; samples,\n"
      "seed: override uncertainty.samples and uncertainty.seed; shard K of N of the samples; threads\n"
      "(results do not depend on them). The keywords are the command's flags (an underscore for a dash).");
}

void bind_robust_merge(nb::module_& m) {
  m.def(
      "merge_robust_shards",
      [](const std::vector<std::string>& parts) {
        return run_job<RobustRunResult>([&](RobustRunResult& r) {
          std::vector<RobustSummary> summaries;
          for (std::size_t i = 0; i < parts.size(); ++i) {
            const std::string where = detail::str("merge_robust_shards: part ", i);
            nlohmann::json j;
            try {
              j = nlohmann::json::parse(parts[i]);
            } catch (const std::exception& e) {
              throw InputError(detail::str(where, " is not JSON: ", e.what()));
            }
            summaries.push_back(RobustSummary::from_json(j, where));
          }
          r.result = merge_shards(std::move(summaries));
          r.json = r.result.to_json().dump();
        });
      },
      "parts"_a,
      "The shards of one robust run merged (any order), as `ffsr-optimize robust --merge` merges them:\n"
      "parts are the shards' --json texts (RobustResult.to_json()); the samples are concatenated by index\n"
      "and the percentiles, mean and tail computed again, those of the unsharded run to the bit.\n"
      "InputError when the parts are not shards of one run or leave gaps or overlaps.");
}

void bind_pareto(nb::module_& m) {
  nb::class_<ParetoPoint>(m, "ParetoPoint", "A capture configuration on the axes of the front.")
      .def_ro("M_ie", &ParetoPoint::M_ie, "Integrated effective mass (Eq. 14), kg.")
      .def_ro("base_rate", &ParetoPoint::base_rate,
              "|Delta w_0|, the base's angular rate jump at the impact, rad/s.")
      .def_prop_ro(
          "theta", [](const ParetoPoint& p) { return out(p.theta); }, "The configuration, rad.",
          nb::rv_policy::automatic);

  job_result_class<ParetoRun>(
      m, "ParetoResult",
      "The front of (M_ie, base angular rate jump) on the capture manifold at the global run's base\n"
      "pose (ffsr-optimize pareto). to_dict() is the command's --json.")
      .def_prop_ro(
          "front", [](const ParetoRun& r) { return r.result.front.points; },
          "Non-dominated points, M_ie increasing.")
      .def_prop_ro(
          "knee", [](const ParetoRun& r) { return r.result.front.points[r.result.front.knee]; },
          "The knee of the front.")
      .def_prop_ro(
          "min_mass_end", [](const ParetoRun& r) { return r.result.front.min_mass; }, "The least-M_ie end.")
      .def_prop_ro(
          "min_rate_end", [](const ParetoRun& r) { return r.result.front.min_rate; },
          "The least-base-rate end.")
      .def_prop_ro(
          "runs", [](const ParetoRun& r) { return r.result.runs; },
          "The plain run, the paper's method and the global run on the same axes.")
      .def_prop_ro(
          "hypervolume_normalized", [](const ParetoRun& r) { return r.result.front.hypervolume_normalized; },
          "Area the front dominates up to the nadir of its ends, divided by the nadir box (0..1).")
      .def_prop_ro(
          "axis", [](const ParetoRun& r) { return r.result.axis; },
          "The second objective: base-rate, or a post-capture figure (to_dict()['post_capture']).")
      .def(
          "front_csv",
          [](const ParetoRun& r) {
            return r.result.post_capture ? post_capture_front_csv(*r.result.post_capture)
                                         : pareto_csv(r.result.front);
          },
          "The front as the command's --csv (of the post-capture axis when one is chosen).");

  const ParetoJobOptions d;
  def_scenario_method(
      "pareto",
      [](const Scenario& sc, int levels, int starts, const std::string& axis) {
        require_capture_scenario(sc);
        ParetoJobOptions o;
        o.levels = levels;
        o.starts = starts;
        o.axis = axis;
        return run_job<ParetoRun>([&](ParetoRun& r) {
          r.result = pareto(sc, o);
          r.json = pareto_json(sc, r.result, FFSR_VERSION).dump();
        });
      },
      "levels"_a = d.levels, "starts"_a = d.starts, "axis"_a = d.axis,
      "The job `pareto` (ffsr-optimize pareto --config FILE): the main job's runs, then the front of M_ie\n"
      "(Eq. 14) against the base's angular rate jump at the impact on the capture manifold at the global\n"
      "run's base pose (levels: epsilon levels between the two ends; starts: random starts of the two\n"
      "single-objective searches; axis: base-rate, or time-to-rest, peak-joint-torque, gripper-force or\n"
      "gripper-moment for the front of M_ie against that figure of the post-capture run, the Detumble\n"
      "keys' run at the global search's local optima and the sweep's points).");
}

}  // namespace ffsr::python
