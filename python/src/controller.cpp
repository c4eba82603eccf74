// python/src/controller.cpp -- the capture controller in ffsr._ffsr: CaptureController (the paper's
// gradient policy or the servo to a chosen capture configuration, made from a Scenario as the C++
// make_gradient_controller / make_servo_controller make it), TargetEstimate, and the tick step(): its
// inputs read as every argument is (arguments.hpp) but their values left to the controller (a bad one is
// a fault status), its outputs written into the caller's own arrays, checked strictly; no array per tick.
#include "arguments.hpp"
#include "bindings.hpp"
#include "outputs.hpp"

#include "ffsr/control/capture_controller.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <variant>

namespace ffsr::python {
namespace {

using namespace nb::literals;
using detail::str;

using OutArray = nb::ndarray<double, nb::c_contig, nb::device::cpu>;

/// The caller's output array of `n` float64 entries (writable, C-contiguous, 1-D), or InputError
/// naming what is wrong with it. The fast path is one cast without conversion.
double* out_array(nb::handle h, size_t n, const char* where, const char* what) {
  OutArray a;
  if (nb::try_cast(h, a, false) && a.ndim() == 1 && a.shape(0) == n) return a.data();
  // the reason, for the message
  nb::ndarray<nb::ro> any;
  if (!nb::try_cast(h, any, false))
    throw InputError(str(where, ": ", what, " must be a numpy array of float64 (the caller's output), got ",
                         py_type_name(h)));
  if (any.device_type() != nb::device::cpu::value)
    throw InputError(str(where, ": ", what, " must be an array in CPU memory"));
  if (any.dtype() != nb::dtype<double>())
    throw InputError(str(where, ": ", what, " must be an array of float64 (numpy.zeros(", n,
                         ") makes one), got another dtype"));
  if (any.ndim() != 1 || any.shape(0) != n) {
    std::string shape;
    for (size_t i = 0; i < any.ndim(); ++i) shape += str(i ? ", " : "", any.shape(i));
    if (any.ndim() == 1) shape += ",";
    throw InputError(str(where, ": ", what, " has shape (", shape, "), expected (", n, ",)"));
  }
  if (any.shape(0) > 1 && any.stride(0) != 1)
    throw InputError(
        str(where, ": ", what, " must be C-contiguous (a strided view is not written in place)"));
  throw InputError(str(where, ": ", what, " is read-only"));
}

/// The estimate of a target from arrays (checked for size here, for values by the controller).
TargetEstimate make_estimate(nb::handle position, nb::handle attitude, nb::handle velocity,
                             nb::handle angular_velocity) {
  TargetEstimate e;
  const char* w = "TargetEstimate";
  const Values any = Values::Any;  // NaN: the controller's fault
  if (!position.is_none()) e.position = vec3(position, w, "position", any);
  if (!attitude.is_none()) e.attitude = quat_xyzw(attitude, w, "attitude", any);
  if (!velocity.is_none()) e.velocity = vec3(velocity, w, "velocity", any);
  if (!angular_velocity.is_none()) e.angular_velocity = vec3(angular_velocity, w, "angular_velocity", any);
  return e;
}

/// The Python CaptureController: the C++ controller (either policy), the tick's input and output storage.
class Controller {
 public:
  Controller(const Scenario& sc, nb::handle goal, double gain, double quaternion_tolerance,
             int prediction_window)
      : options_(sc.capture),
        ctrl_(make(sc, goal, gain, quaternion_tolerance, prediction_window, options_)),
        state_{sc.problem.base, sc.problem.theta},
        estimate_(target_estimate(sc.problem.target)),
        command_(std::visit([](auto& c) { return c.make_command(); }, ctrl_)) {}

