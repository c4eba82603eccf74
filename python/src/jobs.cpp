// python/src/jobs.cpp -- the command's one-configuration jobs as methods of ffsr.Scenario: inspect()
// (ffsr/jobs/inspect.hpp), whose result's to_dict() is `ffsr-optimize inspect --json` for the same
// scenario (the library makes the JSON: the command prints the same document).
#include "common.hpp"

#include <ffsr/jobs/closed_loop.hpp>
#include <ffsr/jobs/contact.hpp>
#include <ffsr/jobs/inspect.hpp>
#include <ffsr/jobs/map.hpp>
#include <ffsr/jobs/pareto.hpp>
#include <ffsr/jobs/robust.hpp>

#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/unique_ptr.h>
#include <nanobind/stl/vector.h>

#include <memory>
#include <optional>

#ifndef FFSR_VERSION
#error "FFSR_VERSION must be defined (python/CMakeLists.txt reads it from the project)"
#endif

namespace ffsr::python {
namespace {

using namespace nb::literals;


/// inspect's result: the subject it evaluated (the result's Data is made from its model), the
/// evaluation and the command's JSON, made together.
struct InspectRun {
  Subject subject;
  std::optional<InspectResult> result;
  std::string json;
};

/// contact's result: the rows (one per law) and the command's JSON.
struct ContactRun {
  std::vector<ContactRow> rows;
  std::string json;
};

/// closed_loop's result and the command's JSON.
struct ClosedLoopRun {
  ClosedLoopJobResult job;
  std::string json;
};

/// robust's summary and the command's JSON.
struct RobustRunResult {
  RobustSummary summary;
  std::string json;
};

/// pareto's result and the command's JSON.
struct ParetoRun {
  ParetoJobResult job;
  std::string json;
};

/// map's points (one row per point of the shard, in the grid's numbering) and the command's JSON.
struct MapRunResult {
  std::optional<MapRun> run;
  Eigen::MatrixXd angles_deg;  ///< points x varied joints
  Eigen::VectorXd M_ie, f_max;
  std::string json;
};

/// The subject of a scenario: its keys as resolved, built again by the job layer (as the command builds
/// the subject of --config FILE); `overrides`: (key, value) given to the job (values a scenario refuses,
/// as 'all'), as the command's flags.
Subject scenario_subject(const Scenario& sc, const std::vector<std::pair<const char*, std::optional<std::string>>>& overrides = {}) {
  ScenarioKeys keys = sc.keys;
  for (const auto& [key, value] : overrides)
    if (value) override_scenario_key(keys, key, *value);
  return load_subject(std::move(keys));
}

}  // namespace

void bind_jobs(nb::module_& m) {
  nb::class_<BaseDisturbance>(m, "BaseDisturbance",
                              "The base's velocity jump at the impact (single-body impulse P = M_ie delta_dot^- (1 + e)).")
      .def_ro("M_ie", &BaseDisturbance::M_ie, "Integrated effective mass (Eq. 14), kg.")
      .def_ro("approach_velocity", &BaseDisturbance::approach_velocity, "delta_dot^-, m/s.")
      .def_ro("restitution", &BaseDisturbance::restitution, "e of the single-body model (realized by the law).")
      .def_ro("impulse", &BaseDisturbance::impulse, "P, N s.")
      .def_prop_ro("linear", [](const BaseDisturbance& d) { return out(d.linear); },
                   "Jump of the base origin's velocity, m/s (inertial frame).", nb::rv_policy::automatic)
      .def_prop_ro("angular", [](const BaseDisturbance& d) { return out(d.angular); },
                   "Jump of the base's angular velocity, rad/s (inertial frame).", nb::rv_policy::automatic)
      .def_prop_ro("angular_rate", &BaseDisturbance::angular_rate, "|Delta w_0|, rad/s.");

  nb::class_<InspectRun>(m, "InspectResult",
                         "One configuration evaluated (ffsr-optimize inspect): H, J_bm, J_f, m_e (Eq. 4), M_ie\n"
                         "(Eq. 14) and the base's jump at the impact. to_dict() is the command's --json.")
      .def_prop_ro("M_ie", [](const InspectRun& r) { return r.result->M_ie; },
                   "Integrated effective mass (Eq. 14) under the scenario's joint model, kg.")
      .def_prop_ro("m_e", [](const InspectRun& r) { return r.result->m_e; }, "Effective mass along u (Eq. 4), kg.")
      .def_prop_ro("direction", [](const InspectRun& r) { return out(r.result->u); },
                   "The contact normal u (inertial frame).", nb::rv_policy::automatic)
      .def_prop_ro("H", [](const InspectRun& r) { return out(r.result->data.H); },
                   "Generalized inertia matrix H ((6 + n) x (6 + n)).", nb::rv_policy::automatic)
      .def_prop_ro("J_bm", [](const InspectRun& r) { return out(r.result->data.J); },
                   "End-effector Jacobian [J_b J_m] (6 x (6 + n), linear rows first).", nb::rv_policy::automatic)
      .def_prop_ro("J_f", [](const InspectRun& r) { return out(r.result->Jf); },
                   "Generalized Jacobian J_f (6 x n, linear rows first).", nb::rv_policy::automatic)
      .def_prop_ro("end_effector", [](const InspectRun& r) { return r.result->ee; }, "The end-effector's pose.")
      .def_prop_ro("base_disturbance", [](const InspectRun& r) { return r.result->disturbance; },
                   "The base's jump at the impact, or None when the end-effector does not approach the target.")
      .def_prop_ro("contact_joints", [](const InspectRun& r) { return std::string(joint_model_name(r.result->joints.model)); },
                   "The joint model of M_ie, m_e and the base's jump (free, locked, armature).")
      .def("to_dict", [](const InspectRun& r) { return json_loads(r.json); }, "The command's --json, as a dict.")
      .def("to_json", [](const InspectRun& r) { return r.json; }, "The command's --json, as text.");

  nb::class_<ContactRow>(m, "ContactRow", "One law's row of the job contact.")
      .def_ro("model", &ContactRow::model, "The law's name (Table 1).")
      .def_ro("M_ie", &ContactRow::M_ie, "Integrated effective mass (Eq. 14) under the chosen joint model, kg.")
      .def_ro("approach_velocity", &ContactRow::v_in, "delta_dot^- of the multibody run, m/s.")
      .def_ro("f_max_closed_form", &ContactRow::f_closed, "Peak force, closed form (Eq. 24), N.")
      .def_ro("f_max_exact", &ContactRow::f_exact, "Peak force, exact single-body peak (Eq. 16), N.")
      .def_ro("f_max_multibody", &ContactRow::f_multibody, "Peak force of the multibody reference (CVODE), N.")
      .def_ro("model_accuracy", &ContactRow::accuracy, "Eq. 32, closed form vs multibody, percent.")
      .def_ro("relative_error_xi", &ContactRow::xi, "The closed form's relative error xi (Eq. 25), percent.")
      .def_ro("delta_max", &ContactRow::delta_max, "The closed form's largest deformation, m.")
      .def_ro("time_of_peak", &ContactRow::t_peak, "Time of the multibody peak, s.")
      .def_ro("contact_duration", &ContactRow::duration, "Duration of the multibody contact, s.")
      .def_ro("restitution_realized", &ContactRow::restitution, "Restitution realized by the multibody run.")
      .def_ro("base_disturbance", &ContactRow::base_jump, "The base's jump predicted (single-body impulse).")
      .def_prop_ro(
          "series",
          [](const ContactRow& r) {
            Eigen::MatrixXd s(static_cast<Eigen::Index>(r.series.size()), 3);
            for (size_t i = 0; i < r.series.size(); ++i)
              s.row(static_cast<Eigen::Index>(i)) << r.series[i].t, r.series[i].force, r.series[i].delta;
            return out(s);
          },
          "t (s), F (N), delta (m) of the multibody run, one row per sample (contact(series=True); else empty).",
          nb::rv_policy::automatic);

  nb::class_<ContactRun>(m, "ContactResult",
                         "The maximum contact force (ffsr-optimize contact): closed form (Eq. 24), exact (Eq. 16) and\n"
                         "the multibody reference, a row per law. to_dict() is the command's --json.")
      .def_ro("rows", &ContactRun::rows, "One row per law (every law of Table 1 for model='all').")
      .def_prop_ro("M_ie", [](const ContactRun& r) { return r.rows.front().M_ie; }, "M_ie of the first row, kg.")
      .def_prop_ro("f_max_multibody", [](const ContactRun& r) { return r.rows.front().f_multibody; },
                   "The multibody peak of the first row, N.")
      .def("to_dict", [](const ContactRun& r) { return json_loads(r.json); }, "The command's --json, as a dict.")
      .def("to_json", [](const ContactRun& r) { return r.json; }, "The command's --json, as text.");

  nb::class_<ClosedLoopRun>(m, "ClosedLoopResult",
                            "The capture controller in a closed loop with the robot's dynamics (ffsr-optimize closed-loop),\n"
                            "beside the open-loop plan it follows. to_dict() is the command's --json.")
      .def_prop_ro("plan", [](const ClosedLoopRun& r) { return r.job.plan.name; }, "The plan followed.")
      .def_prop_ro("open_loop", [](const ClosedLoopRun& r) { return r.job.plan.open; }, "The open-loop plan's run.")
      .def_prop_ro("theta", [](const ClosedLoopRun& r) { return out(r.job.result.theta); },
                   "The closed loop's configuration at T, rad.", nb::rv_policy::automatic)
      .def_prop_ro("capture_error", [](const ClosedLoopRun& r) { return r.job.result.capture_error; },
                   "|p_e(T) - capture point| of the closed loop, m.")
      .def_prop_ro("M_ie", [](const ClosedLoopRun& r) { return r.job.result.M_ie; },
                   "M_ie (Eq. 14) at the closed loop's capture configuration, kg.")
      .def_prop_ro("f_max_closed_form", [](const ClosedLoopRun& r) { return r.job.result.f_max_closed_form; },
                   "Eq. 24 at that M_ie, N.")
      .def_prop_ro("max_torque", [](const ClosedLoopRun& r) { return r.job.result.max_torque; }, "Largest |tau_k|, N m.")
      .def_prop_ro("ticks", [](const ClosedLoopRun& r) { return r.job.result.ticks; }, "Control ticks flown.")
      .def("to_dict", [](const ClosedLoopRun& r) { return json_loads(r.json); }, "The command's --json, as a dict.")
      .def("to_json", [](const ClosedLoopRun& r) { return r.json; }, "The command's --json, as text.")
      .def("series_csv", [](const ClosedLoopRun& r) { return closed_loop_series_csv(r.job.result); },
           "The recorded samples (record_every) as the command's --csv.");

  nb::class_<RobustConfigurationSummary>(m, "RobustConfiguration",
                                         "One capture configuration of the job robust: its F_max over the samples.")
      .def_ro("name", &RobustConfigurationSummary::name, "plain, optimized, global, robust or given.")
      .def_prop_ro("f_max", [](const RobustConfigurationSummary& c) {
            return out(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(c.f_max.data(), static_cast<Eigen::Index>(c.f_max.size()))));
          }, "Every sample's F_max, by index, N.", nb::rv_policy::automatic)
      .def_prop_ro("nominal_f_max", [](const RobustConfigurationSummary& c) { return c.nominal.f_max; },
                   "F_max on the nominal sample (no spread), N.")
      .def_prop_ro("nominal_M_ie", [](const RobustConfigurationSummary& c) { return c.nominal.M_ie; },
                   "M_ie (Eq. 14) on the nominal sample, kg.")
      .def_prop_ro("mean", [](const RobustConfigurationSummary& c) { return c.summary.mean; }, "Mean F_max, N.")
      .def_prop_ro("p50", [](const RobustConfigurationSummary& c) { return c.summary.p50; }, "50th percentile, N.")
      .def_prop_ro("p95", [](const RobustConfigurationSummary& c) { return c.summary.p95; }, "95th percentile, N.")
      .def_prop_ro("p99", [](const RobustConfigurationSummary& c) { return c.summary.p99; }, "99th percentile, N.")
      .def_prop_ro("max", [](const RobustConfigurationSummary& c) { return c.summary.max; }, "Largest F_max, N.");

