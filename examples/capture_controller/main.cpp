// The capture controller in a control loop on the paper's 7-DOF robot (Zhang 2022, Section 5.2:
// position task, rho = -0.01, T = 157 s): 100 Hz ticks, a target estimate every 0.2 s, the joint-rate
// command printed every 10 s. The "robot" here integrates the commanded rates exactly (a kinematic
// stand-in for the real arm and its joint rate loops), with the base moving as zero momentum says.
//
//   capture_controller <path to paper_7dof.urdf>
#include <ffsr/control/capture_controller.hpp>
#include <ffsr/parsers/urdf.hpp>

#include <cmath>
#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: capture_controller <paper_7dof.urdf>\n");
    return 2;
  }
  try {
    const ffsr::Model model = ffsr::model_from_urdf_file(argv[1], "ee");
    // the problem of robots/paper_7dof_position.toml
    ffsr::CaptureProblem pb;
    pb.model = &model;
    pb.frame = model.end_effector();
    pb.theta = Eigen::Matrix<double, 7, 1>(0, 90, 90, -90, 90, 90, 0) * M_PI / 180;
    pb.target.position = ffsr::Vector3(2.3, -0.8, 2.0);
    pb.target.angular_velocity = ffsr::Vector3(1, -0.5, 2) * M_PI / 180;
    pb.target.contact_offset = ffsr::Vector3(-0.25, 0.15, 0.1);
    ffsr::CaptureTask task;  // the end-effector position, three axes
    ffsr::CaptureOptions opt;
    opt.duration = 157;
    opt.gain = -0.01;

    // built once (allocates); the loop below does not allocate and cannot throw
    auto controller = ffsr::make_gradient_controller(pb, task, opt);
    ffsr::ControlCommand cmd = controller.make_command();
    ffsr::ControllerState state{pb.base, pb.theta};
    ffsr::TargetEstimate estimate = ffsr::target_estimate(pb.target);

    const double dt = 0.01;
    const long ticks = std::lround(opt.duration / dt);
    for (long k = 0; k <= ticks; ++k) {
      const double t = static_cast<double>(k) * dt;
      if (k % 20 == 0 && t < opt.duration) {  // 5 Hz: a fresh estimate (here: the truth) re-plans
        estimate = ffsr::target_estimate(ffsr::propagate_target(pb.target, t));
        if (controller.update_target(t, estimate) != ffsr::ControlFault::None) return 1;
      }
      controller.step(t, state, estimate, cmd);
      if (cmd.status == ffsr::ControlStatus::Fault) {
        std::fprintf(stderr, "fault at t = %.2f s: %s\n", t, ffsr::fault_name(cmd.fault));
        return 1;
      }
      if (k % 1000 == 0) {
        std::printf("t = %6.1f s  %-12s theta_dot (deg/s) =", t, ffsr::status_name(cmd.status));
        for (int j = 0; j < cmd.theta_dot.size(); ++j) std::printf(" %7.4f", cmd.theta_dot(j) * 180 / M_PI);
        std::printf("  |x_d - p_e| = %.2e m\n", (cmd.reference - cmd.end_effector).norm());
      }
      if (k == ticks) break;
      // the stand-in robot: joints follow the command, the base follows from zero momentum (Euler step)
      state.theta += dt * cmd.theta_dot;
      state.base.position += dt * cmd.base_velocity.head<3>();
      const ffsr::Vector3 w = cmd.base_velocity.tail<3>();
      state.base.orientation = ffsr::Quaternion(ffsr::rotation_from_vector(dt * w)) * state.base.orientation;
      state.base.orientation.normalize();
    }
    const double miss = (cmd.end_effector - controller.setup().capture.x_cap).norm();
    std::printf("capture point reached within %.2e m\n", miss);
    return miss < 1e-2 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "capture_controller: %s\n", e.what());
    return 2;
  }
}
