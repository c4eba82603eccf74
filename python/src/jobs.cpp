// python/src/jobs.cpp -- the command's one-configuration jobs as methods of ffsr.Scenario: inspect(),
// contact() and closed_loop(). Each result's to_dict() is the command's --json for the same scenario
// (the library makes the JSON: the command prints the same document).
#include "arguments.hpp"
#include "bindings.hpp"
#include "job_helpers.hpp"

#include "ffsr/jobs/closed_loop.hpp"
#include "ffsr/jobs/contact.hpp"
#include "ffsr/jobs/inspect.hpp"

#include <nanobind/stl/optional.h>
#include <nanobind/stl/vector.h>

namespace ffsr::python {
namespace {

using namespace nb::literals;

/// inspect's result: the evaluation and the command's JSON, made together.
struct InspectRun {
  std::optional<InspectResult> result;
  std::string json;
};

/// contact's rows (one per law) and closed_loop's result, each with the command's JSON.
using ContactRun = JobRun<std::vector<ContactRow>>;
using ClosedLoopRun = JobRun<ClosedLoopJobResult>;

/// The command's closed-loop flags, as keywords (an underscore for a dash) in its units.
ClosedLoopJobOptions closed_loop_options(const std::string& plan, std::optional<std::vector<double>> goal,
                                         double control_rate, double estimate_rate, double position_noise,
                                         double attitude_noise_deg, double velocity_noise,
                                         double spin_noise_deg, int prediction_window,
                                         std::uint64_t noise_seed, double rate_loop_bandwidth,
                                         double torque_limit, double record_every) {
  ClosedLoopJobOptions o;
  o.plan = plan;
  if (goal) o.goal_joints_deg = *goal;
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
  return o;
}

}  // namespace

void bind_base_disturbance(nb::module_& m) {
  nb::class_<BaseDisturbance>(
      m, "BaseDisturbance",
      "The base's velocity jump at the impact (single-body impulse P = M_ie delta_dot^- (1 + e)).")
      .def_ro("M_ie", &BaseDisturbance::M_ie, "Integrated effective mass (Eq. 14), kg.")
      .def_ro("approach_velocity", &BaseDisturbance::approach_velocity, "delta_dot^-, m/s.")
      .def_ro("restitution", &BaseDisturbance::restitution,
              "e of the single-body model (realized by the law).")
      .def_ro("impulse", &BaseDisturbance::impulse, "P, N s.")
      .def_prop_ro(
          "linear", [](const BaseDisturbance& d) { return out(d.linear); },
          "Jump of the base origin's velocity, m/s (inertial frame).", nb::rv_policy::automatic)
      .def_prop_ro(
          "angular", [](const BaseDisturbance& d) { return out(d.angular); },
          "Jump of the base's angular velocity, rad/s (inertial frame).", nb::rv_policy::automatic)
      .def_prop_ro("angular_rate", &BaseDisturbance::angular_rate, "|Delta w_0|, rad/s.");
}

void bind_inspect(nb::module_& m) {
  job_result_class<InspectRun>(
      m, "InspectResult",
      "One configuration evaluated (ffsr-optimize inspect): H, J_bm, J_f, m_e (Eq. 4), M_ie\n"
      "(Eq. 14) and the base's jump at the impact. to_dict() is the command's --json.")
      .def_prop_ro(
          "M_ie", [](const InspectRun& r) { return r.result->M_ie; },
          "Integrated effective mass (Eq. 14) under the scenario's joint model, kg.")
      .def_prop_ro(
          "m_e", [](const InspectRun& r) { return r.result->m_e; }, "Effective mass along u (Eq. 4), kg.")
      .def_prop_ro(
          "direction", [](const InspectRun& r) { return out(r.result->u); },
          "The contact normal u (inertial frame).", nb::rv_policy::automatic)
      .def_prop_ro(
          "H", [](const InspectRun& r) { return out(r.result->data.H); },
          "Generalized inertia matrix H ((6 + n) x (6 + n)).", nb::rv_policy::automatic)
      .def_prop_ro(
          "J_bm", [](const InspectRun& r) { return out(r.result->data.J); },
          "End-effector Jacobian [J_b J_m] (6 x (6 + n), linear rows first).", nb::rv_policy::automatic)
      .def_prop_ro(
          "J_f", [](const InspectRun& r) { return out(r.result->Jf); },
          "Generalized Jacobian J_f (6 x n, linear rows first).", nb::rv_policy::automatic)
      .def_prop_ro(
          "end_effector", [](const InspectRun& r) { return r.result->ee; }, "The end-effector's pose.")
      .def_prop_ro(
          "base_disturbance", [](const InspectRun& r) { return r.result->disturbance; },
          "The base's jump at the impact, or None when the end-effector does not approach the target.")
      .def_prop_ro(
          "contact_joints",
          [](const InspectRun& r) { return std::string(joint_model_name(r.result->joints.model)); },
          "The joint model of M_ie, m_e and the base's jump (free, locked, armature).");

  def_scenario_method(
      "inspect",
      [](const Scenario& sc) {
        require_capture_scenario(sc);
        return run_job<InspectRun>([&sc](InspectRun& r) {
          r.result.emplace(inspect(sc));
          r.json = inspect_json(sc, *r.result, FFSR_VERSION).dump();
        });
      },
      "The job `inspect` (ffsr-optimize inspect --config FILE): the start configuration evaluated: H, J_f,\n"
      "m_e (Eq. 4), M_ie (Eq. 14) and the base's jump at the impact under the scenario's joint model\n"
      "(contact-joints), the distances between the shapes.");
}

void bind_contact_job(nb::module_& m) {
  nb::class_<ContactRow>(m, "ContactRow", "One law's row of the job contact.")
      .def_ro("model", &ContactRow::model, "The law's name (Table 1).")
      .def_ro("M_ie", &ContactRow::M_ie,
              "Integrated effective mass (Eq. 14) under the chosen joint model, kg.")
      .def_ro("approach_velocity", &ContactRow::v_in, "delta_dot^- of the multibody run, m/s.")
      .def_ro("f_max_closed_form", &ContactRow::f_closed, "Peak force, closed form (Eq. 24), N.")
      .def_ro("f_max_exact", &ContactRow::f_exact, "Peak force, exact single-body peak (Eq. 16), N.")
      .def_ro("f_max_multibody", &ContactRow::f_multibody,
              "Peak force of the multibody reference (CVODE), N.")
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
          "t (s), F (N), delta (m) of the multibody run, one row per sample (contact(series=True); else "
          "empty).",
          nb::rv_policy::automatic);