  nb::class_<RobustRunResult>(m, "RobustResult",
                              "Monte Carlo of F_max over the scenario's [uncertainty] table (ffsr-optimize robust).\n"
                              "to_dict() is the command's --json.")
      .def_prop_ro("configurations", [](const RobustRunResult& r) { return r.summary.configurations; },
                   "One per capture configuration evaluated.")
      .def_prop_ro("samples", [](const RobustRunResult& r) { return r.summary.samples; },
                   "Samples of the uncertainty table (all shards).")
      .def_prop_ro("seed", [](const RobustRunResult& r) { return r.summary.seed; }, "The samples' seed.")
      .def("to_dict", [](const RobustRunResult& r) { return json_loads(r.json); }, "The command's --json, as a dict.")
      .def("to_json", [](const RobustRunResult& r) { return r.json; }, "The command's --json, as text.");

  nb::class_<ParetoPoint>(m, "ParetoPoint", "A capture configuration on the axes of the front.")
      .def_ro("M_ie", &ParetoPoint::M_ie, "Integrated effective mass (Eq. 14), kg.")
      .def_ro("base_rate", &ParetoPoint::base_rate, "|Delta w_0|, the base's angular rate jump at the impact, rad/s.")
      .def_prop_ro("theta", [](const ParetoPoint& p) { return out(p.theta); }, "The configuration, rad.",
                   nb::rv_policy::automatic);

