// ffsr/control/detumble_dynamics.hpp -- the stack's equations of motion as the post-capture phase
// integrates them (the robot holding the target: ABA on the stack model, the base quaternion, the
// momentum the reaction wheels store), with the load on the gripper; and one classical Runge-Kutta
// step of them. Eigen only: the CVODE run (control/detumble_run.hpp), the planner and the onboard
// core's plant model (ffsr_detumble_predict) share it.
#pragma once

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/algorithm/grasp.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/control/detumble_controller.hpp"

namespace ffsr {

namespace detail {

/// The stack's ODE: y = [p_0 (3), base quaternion (x, y, z, w), theta (n), v (6+n), wheel momentum (3,
/// inertial)] with the command held; ABA on the stack. Also the gripper load of a state.
struct DetumbleSystem {
  const Model& model;
  Data data;
  int n;
  Eigen::VectorXd tau, a, theta, v;
  DetumbleSystem(const Model& m)
      : model(m), data(m), n(m.n()), tau(m.nv()), a(m.nv()), theta(m.n()), v(m.nv()) {}
  Eigen::Index size() const { return 16 + 2 * n; }
  BasePose base(const Eigen::Ref<const Eigen::VectorXd>& y) const {
    BasePose b;
    b.position = y.head<3>();
    b.orientation = Quaternion(y(6), y(3), y(4), y(5)).normalized();
    return b;
  }
  Eigen::VectorXd pack(const DetumbleState& s) const {
    Eigen::VectorXd y(size());
    const Quaternion q = s.base.orientation.normalized();
    y << s.base.position, q.x(), q.y(), q.z(), q.w(), s.theta, s.v, s.wheel_momentum;
    return y;
  }
  DetumbleState unpack(const Eigen::Ref<const Eigen::VectorXd>& y) const {
    return {base(y), y.segment(7, n), y.segment(7 + n, 6 + n), y.tail<3>()};
  }
  /// ydot at y for the command c (wheel torque: the base's moment when the actuator is wheels).
  void rhs(const Eigen::Ref<const Eigen::VectorXd>& y, const DetumbleCommand& c, bool wheels,
           Eigen::Ref<Eigen::VectorXd> ydot) {
    const BasePose b = base(y);
    theta = y.segment(7, n);
    v = y.segment(7 + n, 6 + n);
    tau << c.base_wrench, c.tau;
    aba(model, data, b, theta, v, tau, a);
    const Vector3 w = v.segment<3>(3);
    const Quaternion qd = Quaternion(0, w.x(), w.y(), w.z()) * Quaternion(y(6), y(3), y(4), y(5));
    ydot.head<3>() = v.head<3>();
    ydot.segment<4>(3) = 0.5 * qd.coeffs();
    ydot.segment(7, n) = v.tail(n);
    ydot.segment(7 + n, 6 + n) = a;
    ydot.tail<3>() = wheels ? Vector3(-c.base_wrench.tail<3>()) : Vector3::Zero();
  }
  /// The wrench the gripper applies on the target (its rate of momentum, the Newton-Euler equation of
  /// the attached body from the stack's accelerations): f = I_t A_e + V_e x* (I_t V_e) - I_t a_g about
  /// p_0, moved to the contact point. Runs aba (rhs) first. Writes force and moment.
  void gripper_load(const Eigen::Ref<const Eigen::VectorXd>& y, const DetumbleCommand& c, int gripper,
                    const AttachedBody& body, Vector3& force, Vector3& moment) {
    Eigen::VectorXd ydot(size());
    rhs(y, c, false, ydot);
    const int e = model.frame(gripper).body;
    const Pose pg = frame_pose(model, data, gripper);
    const Pose pt = pg * body.pose;
    const Vector3& p0 = data.p[0];
    const SpatialInertia It =
        SpatialInertia::from_com(body.mass, pt.p - p0, pt.R * body.inertia * pt.R.transpose());
    Vector6 f = It * data.A[static_cast<size_t>(e)], bias;
    rigid_bias_force(It, data.V[static_cast<size_t>(e)], model.gravity, bias);
    f += bias;
    force = f.head<3>();
    moment = f.tail<3>() - (pg.p - p0).cross(force);
  }
  /// The stack's kinetic energy and [P; L about o] plus the wheels' momentum.
  void energy_momentum(const Eigen::Ref<const Eigen::VectorXd>& y, double& T, Vector6& h) {
    const BasePose b = base(y);
    theta = y.segment(7, n);
    v = y.segment(7 + n, 6 + n);
    forward_kinematics(model, data, b, theta);
    T = kinetic_energy(model, data, v);
    h = robot_momentum_about_origin(model, data, v);
    h.tail<3>() += y.tail<3>();
  }
};

}  // namespace detail

namespace detail {

/// Workspace of rk4_stack_step (sized for a system at construction; the step then does not allocate).
struct StackRk4 {
  Eigen::VectorXd k1, k2, k3, k4, tmp;
  explicit StackRk4(Eigen::Index size) : k1(size), k2(size), k3(size), k4(size), tmp(size) {}
};

/// One classical Runge-Kutta step of the stack's state y over dt with the right-hand side f(y, ydot)
/// (the stack's ODE under a command, which may depend on y); the quaternion renormalized after the step.
template <class Rhs>
inline void rk4_stack_step(StackRk4& w, Eigen::VectorXd& y, double dt, const Rhs& f) {
  f(y, w.k1);
  w.tmp = y + 0.5 * dt * w.k1;
  f(w.tmp, w.k2);
  w.tmp = y + 0.5 * dt * w.k2;
  f(w.tmp, w.k3);
  w.tmp = y + dt * w.k3;
  f(w.tmp, w.k4);
  y += dt / 6 * (w.k1 + 2 * w.k2 + 2 * w.k3 + w.k4);
  y.segment<4>(3).normalize();
}

/// One classical Runge-Kutta step of the stack's state y over dt with the command c held.
inline void rk4_stack_step(DetumbleSystem& sys, StackRk4& w, Eigen::VectorXd& y, const DetumbleCommand& c,
                           bool wheels, double dt) {
  rk4_stack_step(w, y, dt, [&](const Eigen::VectorXd& x, Eigen::VectorXd& xd) { sys.rhs(x, c, wheels, xd); });
}

}  // namespace detail

}  // namespace ffsr