  job_result_class<ContactRun>(
      m, "ContactResult",
      "The maximum contact force (ffsr-optimize contact): closed form (Eq. 24), exact (Eq. 16) and\n"
      "the multibody reference, a row per law. to_dict() is the command's --json.")
      .def_prop_ro(
          "rows", [](const ContactRun& r) { return r.result; },
          "One row per law (every law of Table 1 for model='all').")
      .def_prop_ro(
          "M_ie", [](const ContactRun& r) { return r.result.front().M_ie; }, "M_ie of the first row, kg.")
      .def_prop_ro(
          "f_max_multibody", [](const ContactRun& r) { return r.result.front().f_multibody; },
          "The multibody peak of the first row, N.");

  def_scenario_method(
      "contact",
      [](const Scenario& sc, std::optional<std::string> model, std::optional<std::string> contact_joints,
         bool series) {
        require_capture_scenario(sc);
        return run_job<ContactRun>([&](ContactRun& r) {
          std::optional<Scenario> variant;
          const Scenario& s =
              scenario_with(sc, {{"model", model}, {"contact-joints", contact_joints}}, variant);
          ContactJobOptions o;
          o.record_series = series;
          r.result = contact(s, o);
          r.json = contact_json(s, r.result, FFSR_VERSION).dump();
        });
      },
      "model"_a = nb::none(), "contact_joints"_a = nb::none(), "series"_a = false,
      "The job `contact` (ffsr-optimize contact --config FILE): the peak contact force at the start\n"
      "configuration by the closed form (Eq. 24), the exact single-body peak (Eq. 16) and the multibody\n"
      "reference (CVODE, robot + target). model: a law of Table 1 or 'all' (default: the scenario's);\n"
      "contact_joints: free, locked, armature or 'all' (default: the scenario's; as --model and\n"
      "--contact-joints); series: keep F(t), delta(t).");
}