  nb::class_<ParetoRun>(m, "ParetoResult",
                        "The front of (M_ie, base angular rate jump) on the capture manifold at the global run's base\n"
                        "pose (ffsr-optimize pareto). to_dict() is the command's --json.")
      .def_prop_ro("front", [](const ParetoRun& r) { return r.job.front.points; }, "Non-dominated points, M_ie increasing.")
      .def_prop_ro("knee", [](const ParetoRun& r) { return r.job.front.points[r.job.front.knee]; }, "The knee of the front.")
      .def_prop_ro("min_mass_end", [](const ParetoRun& r) { return r.job.front.min_mass; }, "The least-M_ie end.")
      .def_prop_ro("min_rate_end", [](const ParetoRun& r) { return r.job.front.min_rate; }, "The least-base-rate end.")
      .def_prop_ro("runs", [](const ParetoRun& r) { return r.job.runs; },
                   "The plain run, the paper's method and the global run on the same axes.")
      .def_prop_ro("hypervolume_normalized", [](const ParetoRun& r) { return r.job.front.hypervolume_normalized; },
                   "Area the front dominates up to the nadir of its ends, divided by the nadir box (0..1).")
      .def("to_dict", [](const ParetoRun& r) { return json_loads(r.json); }, "The command's --json, as a dict.")
      .def("to_json", [](const ParetoRun& r) { return r.json; }, "The command's --json, as text.")
      .def("front_csv", [](const ParetoRun& r) { return pareto_csv(r.job.front); }, "The front as the command's --csv.");

