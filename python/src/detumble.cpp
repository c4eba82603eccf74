// python/src/detumble.cpp -- the post-capture phase: attach_body (the stack model), grasp,
// grasp_at_capture and grasp_after_contact (the plastic lock), the DetumbleController (one step per
// tick) and run_detumble (the stack's dynamics with the controller in the loop). Names mirror C++.
#include "arguments.hpp"
#include "bindings.hpp"
#include "job_helpers.hpp"
#include "outputs.hpp"

#include "ffsr/control/contact_grasp.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/jobs/detumble.hpp"

#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

namespace ffsr::python {

using namespace nb::literals;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

BaseActuator actuator_arg(const std::string& name) {
  if (const std::optional<BaseActuator> a = find_base_actuator(name)) return *a;
  throw InputError(detail::str("detumble: unknown actuator '", name, "' (", base_actuator_names(", "), ")"));
}

DetumbleLimits limits_arg(const Model& stack, nb::handle joint_torque, const std::string& actuator,
                          double wheel_torque, double wheel_momentum, double thruster_force,
                          double thruster_torque, double gripper_force, double gripper_moment) {
  DetumbleLimits l;
  const VecIn t(joint_torque, "detumble", "joint_torque");
  t.require(stack.n());
  l.joint_torque = t.map();
  l.actuator = actuator_arg(actuator);
  l.wheel_torque = wheel_torque;
  l.wheel_momentum = wheel_momentum;
  l.thruster_force = thruster_force;
  l.thruster_torque = thruster_torque;
  l.gripper_force = gripper_force;
  l.gripper_moment = gripper_moment;
  return l;
}

DetumbleOptions options_arg(double max_decay, double max_base_decay, double rest_rate, bool stop_stack_spin,
                            bool hold) {
  DetumbleOptions o;
  o.max_decay = max_decay;
  o.max_base_decay = max_base_decay;
  o.rest_rate = rest_rate;
  o.stop_stack_spin = stop_stack_spin;
  o.hold = hold;
  return o;
}

DetumbleState state_arg(const Model& stack, const BasePose& base, nb::handle theta, nb::handle v,
                        nb::handle wheel_momentum) {
  const VecIn th(theta, "detumble", "theta"), vv(v, "detumble", "v");
  th.require(stack.n());
  vv.require(stack.nv());
  DetumbleState s{base, th.map(), vv.map(), Vector3::Zero()};
  if (!wheel_momentum.is_none()) s.wheel_momentum = vec3(wheel_momentum, "detumble", "wheel_momentum");
  return s;
}

nb::dict grasp_dict(const GraspResult& g) {
  nb::dict d;
  d["v_before"] = out(g.v_before);
  d["v_after"] = out(g.v_after);
  d["target_before"] = out(g.target_before);
  d["target_after"] = out(g.target_after);
  d["impulse"] = out(g.impulse);
  d["base_velocity_jump"] = out(g.base_velocity_jump);
  d["momentum_before"] = out(g.momentum_before);
  d["momentum_after"] = out(g.momentum_after);
  d["energy_before"] = g.energy_before;
  d["energy_after"] = g.energy_after;
  d["relative_twist_after"] = out(g.relative_twist_after);
  d["contact_point"] = out(g.contact_point);
  return d;
}

void bind_grasp_result(nb::module_& m) {
  nb::class_<AttachedBody>(
      m, "AttachedBody",
      "A rigid body attached at a frame: mass (kg), inertia about its centre of mass (its\n"
      "axes, kg m^2), pose of its centre-of-mass frame in the frame, the name of that frame.")
      .def(
          "__init__",
          [](AttachedBody* self, double mass, nb::handle inertia, const Pose& pose, const std::string& name) {
            AttachedBody b{mass, mat3(inertia, "AttachedBody", "inertia"), pose, name};
            detail::check_attached_body(b);
            new (self) AttachedBody(std::move(b));
          },
          "mass"_a, "inertia"_a, "pose"_a = Pose{}, "name"_a = "target",
          "InputError for a mass that is not positive and finite, an inertia that is not symmetric\n"
          "positive definite or breaks the triangle inequality, a pose that is not a rotation.")
      .def_ro("mass", &AttachedBody::mass)
      .def_prop_ro(
          "inertia", [](const AttachedBody& b) { return out(b.inertia); }, nb::rv_policy::automatic)
      .def_ro("pose", &AttachedBody::pose)
      .def_ro("name", &AttachedBody::name);
  nb::class_<GraspResult>(m, "GraspResult",
                          "The plastic lock of gripper and target: velocities before and after (inertial,\n"
                          "linear first), the impulse on the gripper at the contact point (N s, N m s).")
      .def_prop_ro(
          "v_before", [](const GraspResult& g) { return out(g.v_before); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "v_after", [](const GraspResult& g) { return out(g.v_after); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "target_before", [](const GraspResult& g) { return out(g.target_before); },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "target_after", [](const GraspResult& g) { return out(g.target_after); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "impulse", [](const GraspResult& g) { return out(g.impulse); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "base_velocity_jump", [](const GraspResult& g) { return out(g.base_velocity_jump); },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "momentum_before", [](const GraspResult& g) { return out(g.momentum_before); },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "momentum_after", [](const GraspResult& g) { return out(g.momentum_after); },
          nb::rv_policy::automatic)
      .def_ro("energy_before", &GraspResult::energy_before)
      .def_ro("energy_after", &GraspResult::energy_after)
      .def_prop_ro(
          "relative_twist_after", [](const GraspResult& g) { return out(g.relative_twist_after); },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "contact_point", [](const GraspResult& g) { return out(g.contact_point); },
          nb::rv_policy::automatic)
      .def_ro("body", &GraspResult::body)
      .def("to_dict", &grasp_dict)
      .def("__repr__", [](const GraspResult& g) {
        return detail::str("GraspResult(impulse ", g.impulse.head<3>().norm(), " N s, ",
                           g.impulse.tail<3>().norm(), " N m s, energy ", g.energy_before, " -> ",
                           g.energy_after, " J)");
      });
}

void bind_detumble_result(nb::module_& m) {
  nb::class_<DetumbleRunResult>(m, "DetumbleResult", "The post-capture run's summary and series (SI units).")
      .def_ro("at_rest", &DetumbleRunResult::at_rest)
      .def_ro("time_to_rest", &DetumbleRunResult::time_to_rest)
      .def_ro("peak_joint_torque", &DetumbleRunResult::peak_joint_torque)
      .def_ro("peak_joint", &DetumbleRunResult::peak_joint)
      .def_ro("peak_gripper_force", &DetumbleRunResult::peak_gripper_force)
      .def_ro("peak_gripper_moment", &DetumbleRunResult::peak_gripper_moment)
      .def_ro("base_attitude_excursion", &DetumbleRunResult::base_attitude_excursion)
      .def_ro("peak_wheel_momentum", &DetumbleRunResult::peak_wheel_momentum)
      .def_ro("momentum_drift", &DetumbleRunResult::momentum_drift)
      .def_ro("energy_start", &DetumbleRunResult::energy_start)
      .def_ro("energy_end", &DetumbleRunResult::energy_end)
      .def_ro("joint_work", &DetumbleRunResult::joint_work)
      .def_ro("dwell_peak_rate", &DetumbleRunResult::dwell_peak_rate)
      .def_ro("dwell_at_rest", &DetumbleRunResult::dwell_at_rest)
      .def_ro("ticks", &DetumbleRunResult::ticks)
      .def_prop_ro(
          "series_t",
          [](const DetumbleRunResult& r) {
            Eigen::VectorXd t(static_cast<Eigen::Index>(r.series.size()));
            for (size_t i = 0; i < r.series.size(); ++i) t(static_cast<Eigen::Index>(i)) = r.series[i].t;
            return out(t);
          },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "series_tau",
          [](const DetumbleRunResult& r) {
            Eigen::MatrixXd x(static_cast<Eigen::Index>(r.series.size()),
                              r.series.empty() ? 0 : r.series[0].command.tau.size());
            for (size_t i = 0; i < r.series.size(); ++i)
              x.row(static_cast<Eigen::Index>(i)) = r.series[i].command.tau.transpose();
            return out(x);
          },
          nb::rv_policy::automatic)
      .def("__repr__", [](const DetumbleRunResult& r) {
        return detail::str("DetumbleResult(", r.at_rest ? "at rest in " : "not at rest after ",
                           r.time_to_rest, " s, peak joint torque ", r.peak_joint_torque, " N m)");
      });
}

/// The job `detumble` (ffsr/jobs/detumble.hpp): one result per start (the scenario's configuration, or
/// each run of --run).
/// With the series as the command's --csv writes it (made from the same scenario).
struct DetumbleJobRun : JobRun<std::vector<DetumbleJobResult>> {
  std::string series_csv;
};

void bind_detumble_job(nb::module_& m) {
  job_result_class<DetumbleJobRun>(
      m, "DetumbleJobResult",
      "The grasp and the post-capture run (ffsr-optimize detumble), one per start. to_dict() is the\n"
      "command's --json.")
      .def_prop_ro(
          "runs", [](const DetumbleJobRun& r) { return r.result.size(); }, "The number of starts.")
      .def_prop_ro(
          "time_to_rest", [](const DetumbleJobRun& r) { return r.result.front().result.time_to_rest; },
          "The first start's time to rest, s.")
      .def_prop_ro(
          "peak_joint_torque",
          [](const DetumbleJobRun& r) { return r.result.front().result.peak_joint_torque; },
          "The first start's peak joint torque, N m.")
      .def_prop_ro(
          "peak_joint", [](const DetumbleJobRun& r) { return r.result.front().peak_joint_name; },
          "The joint of that peak.")
      .def_prop_ro(
          "plan_time_to_rest",
          [](const DetumbleJobRun& r) -> std::optional<double> {
            const auto& p = r.result.front().plan;
            return p ? std::optional<double>(p->plan.duration) : std::nullopt;
          },
          "The first start's time-optimal plan's time to rest, s (None without plan=True).")
      .def(
          "series_csv", [](const DetumbleJobRun& r) { return r.series_csv; },
          "The post-capture series as the command's --csv writes it (with the joint angles and the\n"
          "base's, the target's and every body's pose: ffsr.view.capture(..., detumble=this) animates it).");
  def_scenario_method(
      "detumble",
      [](const Scenario& sc, std::optional<std::string> run, bool plan) {
        return run_job<DetumbleJobRun>([&](DetumbleJobRun& r) {
          if (plan) require_detumble_planner();
          if (run)
            r.result = detumble_runs(sc, *run);
          else
            r.result.push_back(detumble(sc));
          if (plan) detumble_plans(sc, r.result);
          r.json = (run ? detumble_runs_json(sc, r.result, FFSR_VERSION)
                        : detumble_json(sc, r.result.front(), FFSR_VERSION))
                       .dump();
          r.series_csv = detumble_series_csv(sc, r.result);
        });
      },
      "run"_a = nb::none(), "plan"_a = false,
      "The job `detumble` (ffsr-optimize detumble --config FILE): the grasp at the end of the approach\n"
      "(or, with the key grasp_after = 'contact', after the Hertz contact run at its separation),\n"
      "then the stack brought to rest under the scenario's limits (joint-torque-limit, base-actuator,\n"
      "...). run: plain, optimized, global or all (as --run: from the main job's captures); default: the\n"
      "scenario's configuration. plan: also the time-optimal plan from each start and its re-run by CVODE\n"
      "(as --plan: to_dict()['plan'], plan_time_to_rest, the plan's rows in series_csv()).");
}

void bind_detumble_controller(nb::module_& m) {
  nb::class_<DetumbleController>(
      m, "DetumbleController",
      "The detumbling controller on the stack model: one step per tick, no allocation.")
      .def(
          "__init__",
          [](DetumbleController* self, const Model& stack, nb::handle gripper, const AttachedBody& body,
             nb::handle joint_torque, const std::string& actuator, double wheel_torque, double wheel_momentum,
             double thruster_force, double thruster_torque, double gripper_force, double gripper_moment,
             double max_decay, double max_base_decay, double rest_rate, bool stop_stack_spin, bool hold,
             double tick) {
            new (self) DetumbleController(
                stack, frame_arg(stack, gripper, "DetumbleController"), body,
                limits_arg(stack, joint_torque, actuator, wheel_torque, wheel_momentum, thruster_force,
                           thruster_torque, gripper_force, gripper_moment),
                options_arg(max_decay, max_base_decay, rest_rate, stop_stack_spin, hold), tick);
          },
          "stack"_a, "gripper"_a, "body"_a, "joint_torque"_a, "actuator"_a = "none", "wheel_torque"_a = 0.0,
          "wheel_momentum"_a = 0.0, "thruster_force"_a = 0.0, "thruster_torque"_a = 0.0,
          "gripper_force"_a = kInf, "gripper_moment"_a = kInf, "max_decay"_a = DetumbleOptions{}.max_decay,
          "max_base_decay"_a = DetumbleOptions{}.max_base_decay, "rest_rate"_a = 1e-3,
          "stop_stack_spin"_a = false, "hold"_a = true, "tick"_a = DetumbleRunOptions{}.tick,
          nb::keep_alive<1, 2>())
      .def_prop_ro("decay_cap", &DetumbleController::decay_cap,
                   "The largest decay rate the law asks: max_decay, at most half the tick's inverse (1/s).")
      .def(
          "step",
          [](DetumbleController& c, const Model& stack, const BasePose& base, nb::handle theta, nb::handle v,
             nb::handle wheel_momentum) {
            DetumbleCommand cmd = c.make_command();
            c.step(state_arg(stack, base, theta, v, wheel_momentum), cmd);
            nb::dict d;
            d["tau"] = out(cmd.tau);
            d["base_wrench"] = out(cmd.base_wrench);
            d["status"] = status_name(cmd.status);
            d["fault"] = fault_name(cmd.fault);
            d["joint_rate"] = cmd.joint_rate;
            d["relative_rate"] = cmd.relative_rate;
            d["stack_rate"] = cmd.stack_rate;
            d["brake_scale"] = cmd.brake_scale;
            d["decay"] = cmd.decay;
            d["base_decay"] = cmd.base_decay;
            d["passive"] = cmd.passive;
            return d;
          },
          "stack"_a, "base"_a, "theta"_a, "v"_a, "wheel_momentum"_a = nb::none(),
          "One tick: the command (tau, base_wrench, status...) as a dict.");
}

/// The grasp after the Hertz contact run (control/contact_grasp.hpp).
void bind_contact_grasp(nb::module_& m) {
  nb::class_<ContactGraspResult>(m, "ContactGraspResult",
                                 "The Hertz contact run (contact) and the lock at its separation (grasp);\n"
                                 "contact_impulse: the contact force's impulse on the gripper, N s.")
      .def_ro("contact", &ContactGraspResult::contact)
      .def_prop_ro(
          "contact_impulse", [](const ContactGraspResult& r) { return out(r.contact_impulse); },
          nb::rv_policy::automatic)
      .def_ro("grasp", &ContactGraspResult::grasp);
  m.def(
      "grasp_after_contact",
      [](const Model& model, nb::handle frame, const BasePose& base, nb::handle theta, const Target& target,
         double approach_speed, const ContactParams& params, const std::string& law) {
        const VecIn th(theta, "grasp_after_contact", "theta");
        th.require(model.n());
        speed_arg(approach_speed, "grasp_after_contact", "approach_speed");
        const int f = frame_arg(model, frame, "grasp_after_contact");
        const Eigen::VectorXd q = th.map();
        nb::gil_scoped_release release;
        return grasp_after_contact(model, f, base, q, target, approach_speed, params, law);
      },
      "model"_a, "frame"_a = nb::none(), "base"_a, "theta"_a, "target"_a, "approach_speed"_a,
      "params"_a = ContactParams(), "law"_a = "herbert-mcwhannell",
      "The grasp after the Hertz contact: simulate_contact from the first touch to the separation, then\n"
      "grasp() from the state it ends in (robot and target where the penetration returns to zero).");
}

}  // namespace

void bind_detumble(nb::module_& m) {
  bind_grasp_result(m);
  bind_detumble_result(m);
  bind_detumble_job(m);
  bind_detumble_controller(m);
  bind_contact_grasp(m);
  m.def(
      "attach_body",
      [](const Model& model, const std::string& frame, double mass, nb::handle inertia, const Pose& pose,
         const std::string& name) {
        AttachedBody b{mass, mat3(inertia, "attach_body", "inertia"), pose, name};
        return attach_body(model, frame, b);
      },
      "model"_a, "frame"_a, "mass"_a, "inertia"_a, "pose"_a = Pose{}, "name"_a = "target",
      "The model with a rigid body attached at `frame` (the stack): its inertia merged into the frame's\n"
      "body, a frame `name` at its centre of mass. InputError for a non-physical body or unknown frame.");
  m.def(
      "grasp",
      [](const Model& model, Data& data, const BasePose& base, nb::handle theta, nb::handle v,
         nb::handle frame, const Target& target) {
        check_data(model, data, "grasp");
        const VecIn th(theta, "grasp", "theta"), vv(v, "grasp", "v");
        return grasp(model, data, base, th.map(), vv.map(), frame_arg(model, frame, "grasp"), target);
      },
      "model"_a, "data"_a, "base"_a, "theta"_a, "v"_a, "frame"_a = nb::none(), "target"_a,
      "The plastic 6-D lock of the gripper (the frame's origin) on the target: the KKT system\n"
      "[M J^T; J 0][v+; -p] = [M v-; 0] with the target as a second free body.");
  m.def(
      "grasp_at_capture",
      [](const Model& model, nb::handle frame, const BasePose& base, nb::handle theta, const Target& target,
         double approach_speed) {
        const VecIn th(theta, "grasp_at_capture", "theta");
        th.require(model.n());
        return grasp_at_capture(model, frame_arg(model, frame, "grasp_at_capture"), base, th.map(), target,
                                speed_arg(approach_speed, "grasp_at_capture", "approach_speed"));
      },
      "model"_a, "frame"_a = nb::none(), "base"_a, "theta"_a, "target"_a, "approach_speed"_a,
      "The grasp at the end of the approach (contact point moving at approach_speed along the normal\n"
      "under zero momentum, the target's contact point on the frame's origin).");
  m.def(
      "run_detumble",
      [](const Model& stack, nb::handle gripper, const AttachedBody& body, const BasePose& base,
         nb::handle theta, nb::handle v, nb::handle joint_torque, const std::string& actuator,
         double wheel_torque, double wheel_momentum, double thruster_force, double thruster_torque,
         double gripper_force, double gripper_moment, double max_decay, double max_base_decay, double rest_rate,
         bool stop_stack_spin, bool hold, double tick, double horizon, double dwell) {
        const DetumbleLimits l = limits_arg(stack, joint_torque, actuator, wheel_torque, wheel_momentum,
                                            thruster_force, thruster_torque, gripper_force, gripper_moment);
        DetumbleRunOptions r;
        r.tick = tick;
        r.horizon = horizon;
        r.dwell = dwell;
        return run_detumble(stack, frame_arg(stack, gripper, "run_detumble"), body,
                            state_arg(stack, base, theta, v, nb::none()), l,
                            options_arg(max_decay, max_base_decay, rest_rate, stop_stack_spin, hold), r);
      },
      "stack"_a, "gripper"_a, "body"_a, "base"_a, "theta"_a, "v"_a, "joint_torque"_a, "actuator"_a = "none",
      "wheel_torque"_a = 0.0, "wheel_momentum"_a = 0.0, "thruster_force"_a = 0.0, "thruster_torque"_a = 0.0,
      "gripper_force"_a = kInf, "gripper_moment"_a = kInf, "max_decay"_a = DetumbleOptions{}.max_decay,
      "max_base_decay"_a = DetumbleOptions{}.max_base_decay, "rest_rate"_a = 1e-3, "stop_stack_spin"_a = false,
      "hold"_a = true, "tick"_a = DetumbleRunOptions{}.tick, "horizon"_a = DetumbleRunOptions{}.horizon,
      "dwell"_a = DetumbleRunOptions{}.dwell,
      "The post-capture run on the stack (ABA, CVODE) with the DetumbleController in the loop.");
}

}  // namespace ffsr::python