  int joints() const {
    return std::visit([](auto& c) { return c.joints(); }, ctrl_);
  }
  double duration() const { return options_.duration; }
  double feedback() const { return options_.feedback; }
  double gain() const { return options_.gain; }
  double max_joint_rate() const { return options_.max_joint_rate; }
  bool servo() const { return std::holds_alternative<CaptureController<ServoPolicy>>(ctrl_); }
  const CaptureSetup& setup() const {
    return std::visit([](auto& c) -> const CaptureSetup& { return c.setup(); }, ctrl_);
  }
  const ControlCommand& command() const { return command_; }
  const TargetEstimate& estimate() const { return estimate_; }

  std::string step(double t, nb::handle base_position, nb::handle base_orientation, nb::handle theta,
                   nb::handle theta_dot, nb::handle base_velocity, const TargetEstimate* estimate,
                   nb::handle reference, nb::handle end_effector) {
    const int n = joints();
    // every argument first: nothing is written when one is wrong
    const VecIn p(base_position, "CaptureController.step", "base_position", Values::Any);
    p.require(3);
    const VecIn q(base_orientation, "CaptureController.step", "base_orientation", Values::Any);
    q.require(4);
    const VecIn th(theta, "CaptureController.step", "theta", Values::Any);
    th.require(n);
    double* td = out_array(theta_dot, size_t(n), "CaptureController.step", "theta_dot");
    double* xb = out_array(base_velocity, 6, "CaptureController.step", "base_velocity");
    double* ref =
        reference.is_none() ? nullptr : out_array(reference, 3, "CaptureController.step", "reference");
    double* ee = end_effector.is_none()
                     ? nullptr
                     : out_array(end_effector, 3, "CaptureController.step", "end_effector");
    state_.base.position = p.map();
    state_.base.orientation.coeffs() =
        q.map();              // (x, y, z, w): Eigen's order; the norm is the controller's check
    state_.theta = th.map();  // the same size: no allocation
    const TargetEstimate& e = estimate ? *estimate : estimate_;
    std::visit([&](auto& c) { c.step(t, state_, e, command_); }, ctrl_);
    Eigen::Map<Eigen::VectorXd>{td, n} = command_.theta_dot;
    Eigen::Map<Vector6>{xb} = command_.base_velocity;
    if (ref) Eigen::Map<Vector3>{ref} = command_.reference;
    if (ee) Eigen::Map<Vector3>{ee} = command_.end_effector;
    return status_name(command_.status);
  }

  std::string update_target(double t, const TargetEstimate& e) {
    const ControlFault f = std::visit([&](auto& c) { return c.update_target(t, e); }, ctrl_);
    if (f == ControlFault::None) estimate_ = e;
    return fault_name(f);
  }

 private:
  using Variant = std::variant<CaptureController<GradientPolicy>, CaptureController<ServoPolicy>>;

  static Variant make(const Scenario& sc, nb::handle goal, double gain, double qtol, int window,
                      CaptureOptions& options) {
    ControllerOptions copt;
    copt.quaternion_tolerance = qtol;
    copt.prediction_window = window;
    options.progress = nullptr;
    options.record_series = false;
    if (goal.is_none()) {
      if (gain != 0.0)
        throw InputError(
            "CaptureController: gain is the servo's (give goal); the paper's method takes the "
            "scenario's gain (rho)");
      return Variant(std::in_place_index<0>, make_gradient_controller(sc.problem, sc.task, options, copt));
    }
    const VecIn g(goal, "CaptureController", "goal");  // its size: the library's check
    // the servo as the command's closed-loop runs it: no gradient term, the global run's rate limit
    options.gain = 0.0;
    options.max_joint_rate = sc.keys.max_joint_rate_deg * M_PI / 180.0;
    return Variant(std::in_place_index<1>,
                   make_servo_controller(sc.problem, sc.task, options, Eigen::VectorXd(g.map()), gain, copt));
  }