  nb::class_<MapRunResult>(m, "MapResult",
                           "M_ie (Eq. 14) and the closed-form F_max (Eq. 24) over a grid of joint angles (ffsr-optimize map),\n"
                           "one row per point of the shard in the grid's numbering (the last varied joint fastest): the rows\n"
                           "of the command's --csv. to_dict() is the command's --json (the grid and the extremes).")
      .def_prop_ro("angles_deg", [](nb::handle self) { return view(nb::cast<const MapRunResult&>(self).angles_deg, self); },
                   "The varied joints' angles of each point, deg, shape (points, varied joints).", nb::rv_policy::automatic)
      .def_prop_ro("M_ie", [](nb::handle self) { return view(nb::cast<const MapRunResult&>(self).M_ie, self); },
                   "M_ie of each point under the scenario's joint model (contact-joints), kg.", nb::rv_policy::automatic)
      .def_prop_ro("f_max", [](nb::handle self) { return view(nb::cast<const MapRunResult&>(self).f_max, self); },
                   "The closed-form F_max of each point (Eq. 24), N.", nb::rv_policy::automatic)
      .def_prop_ro("points", [](const MapRunResult& r) { return r.run->plan.grid.size; }, "The points of the whole grid.")
      .def_prop_ro("first", [](const MapRunResult& r) { return r.run->plan.first; },
                   "The grid index of the shard's first point (its rows are [first, end)).")
      .def_prop_ro("end", [](const MapRunResult& r) { return r.run->plan.end; }, "One past the shard's last point.")
      .def("to_dict", [](const MapRunResult& r) { return json_loads(r.json); }, "The command's --json, as a dict.")
      .def("to_json", [](const MapRunResult& r) { return r.json; }, "The command's --json, as text.");

