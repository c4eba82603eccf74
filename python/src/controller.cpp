// python/src/controller.cpp -- the onboard capture controller (control/capture_controller.hpp) in
// ffsr._ffsr: made from a scenario's plan, one step per control tick that writes the joint-rate command
// and the base velocity into numpy arrays the caller owns (no allocation in the tick), and
// update_target for a new target estimate.
#include "common.hpp"

#include <ffsr/control/capture_controller.hpp>
#include <ffsr/io/scenario.hpp>

#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <variant>

namespace ffsr::python {
namespace {

using namespace nb::literals;
using detail::str;

/// A caller's output array: float64, 1-D, contiguous, writable, `n` entries; InputError otherwise.
double* out_buffer(nb::handle h, size_t n, const char* what) {
  nb::ndarray<> a;
  if (!nb::try_cast(h, a, false)) {
    nb::ndarray<nb::ro> ro;
    if (nb::try_cast(h, ro, false))
      throw InputError(str("CaptureController.step: ", what, " must be a writable array"));
    throw InputError(str("CaptureController.step: ", what, " must be a numpy array of float64"));
  }
  if (a.dtype() != nb::dtype<double>() || a.device_type() != nb::device::cpu::value)
    throw InputError(str("CaptureController.step: ", what, " must be an array of float64"));
  if (a.ndim() != 1 || a.shape(0) != n)
    throw InputError(str("CaptureController.step: ", what, " must have shape (", n, ",)"));
  if (n > 1 && a.stride(0) != 1) throw InputError(str("CaptureController.step: ", what, " must be contiguous"));
  return static_cast<double*>(a.data());
}

/// The controller of either policy with its state, estimate and command, sized once.
class PyController {
 public:
  PyController(const Scenario& sc, nb::handle theta_goal, double servo_gain, double quaternion_tolerance,
               int prediction_window)
      : model_(std::make_shared<Model>(*sc.model)),
        ctrl_(make(sc, *model_, theta_goal, servo_gain, quaternion_tolerance, prediction_window)) {
    std::visit([&](auto& c) { cmd_ = c.make_command(); }, ctrl_);
    state_.theta = Eigen::VectorXd::Zero(model_->n());
  }

  int joints() const { return model_->n(); }
  double duration() const {
    return std::visit([](const auto& c) { return c.duration(); }, ctrl_);
  }

  std::tuple<std::string, std::string, int> step(double t, nb::handle base_position, nb::handle base_orientation,
                                                 nb::handle theta, nb::handle target_position,
                                                 nb::handle target_attitude, nb::handle target_velocity,
                                                 nb::handle target_angular_velocity, nb::handle theta_dot_out,
                                                 nb::handle base_velocity_out) {
    const auto n = size_t(model_->n());
    double* td = out_buffer(theta_dot_out, n, "theta_dot_out");
    double* bv = out_buffer(base_velocity_out, 6, "base_velocity_out");
    // the measured inputs are copied into storage made once; the controller checks their values
    read3(base_position, "base_position", state_.base.position);
    read_quat(base_orientation, "base_orientation", state_.base.orientation);
    const VecIn th(theta, "CaptureController.step", "theta");
    th.require(Eigen::Index(n));
    state_.theta = th.map();
    read3(target_position, "target_position", est_.position);
    read_quat(target_attitude, "target_attitude", est_.attitude);
    read3(target_velocity, "target_velocity", est_.velocity);
    read3(target_angular_velocity, "target_angular_velocity", est_.angular_velocity);
    std::visit([&](auto& c) { c.step(t, state_, est_, cmd_); }, ctrl_);
    Eigen::Map<Eigen::VectorXd>(td, Eigen::Index(n)) = cmd_.theta_dot;
    Eigen::Map<Vector6>(bv) = cmd_.base_velocity;
    return {status_name(cmd_.status), fault_name(cmd_.fault), cmd_.fault_index};
  }

  std::string update_target(double t, nb::handle position, nb::handle attitude, nb::handle velocity,
                            nb::handle angular_velocity) {
    TargetEstimate e;
    read3(position, "position", e.position);
    read_quat(attitude, "attitude", e.attitude);
    read3(velocity, "velocity", e.velocity);
    read3(angular_velocity, "angular_velocity", e.angular_velocity);
    const ControlFault f = std::visit([&](auto& c) { return c.update_target(t, e); }, ctrl_);
    return fault_name(f);
  }