void bind_closed_loop(nb::module_& m) {
  job_result_class<ClosedLoopRun>(
      m, "ClosedLoopResult",
      "The capture controller in a closed loop with the robot's dynamics (ffsr-optimize closed-loop),\n"
      "beside the open-loop plan it follows. to_dict() is the command's --json.")
      .def_prop_ro(
          "plan", [](const ClosedLoopRun& r) { return r.result.plan.name; }, "The plan followed.")
      .def_prop_ro(
          "open_loop", [](const ClosedLoopRun& r) { return r.result.plan.open; }, "The open-loop plan's run.")
      .def_prop_ro(
          "theta", [](const ClosedLoopRun& r) { return out(r.result.result.theta); },
          "The closed loop's configuration at T, rad.", nb::rv_policy::automatic)
      .def_prop_ro(
          "capture_error", [](const ClosedLoopRun& r) { return r.result.result.capture_error; },
          "|p_e(T) - capture point| of the closed loop, m.")
      .def_prop_ro(
          "M_ie", [](const ClosedLoopRun& r) { return r.result.result.M_ie; },
          "M_ie (Eq. 14) at the closed loop's capture configuration, kg.")
      .def_prop_ro(
          "f_max_closed_form", [](const ClosedLoopRun& r) { return r.result.result.f_max_closed_form; },
          "Eq. 24 at that M_ie, N.")
      .def_prop_ro(
          "max_torque", [](const ClosedLoopRun& r) { return r.result.result.max_torque; },
          "Largest |tau_k|, N m.")
      .def_prop_ro(
          "ticks", [](const ClosedLoopRun& r) { return r.result.result.ticks; }, "Control ticks flown.")
      .def(
          "series_csv", [](const ClosedLoopRun& r) { return closed_loop_series_csv(r.result.result); },
          "The recorded samples (record_every) as the command's --csv.");

  const ClosedLoopJobOptions d;
  def_scenario_method(
      "closed_loop",
      [](const Scenario& sc, const std::string& plan, std::optional<std::vector<double>> goal_joints_deg,
         double control_rate, double estimate_rate, double position_noise, double attitude_noise_deg,
         double velocity_noise, double spin_noise_deg, int prediction_window, std::uint64_t noise_seed,
         double rate_loop_bandwidth, double torque_limit, double record_every) {
        require_capture_scenario(sc);
        const ClosedLoopJobOptions o =
            closed_loop_options(plan, std::move(goal_joints_deg), control_rate, estimate_rate, position_noise,
                                attitude_noise_deg, velocity_noise, spin_noise_deg, prediction_window,
                                noise_seed, rate_loop_bandwidth, torque_limit, record_every);
        return run_job<ClosedLoopRun>([&](ClosedLoopRun& r) {
          r.result = closed_loop(sc, o);
          r.json = closed_loop_json(sc, r.result, FFSR_VERSION).dump();
        });
      },
      "plan"_a = d.plan, "goal_joints_deg"_a = nb::none(), "control_rate"_a = d.loop.control_rate,
      "estimate_rate"_a = d.loop.estimate_rate, "position_noise"_a = d.loop.noise.position,
      "attitude_noise_deg"_a = d.attitude_noise_deg, "velocity_noise"_a = d.loop.noise.velocity,
      "spin_noise_deg"_a = d.spin_noise_deg, "prediction_window"_a = d.controller.prediction_window,
      "noise_seed"_a = d.loop.seed, "rate_loop_bandwidth"_a = d.loop.loop.bandwidth,
      "torque_limit"_a = d.loop.loop.torque_limit, "record_every"_a = d.loop.record_every,
      "The job `closed-loop` (ffsr-optimize closed-loop --config FILE): the capture controller with the\n"
      "robot's full dynamics, joint rate loops and a noisy target estimate, beside the open-loop plan it\n"
      "follows: plan 'paper' (Eq. 29-31) or 'global' (the global run's servo), or the servo to\n"
      "goal_joints_deg. The keywords are the command's flags (an underscore for a dash), in its units;\n"
      "record_every: s between recorded samples (series_csv()). InputError naming the flag.");
}

}  // namespace ffsr::python