  nb::handle scenario = nb::type<Scenario>();
  scenario.attr("inspect") = nb::cpp_function(
      [](const Scenario& sc) {
        auto r = std::make_unique<InspectRun>();
        {
          nb::gil_scoped_release release;
          r->subject = scenario_subject(sc);
          r->result.emplace(inspect(r->subject));
          r->json = inspect_json(r->subject, *r->result, FFSR_VERSION).dump();
        }
        return r;
      },
      nb::is_method(), nb::name("inspect"), nb::scope(scenario),
      "The job `inspect` (ffsr-optimize inspect --config FILE): the start configuration evaluated: H, J_f,\n"
      "m_e (Eq. 4), M_ie (Eq. 14) and the base's jump at the impact under the scenario's joint model\n"
      "(contact-joints), the distances between the shapes.");

  scenario.attr("contact") = nb::cpp_function(
      [](const Scenario& sc, std::optional<std::string> model, std::optional<std::string> contact_joints, bool series) {
        auto r = std::make_unique<ContactRun>();
        {
          nb::gil_scoped_release release;
          const Subject s = scenario_subject(sc, {{"model", model}, {"contact-joints", contact_joints}});
          ContactJobOptions o;
          o.record_series = series;
          r->rows = contact(s, o);
          r->json = contact_json(s, r->rows, FFSR_VERSION).dump();
        }
        return r;
      },
      nb::is_method(), nb::name("contact"), nb::scope(scenario), "model"_a = nb::none(), "contact_joints"_a = nb::none(),
      "series"_a = false,
      "The job `contact` (ffsr-optimize contact --config FILE): the peak contact force at the start configuration by\n"
      "the closed form (Eq. 24), the exact single-body peak (Eq. 16) and the multibody reference (CVODE, robot +\n"
      "target). model: a law of Table 1 or 'all' (default: the scenario's); contact_joints: free, locked, armature\n"
      "or 'all' (default: the scenario's; as --model and --contact-joints); series: keep F(t), delta(t).");

  const MapJobOptions map_defaults;
  scenario.attr("map") = nb::cpp_function(
      [](const Scenario& sc, std::vector<int> vary, std::vector<double> range_deg, std::vector<double> step_deg,
         std::uint64_t shard_k, std::uint64_t shard_n, unsigned threads, std::uint64_t max_points) {
        MapJobOptions o;
        o.vary = std::move(vary);
        o.range_deg = std::move(range_deg);
        o.step_deg = std::move(step_deg);
        o.shard_k = shard_k;
        o.shard_n = shard_n;
        o.threads = threads;
        o.max_points = max_points;
        auto r = std::make_unique<MapRunResult>();
        {
          nb::gil_scoped_release release;
          const Subject s = scenario_subject(sc);
          const MapPlan plan = plan_map(s, o);
          const auto rows = static_cast<Eigen::Index>(plan.count());
          r->angles_deg.resize(rows, static_cast<Eigen::Index>(plan.grid.axes.size()));
          r->M_ie.resize(rows);
          r->f_max.resize(rows);
          MapSink sink;  // each block into its rows, on the thread that computed it (the rows are disjoint)
          sink.evaluated = [&r, &plan](unsigned, const MapBlock& b) {
            const size_t k = plan.grid.axes.size();
            for (std::uint64_t i = 0; i < b.count; ++i) {
              const auto row = static_cast<Eigen::Index>(b.first - plan.first + i);
              for (size_t a = 0; a < k; ++a) r->angles_deg(row, static_cast<Eigen::Index>(a)) = b.angles_deg[i * k + a];
              r->M_ie(row) = b.M_ie[i];
              r->f_max(row) = b.f_max[i];
            }
          };
          r->run.emplace(evaluate_map(s, plan, sink));
          r->json = map_json(s, *r->run, FFSR_VERSION).dump();
        }
        return r;
      },
      nb::is_method(), nb::name("map"), nb::scope(scenario), "vary"_a, "range_deg"_a = map_defaults.range_deg,
      "step_deg"_a = map_defaults.step_deg, "shard_k"_a = 0, "shard_n"_a = 1, "threads"_a = 0,
      "max_points"_a = map_defaults.max_points,
      "The job `map` (ffsr-optimize map --config FILE): M_ie (Eq. 14) under the scenario's joint model and the\n"
      "closed-form F_max (Eq. 24) over a grid of joint angles, the other joints at the scenario's joints-deg\n"
      "(the paper's Figures 8 and 9). vary: the joints, 1-based in URDF tree order; range_deg: [lo, hi) of every\n"
      "varied joint, or one pair per joint; step_deg: one step or one per joint; shard K of N of the points;\n"
      "threads: 0 for one per core (results do not depend on it); max_points: refuse larger grids. The\n"
      "keywords are the command's flags (an underscore for a dash).");