  CaptureOptions options_;
  Variant ctrl_;
  ControllerState state_;
  TargetEstimate estimate_;
  ControlCommand command_;
};

const char* const kStepDoc =
    "One control tick at time t (s, in [0, T]) from the measured state: the joint-rate command of the\n"
    "rate law (Eq. 30-31 evaluated on the measured state instead of integrated),\n"
    "    theta_dot = J_t^+ (x_d_dot + k_p (x_d - p_e)) + alpha qd_null,\n"
    "with the line reference x_d(t) and the plan's null-space policy (the gradient of M_ie, Eq. 14, for\n"
    "the paper's method; the servo to `goal` otherwise), and the base velocity [v_0; omega_0] that zero\n"
    "momentum gives with it (Eq. 2: H_b x_b_dot + H_bm theta_dot = 0).\n"
    "\n"
    "base_position (3,), base_orientation (4,: x, y, z, w), theta (n,): the measured state.\n"
    "theta_dot (n,), base_velocity (6,), and optionally reference (3,: x_d(t)) and end_effector (3,: p_e):\n"
    "numpy arrays of float64 that the caller owns (C-contiguous, writable, exactly that shape); the tick\n"
    "writes into them and makes no array. estimate: the target's TargetEstimate at this tick (checked:\n"
    "a diverged estimate stops the arm), None: the last one given to update_target (at first the\n"
    "scenario's target at t = 0).\n"
    "\n"
    "Returns the status: 'ok', 'damped' (the smallest task singular value is below the threshold: damped\n"
    "least squares), 'rate-limited' (the null-space term was scaled down, or the task alone asks more\n"
    "than the joint-rate limit) or 'fault' (an input value is bad: t outside [0, T], a non-finite value,\n"
    "a quaternion norm off by more than the tolerance, a joint outside its limits, a bad estimate; the\n"
    "field is in `fault`, the joint or component in `fault_index`, and the rates written are zero).\n"
    "The state is read as numpy.asarray(x, dtype=float64) reads it (lists, other dtypes, any layout);\n"
    "a wrong shape of an argument, or a wrong dtype or layout of an output array (never a converted\n"
    "copy, whose writes the caller would not see), is an InputError naming it, and nothing is written.";

}  // namespace

void bind_target_estimate(nb::module_& m) {
  nb::class_<TargetEstimate>(
      m, "TargetEstimate",
      "What a vision filter measures of the target at a time: centre of mass (inertial), attitude\n"
      "quaternion (x, y, z, w), velocity (inertial) and spin (target frame, rad/s). Its mass,\n"
      "inertia, contact offset and normal are the plan's. Values are checked by the controller.")
      .def(
          "__init__",
          [](TargetEstimate* self, nb::handle position, nb::handle attitude, nb::handle velocity,
             nb::handle angular_velocity) {
            new (self) TargetEstimate(make_estimate(position, attitude, velocity, angular_velocity));
          },
          "position"_a.none() = nb::none(), "attitude"_a.none() = nb::none(),
          "velocity"_a.none() = nb::none(), "angular_velocity"_a.none() = nb::none())
      .def_static("from_target", &target_estimate, "target"_a, "The estimate a Target describes (its state).")
      .def_prop_ro(
          "position", [](const TargetEstimate& e) { return out(e.position); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "attitude", [](const TargetEstimate& e) { return out_quat(e.attitude); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "velocity", [](const TargetEstimate& e) { return out(e.velocity); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "angular_velocity", [](const TargetEstimate& e) { return out(e.angular_velocity); },
          nb::rv_policy::automatic);
}

void bind_controller(nb::module_& m) {
  nb::class_<Controller>(
      m, "CaptureController",
      "The capture approach as an onboard controller (C++ ffsr::CaptureController): the planner's\n"
      "rate law (Eq. 30-31) evaluated at every control tick on the measured state, with its storage\n"
      "sized once. Driven by the planner's RK4 with the exact state it reproduces the planned run.\n"
      "Re-planning from a new target estimate: update_target.")
      .def(
          nb::init<const Scenario&, nb::handle, double, double, int>(), "scenario"_a,
          "goal"_a.none() = nb::none(), "gain"_a = 0.0, "quaternion_tolerance"_a = 1e-3,
          "prediction_window"_a = 1, nb::keep_alive<1, 2>(),
          "The controller of a scenario's capture (its robot, target, task and planner keys: duration, "
          "step,\n"
          "feedback k_p, singular-value threshold, damping).\n"
          "goal None: the paper's method, the gradient policy of M_ie (Eq. 30-31, the scenario's gain rho),\n"
          "as make_gradient_controller. goal (n,) rad: the servo to that capture configuration (e.g. the\n"
          "global run's), gain its gain in 1/s (0: 10 / T), the joint rates limited by the scenario's\n"
          "max-joint-rate-deg, as make_servo_controller and `ffsr-optimize closed-loop --goal-joints-deg`.\n"
          "quaternion_tolerance: the largest accepted | |q| - 1 | of the base and estimate quaternions;\n"
          "prediction_window: update_target's capture point is the mean of the last so many predictions.\n"
          "InputError naming CaptureController (or the argument) for a bad input. Keeps the scenario alive.")
      .def_prop_ro("joints", &Controller::joints, "Number of joints n.")
      .def_prop_ro("duration", &Controller::duration, "T, s: the capture time.")
      .def_prop_ro("feedback", &Controller::feedback, "k_p, 1/s, of the rate law.")
      .def_prop_ro("gain", &Controller::gain, "rho of Eq. 30 (0 for the servo).")
      .def_prop_ro("max_joint_rate", &Controller::max_joint_rate, "Joint-rate limit, rad/s (0: none).")
      .def_prop_ro("servo", &Controller::servo, "True for the servo to a goal, False for the paper's method.")
      .def_prop_ro(
          "capture_point", [](const Controller& c) { return out(c.setup().capture.x_cap); },
          "The current plan's capture point x_cap at T (moved by update_target), m.",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "normal", [](const Controller& c) { return out(c.setup().capture.u_cap); },
          "The current plan's inertial contact normal at T.", nb::rv_policy::automatic)
      .def_prop_ro(
          "task_rows", [](const Controller& c) { return std::vector<int>(c.setup().rows); },
          "The rows of J_f (and of [v; omega]) the task constrains.")
      .def("step", &Controller::step, "t"_a, "base_position"_a, "base_orientation"_a, "theta"_a,
           "theta_dot"_a, "base_velocity"_a, "estimate"_a.none() = nb::none(),
           "reference"_a.none() = nb::none(), "end_effector"_a.none() = nb::none(), kStepDoc)
      .def("update_target", &Controller::update_target, "t"_a, "estimate"_a,
           "Re-plans from a target estimate measured at t (s, in [0, T)): the target propagated torque-free "
           "to T\n"
           "gives the new capture point and normal; the line reference is re-anchored from t with a quintic\n"
           "that keeps its position, velocity and acceleration at t. Returns 'none' on success, else the\n"
           "faulty field ('time', 'target position', ...) and the plan is left as it was. The estimate then\n"
           "becomes step()'s default.")
      .def_prop_ro(
          "status", [](const Controller& c) { return std::string(status_name(c.command().status)); },
          "The last tick's status.")
      .def_prop_ro(
          "fault", [](const Controller& c) { return std::string(fault_name(c.command().fault)); },
          "The last tick's faulty field ('none' unless the status is 'fault').")
      .def_prop_ro(
          "fault_index", [](const Controller& c) { return c.command().fault_index; },
          "The joint (joint angle, joint limit) or the vector component of the last fault, else -1.")
      .def_prop_ro(
          "sigma_min", [](const Controller& c) { return c.command().sigma_min; },
          "The last tick's smallest task singular value.")
      .def_prop_ro(
          "null_scale", [](const Controller& c) { return c.command().null_scale; },
          "The factor the last tick applied to the null-space rates (1: not scaled).");
}

}  // namespace ffsr::python