  const ControlCommand& command() const { return cmd_; }

 private:
  // Values are not checked here (NaN, a quaternion's norm): the controller reports them as faults.
  static void read3(nb::handle h, const char* what, Vector3& v) {
    const VecIn a(h, "CaptureController.step", what);
    a.require(3);
    v = a.map();
  }
  static void read_quat(nb::handle h, const char* what, Quaternion& q) {
    const VecIn a(h, "CaptureController.step", what);
    a.require(4);
    const auto c = a.map();
    q = Quaternion(c(3), c(0), c(1), c(2));
  }

  using AnyController = std::variant<CaptureController<GradientPolicy>, CaptureController<ServoPolicy>>;

  /// The paper's method (gradient policy), or the servo to theta_goal; the plan is the scenario's with
  /// the controller's own copy of the model.
  static AnyController make(const Scenario& sc, const Model& model, nb::handle theta_goal, double servo_gain,
                            double quaternion_tolerance, int prediction_window) {
    CaptureProblem pb = sc.problem;
    pb.model = &model;
    ControllerOptions copt;
    copt.quaternion_tolerance = quaternion_tolerance;
    copt.prediction_window = prediction_window;
    if (theta_goal.is_none()) return make_gradient_controller(pb, sc.task, sc.capture, copt);
    const VecIn goal(theta_goal, "CaptureController", "theta_goal");
    goal.require(model.n());
    return make_servo_controller(pb, sc.task, sc.capture, goal.map(), servo_gain, copt);
  }

  std::shared_ptr<Model> model_;
  AnyController ctrl_;
  ControllerState state_;
  TargetEstimate est_;
  ControlCommand cmd_;
};

}  // namespace

void bind_controller(nb::module_& m) {
  nb::class_<PyController>(m, "CaptureController",
                           "The capture approach as an onboard controller (the planner's rate law, Eq. 30-31, on the\n"
                           "measured state): made from a scenario's plan, the paper's method (gradient policy, gain\n"
                           "rho of the scenario) or, with theta_goal, the servo to a chosen capture configuration.")
      .def(nb::init<const Scenario&, nb::handle, double, double, int>(), "scenario"_a, "theta_goal"_a.none() = nb::none(),
           "servo_gain"_a = 0.0, "quaternion_tolerance"_a = 1e-3, "prediction_window"_a = 1)
      .def_prop_ro("joints", &PyController::joints)
      .def_prop_ro("duration", &PyController::duration, "T, s.")
      .def("step", &PyController::step, "t"_a, "base_position"_a, "base_orientation"_a, "theta"_a,
           "target_position"_a, "target_attitude"_a, "target_velocity"_a, "target_angular_velocity"_a,
           "theta_dot_out"_a, "base_velocity_out"_a,
           "One control tick at time t from the measured base pose (quaternion (x, y, z, w)), joint angles and\n"
           "target estimate (angular velocity in the target frame). Writes the joint-rate command into\n"
           "theta_dot_out (n,) and the base velocity that zero momentum gives with it into base_velocity_out\n"
           "(6,), float64 arrays the caller owns (made once). Returns (status, fault, fault_index): status\n"
           "'ok', 'damped', 'rate-limited' or 'fault'; a bad measured value is a fault, not an exception\n"
           "(zero rates), as on board. A wrong output array is an InputError.")
      .def("update_target", &PyController::update_target, "t"_a, "position"_a, "attitude"_a, "velocity"_a,
           "angular_velocity"_a,
           "Re-plans from a target estimate measured at t (propagated to T). Returns the fault name, 'none' on\n"
           "success.")
      .def_prop_ro("sigma_min", [](const PyController& c) { return c.command().sigma_min; },
                   "Smallest task singular value of the last step.")
      .def_prop_ro("null_scale", [](const PyController& c) { return c.command().null_scale; },
                   "Factor applied to the null-space rates in the last step (1: not scaled).")
      .def_prop_ro("reference", [](const PyController& c) { return out(c.command().reference); },
                   "x_d(t) of the last step.", nb::rv_policy::automatic)
      .def_prop_ro("end_effector", [](const PyController& c) { return out(c.command().end_effector); },
                   "p_e of the last step's measured state.", nb::rv_policy::automatic);
}

}  // namespace ffsr::python