  const ClosedLoopJobOptions defaults;
  scenario.attr("closed_loop") = nb::cpp_function(
      [](const Scenario& sc, const std::string& plan, std::optional<std::vector<double>> goal_joints_deg,
         double control_rate, double estimate_rate, double position_noise, double attitude_noise_deg,
         double velocity_noise, double spin_noise_deg, int prediction_window, std::uint64_t noise_seed,
         double rate_loop_bandwidth, double torque_limit, double record_every) {
        ClosedLoopJobOptions o;
        o.plan = plan;
        if (goal_joints_deg) o.goal_joints_deg = *goal_joints_deg;
        o.loop.control_rate = control_rate;
        o.loop.estimate_rate = estimate_rate;
        o.loop.noise.position = position_noise;
        o.attitude_noise_deg = attitude_noise_deg;
        o.loop.noise.velocity = velocity_noise;
        o.spin_noise_deg = spin_noise_deg;
        o.controller.prediction_window = prediction_window;
        o.loop.seed = noise_seed;
        o.loop.loop.bandwidth = rate_loop_bandwidth;
        o.loop.loop.torque_limit = torque_limit;
        o.loop.record_every = record_every;
        auto r = std::make_unique<ClosedLoopRun>();
        {
          nb::gil_scoped_release release;
          r->job = closed_loop(sc, o);
          r->json = closed_loop_json(sc, r->job, FFSR_VERSION).dump();
        }
        return r;
      },
      nb::is_method(), nb::name("closed_loop"), nb::scope(scenario), "plan"_a = defaults.plan,
      "goal_joints_deg"_a = nb::none(), "control_rate"_a = defaults.loop.control_rate,
      "estimate_rate"_a = defaults.loop.estimate_rate, "position_noise"_a = defaults.loop.noise.position,
      "attitude_noise_deg"_a = defaults.attitude_noise_deg, "velocity_noise"_a = defaults.loop.noise.velocity,
      "spin_noise_deg"_a = defaults.spin_noise_deg, "prediction_window"_a = defaults.controller.prediction_window,
      "noise_seed"_a = defaults.loop.seed, "rate_loop_bandwidth"_a = defaults.loop.loop.bandwidth,
      "torque_limit"_a = defaults.loop.loop.torque_limit, "record_every"_a = defaults.loop.record_every,
      "The job `closed-loop` (ffsr-optimize closed-loop --config FILE): the capture controller with the robot's\n"
      "full dynamics, joint rate loops and a noisy target estimate, beside the open-loop plan it follows: plan\n"
      "'paper' (Eq. 29-31) or 'global' (the global run's servo), or the servo to goal_joints_deg. The keywords are\n"
      "the command's flags (an underscore for a dash), in its units; record_every: s between recorded samples\n"
      "(series_csv()). InputError naming the flag.");
  scenario.attr("robust") = nb::cpp_function(
      [](const Scenario& sc, const std::string& force_model, std::optional<std::uint64_t> samples,
         std::optional<std::uint64_t> seed, std::uint64_t shard_k, std::uint64_t shard_n, int threads,
         std::optional<std::vector<double>> capture_joints_deg, std::vector<double> capture_base_position,
         std::vector<double> capture_base_rpy_deg) {
        auto r = std::make_unique<RobustRunResult>();
        {
          nb::gil_scoped_release release;
          // as the command: the table with the samples and seed given, the job's options, the scenario
          // (global runs with seed 1), checked before anything is planned
          if (samples && *samples < 1) throw InputError("--samples: must be at least 1, got 0");
          const UncertaintySpec spec = uncertainty_spec(sc.keys, samples, seed);
          RobustJobOptions job;
          job.force_model = robust_force_model(force_model);
          if (shard_n < 1) throw InputError("--shard: N must be at least 1");
          if (shard_k >= shard_n)
            throw InputError(detail::str("--shard: K must be less than N (K counts from 0), got ", shard_k, "/", shard_n));
          job.shard_k = shard_k;
          job.shard_n = shard_n;
          if (threads < 1 || threads > 1024)
            throw InputError(detail::str("--threads: must be in [1, 1024], got ", threads));
          job.threads = threads;
          ScenarioKeys keys = sc.keys;
          robust_global_seed(keys);
          const Scenario rsc = build_scenario(std::move(keys));
          check_robust_job(rsc, job);
          std::vector<RobustConfiguration> configs =
              capture_joints_deg ? std::vector<RobustConfiguration>{given_robust_configuration(
                                       *rsc.model, *capture_joints_deg, capture_base_position, capture_base_rpy_deg)}
                                 : planned_robust_configurations(rsc);
          const RobustRun run = run_robust(rsc, spec, std::move(configs), job);
          r->summary = robust_summary(rsc, run, rsc.keys.file, FFSR_VERSION);
          r->json = r->summary.to_json().dump();
        }
        return r;
      },
      nb::is_method(), nb::name("robust"), nb::scope(scenario), "force_model"_a = "exact", "samples"_a = nb::none(),
      "seed"_a = nb::none(), "shard_k"_a = 0, "shard_n"_a = 1, "threads"_a = 1, "capture_joints_deg"_a = nb::none(),
      "capture_base_position"_a = std::vector<double>{0, 0, 0}, "capture_base_rpy_deg"_a = std::vector<double>{0, 0, 0},
      "The job `robust` (ffsr-optimize robust --config FILE): Monte Carlo of F_max over the scenario's [uncertainty]\n"
      "table for the configurations the main job plans (plain, optimized, global) or the one given\n"
      "(capture_joints_deg, deg). force_model: closed (Eq. 24), exact (Eq. 16) or multibody; samples, seed:\n"
      "override uncertainty.samples and uncertainty.seed; shard K of N of the samples; threads (results do not\n"
      "depend on them). The keywords are the command's flags (an underscore for a dash).");
  const ParetoJobOptions pareto_defaults;
  scenario.attr("pareto") = nb::cpp_function(
      [](const Scenario& sc, int levels, int starts) {
        ParetoJobOptions o;
        o.levels = levels;
        o.starts = starts;
        auto r = std::make_unique<ParetoRun>();
        {
          nb::gil_scoped_release release;
          r->job = pareto(sc, o);
          r->json = pareto_json(sc, r->job, FFSR_VERSION).dump();
        }
        return r;
      },
      nb::is_method(), nb::name("pareto"), nb::scope(scenario), "levels"_a = pareto_defaults.levels,
      "starts"_a = pareto_defaults.starts,
      "The job `pareto` (ffsr-optimize pareto --config FILE): the main job's runs, then the front of M_ie (Eq. 14)\n"
      "against the base's angular rate jump at the impact on the capture manifold at the global run's base pose\n"
      "(levels: epsilon levels between the two ends; starts: random starts of the two single-objective searches).");
}

}  // namespace ffsr::python
