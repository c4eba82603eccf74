// The post-capture phase: the stack model (a body attached at a frame) against sums over bodies from
// finite differences of forward kinematics; the grasp's plastic impulse (momentum conserved, relative
// twist zero, the stack's momentum equal to the two bodies'); the detumbling controller and its run;
// the way of the Detumble keys from a scenario file to the controller (jobs/detumble.hpp).

#include <catch2/catch.hpp>

#include "support/dynamics_helpers.hpp"

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/algorithm/forward_dynamics.hpp"
#include "ffsr/algorithm/grasp.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/jobs/detumble.hpp"
#include "ffsr/model/attach.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>

namespace test_detumble {

using namespace ffsr;
using namespace ffsr_test;

namespace {

/// A target of the paper's kind with a full inertia, placed so that the frame's origin is a point of it.
Target random_target(Rng& rng, const Vector3& contact) {
  Target t;
  t.mass = 200;
  t.inertia = rng.inertia(60.0);
  t.attitude = rng.quaternion();
  t.position = contact + rng.vec3(0.4);
  t.velocity = rng.vec3(0.05);
  t.angular_velocity = rng.vec3(0.1);
  return t;
}

double rel(const Vector6& a, const Vector6& b) { return (a - b).norm() / std::max(b.norm(), 1e-300); }

}  // namespace

TEST_CASE("attach_body: the stack's momentum, energy and H equal sums over its bodies", "[detumble]") {
  for (const std::string file : {"paper_3dof.urdf", "paper_7dof.urdf"}) {
    const TestRobot robot = paper_robot(file);
    Rng rng(7);
    AttachedBody body;
    body.mass = 150;
    body.inertia = rng.inertia(40.0);
    body.pose = Pose{rng.vec3(0.5), rng.rotation()};
    TestRobot stack{file + " + target", attach_body(robot.model, robot.model.frame(robot.ee).name, body),
                    robot.links, robot.ee};
    stack.links.push_back({"target", Inertia{body.mass, Vector3::Zero(), body.inertia}});
    REQUIRE(stack.model.n() == robot.model.n());
    REQUIRE(std::abs(stack.model.total_mass() - robot.model.total_mass() - body.mass) < 1e-12);
    for (int trial = 0; trial < 3; ++trial) {
      const Config q = random_config(stack.model, rng);
      const VectorXd v = rng.vec(stack.model.nv(), 0.5);
      Data d(stack.model);
      crba(stack.model, d, q.base, q.theta);
      const auto lv = fd_link_velocities(stack, q, v, advance_library);
      // momentum about the base origin: the sum over the listed masses (finite differences)
      const Vector6 h_fd = fd_momentum(stack, lv, d.p[0]);
      CHECK(rel(momentum(stack.model, d, v), h_fd) < 1e-7);
      CHECK(rel(Vector6(d.H.topRows<6>() * v), h_fd) < 1e-7);
      const double T_fd = fd_kinetic_energy(stack, lv);
      CHECK(std::abs(kinetic_energy(stack.model, d, v) - T_fd) < 1e-7 * T_fd);
      CHECK(std::abs(0.5 * v.dot(d.H * v) - T_fd) < 1e-7 * T_fd);
      // ABA on the stack equals the CRBA/RNEA forward dynamics of the stack
      const VectorXd tau = rng.vec(stack.model.nv(), 5.0);
      VectorXd a1, a2;
      aba(stack.model, d, q.base, q.theta, v, tau, a1);
      forward_dynamics(stack.model, d, q.base, q.theta, v, tau, a2);
      CHECK((a1 - a2).norm() < 1e-9 * std::max(1.0, a2.norm()));
    }
  }
}

TEST_CASE("attach_body refuses a non-physical body and an unknown frame", "[detumble]") {
  const Model m = model_from_urdf_file(source_path("robots/paper_7dof.urdf"));
  AttachedBody b;
  b.mass = 100;
  b.inertia = Vector3(10, 20, 25).asDiagonal();
  CHECK_NOTHROW(attach_body(m, "ee", b));
  auto refused = [&](AttachedBody x, const std::string& frame, const std::string& words) {
    try {
      attach_body(m, frame, x);
      FAIL("accepted: " << words);
    } catch (const InputError& e) {
      CHECK_THAT(e.what(), Catch::Contains(words));
    }
  };
  AttachedBody x = b;
  x.mass = 0;
  refused(x, "ee", "mass must be positive");
  x.mass = -1;
  refused(x, "ee", "mass must be positive");
  x.mass = std::numeric_limits<double>::quiet_NaN();
  refused(x, "ee", "mass must be positive");
  x = b;
  x.inertia = Vector3(10, 20, -1).asDiagonal();
  refused(x, "ee", "positive definite");
  x.inertia = Vector3(1, 1, 5).asDiagonal();
  refused(x, "ee", "triangle inequality");
  x.inertia(0, 1) = 0.5;
  refused(x, "ee", "symmetric");
  x = b;
  x.inertia(2, 2) = std::numeric_limits<double>::infinity();
  refused(x, "ee", "inertia");
  refused(b, "gripper", "unknown frame 'gripper'");
  x = b;
  x.name = "link3";
  refused(x, "ee", "already has a frame 'link3'");
}

TEST_CASE("grasp: momentum conserved, relative twist zero, the stack's momentum the two bodies'",
          "[detumble]") {
  for (const std::string file : {"paper_3dof.urdf", "paper_7dof.urdf"}) {
    const Model m = model_from_urdf_file(source_path("robots/" + file));
    Data d(m);
    Rng rng(11);
    for (int trial = 0; trial < 4; ++trial) {
      const Config q = random_config(m, rng, 2.0);
      const VectorXd v = rng.vec(m.nv(), 0.3);
      forward_kinematics(m, d, q.base, q.theta);
      const Target t = random_target(rng, frame_pose(m, d, m.end_effector()).p);
      const GraspResult g = grasp(m, d, q.base, q.theta, v, m.end_effector(), t);
      // the KKT system's second row: the relative twist after the lock is zero
      CHECK(g.relative_twist_after.cwiseAbs().maxCoeff() < 1e-12);
      CHECK(rel(g.momentum_after, g.momentum_before) < 1e-10);
      CHECK(g.energy_after <= g.energy_before);  // plastic: energy is lost, never gained
      CHECK(g.impulse.norm() > 1e-3);            // the relative twist was not zero before
      // the stack model's momentum at v+ is the two bodies' momentum after the lock
      const Model stack = attach_body(m, m.frame(m.end_effector()).name, g.body);
      Data ds(stack);
      forward_kinematics(stack, ds, q.base, q.theta);
      Vector6 hs = momentum(stack, ds, g.v_after);
      hs.tail<3>() += ds.p[0].cross(hs.head<3>());
      CHECK(rel(hs, g.momentum_after) < 1e-10);
      CHECK(std::abs(kinetic_energy(stack, ds, g.v_after) - g.energy_after) < 1e-10 * g.energy_after);
      // the target frame of the stack sits where the target is
      const Pose tp = frame_pose(stack, ds, stack.frame_index("target"));
      CHECK((tp.p - t.position).norm() < 1e-12);
      CHECK((tp.R - t.rotation()).norm() < 1e-12);
      CHECK((g.base_velocity_jump - (g.v_after - v).head<6>()).norm() == 0.0);
    }
  }
}

TEST_CASE("grasp refuses bad input", "[detumble]") {
  const Model m = model_from_urdf_file(source_path("robots/paper_3dof.urdf"));
  Data d(m);
  const Eigen::VectorXd theta = Eigen::VectorXd::Zero(m.n());
  Eigen::VectorXd v = Eigen::VectorXd::Zero(m.nv());
  Target t;
  CHECK_THROWS_AS(grasp(m, d, BasePose{}, theta, Eigen::VectorXd::Zero(m.nv() + 1), m.end_effector(), t),
                  InputError);
  CHECK_THROWS_AS(grasp(m, d, BasePose{}, theta, v, 99, t), InputError);
  v(7) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(grasp(m, d, BasePose{}, theta, v, m.end_effector(), t), InputError);
  v(7) = 0;
  t.mass = -1;
  CHECK_THROWS_AS(grasp(m, d, BasePose{}, theta, v, m.end_effector(), t), InputError);
}

namespace {

/// The 7-DOF robot of robots/paper_7dof_position.toml at its initial configuration grasping the
/// scenario's target (200 kg, 100 kg m^2, spin (1, -0.5, 2) deg/s) at the approach speed 0.2 m/s.
struct Grasped {
  Model robot;
  GraspResult grasp;
  Model stack;
  int gripper;
  DetumbleState start;
};

Grasped grasped_7dof() {
  Model m = model_from_urdf_file(source_path("robots/paper_7dof.urdf"), "ee");
  Eigen::VectorXd theta(7);
  theta << 0, 90, 90, -90, 90, 90, 0;
  theta *= M_PI / 180;
  Target t;
  t.angular_velocity = Vector3(1, -0.5, 2) * M_PI / 180;
  t.contact_offset = Vector3(-0.25, 0.15, 0.1);
  const int ee = m.end_effector();
  GraspResult g = grasp_at_capture(m, ee, BasePose{}, theta, t, 0.2);
  Model stack = attach_body(m, m.frame(ee).name, g.body);
  DetumbleState s{BasePose{}, theta, g.v_after, Vector3::Zero()};
  return {std::move(m), std::move(g), std::move(stack), ee, s};
}

/// The joint torque limits of docs/detumble.md: 60 N m at the shoulder (joints 1-3),
/// 40 N m at the elbow (4), 20 N m at the wrist (5-7).
Eigen::VectorXd limits_7dof() {
  Eigen::VectorXd L(7);
  L << 60, 60, 60, 40, 20, 20, 20;
  return L;
}

void check_torques_within_limits(const DetumbleRunResult& r, const Eigen::VectorXd& L) {
  for (const auto& s : r.series) {
    for (int k = 0; k < L.size(); ++k) REQUIRE(std::abs(s.command.tau(k)) <= L(k) * (1 + 1e-12));
    // the series' rates are the controller's
    REQUIRE(s.theta_dot.cwiseAbs().maxCoeff() == s.command.joint_rate);
  }
}

}  // namespace

TEST_CASE(
    "detumble, free-floating: momentum kept, energy only through joint work, torques within limits, "
    "at rest",
    "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  DetumbleOptions opt;
  DetumbleRunOptions run;
  run.horizon = 60;
  const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, run);
  INFO("time to rest " << r.time_to_rest << " s, peak torque " << r.peak_joint_torque << " N m (joint "
                       << r.peak_joint << "), gripper " << r.peak_gripper_force << " N "
                       << r.peak_gripper_moment << " N m, attitude " << r.base_attitude_excursion
                       << " rad, energy " << r.energy_start << " -> " << r.energy_end << " J, steps "
                       << r.steps);
  CHECK(r.at_rest);
  CHECK(r.momentum_drift < 1e-8);
  CHECK(r.max_energy_balance < 1e-6);  // T(k+1) - T(k) = tau . (theta(k+1) - theta(k)) each tick
  CHECK(r.energy_end < r.energy_start);
  CHECK(r.series.back().command.joint_rate < opt.rest_rate);
  CHECK(r.series.back().command.relative_rate < opt.rest_rate);
  CHECK(r.peak_joint_torque > 0);
  check_torques_within_limits(r, lim.joint_torque);
  // the stack keeps its momentum: the total momentum after the grasp equals the run's
  CHECK((r.series.back().momentum - g.grasp.momentum_after).norm() < 1e-8 * g.grasp.momentum_after.norm());
}

TEST_CASE("detumble after the paper's approach on robots/paper_7dof_position.toml: at rest within the limits",
          "[detumble]") {
  const Scenario sc = load_scenario(source_path("robots/paper_7dof_position.toml"));
  const CaptureProblem& pb = sc.problem;
  const CaptureResult plan = plan_capture(pb, sc.task, sc.capture);
  const CaptureSetup setup = prepare_capture(pb, sc.task, sc.capture);
  const GraspResult g =
      grasp_at_capture(*pb.model, pb.frame, plan.base, plan.theta, setup.capture.target, pb.approach_speed);
  CHECK(g.relative_twist_after.cwiseAbs().maxCoeff() < 1e-12);
  CHECK(rel(g.momentum_after, g.momentum_before) < 1e-10);
  const Model stack = attach_body(*pb.model, pb.model->frame(pb.frame).name, g.body);
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  DetumbleRunOptions run;
  run.horizon = 60;
  const DetumbleRunResult r =
      run_detumble(stack, pb.frame, g.body, {plan.base, plan.theta, g.v_after, {}}, lim, {}, run);
  INFO("time to rest " << r.time_to_rest << " s, peak torque " << r.peak_joint_torque << " N m (joint "
                       << r.peak_joint << "), gripper " << r.peak_gripper_force << " N "
                       << r.peak_gripper_moment << " N m, attitude " << r.base_attitude_excursion << " rad");
  CHECK(r.at_rest);
  CHECK(r.momentum_drift < 1e-8);
  CHECK(r.max_energy_balance < 1e-6);
  check_torques_within_limits(r, lim.joint_torque);
}

TEST_CASE("detumble, free-floating, torque limits that bind: the brake scaled, still at rest", "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof() / 30;  // 2 N m at the shoulder, below the unbounded law's peak of 8.8 N m
  DetumbleRunOptions run;
  run.horizon = 120;
  const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, {}, run);
  INFO("time to rest " << r.time_to_rest << " s, peak torque " << r.peak_joint_torque);
  CHECK(r.at_rest);
  CHECK(r.momentum_drift < 1e-8);
  CHECK(r.max_energy_balance < 1e-6);
  check_torques_within_limits(r, lim.joint_torque);
  long saturated = 0;
  for (const auto& s : r.series) saturated += s.command.status == DetumbleStatus::Saturated;
  CHECK(saturated > 10);
}

TEST_CASE("detumble, free-floating, the passive law: kinetic energy never increases", "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof() / 30;
  DetumbleOptions opt;
  opt.hold = false;  // tau . qd <= 0 at every tick: no actuator puts work in
  DetumbleRunOptions run;
  run.horizon = 120;
  const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, run);
  INFO("time to rest " << r.time_to_rest << " s");
  CHECK(r.at_rest);
  CHECK(r.joint_work < 0);
  CHECK(r.momentum_drift < 1e-8);
  for (size_t k = 1; k < r.series.size(); ++k)
    REQUIRE(r.series[k].energy <= r.series[k - 1].energy * (1 + 1e-12));
  for (const auto& s : r.series) REQUIRE(s.command.tau.dot(s.theta_dot) <= 0.0);
  check_torques_within_limits(r, lim.joint_torque);
}

TEST_CASE("detumble at the limits: each command the largest decay that fits, checked by forward dynamics",
          "[detumble]") {
  // along a run: every command within the joint and gripper limits (the gripper's load from the run's
  // ABA, not the controller's RNEA), and where the decay is below the cap some bound active; at the
  // grasp, ABA under the command (the controller computes it by CRBA and RNEA) gives qdd = -decay qd
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  lim.gripper_force = 20;
  lim.gripper_moment = 10;
  DetumbleController ctrl(g.stack, g.gripper, g.grasp.body, lim);
  DetumbleRunOptions run;
  run.horizon = 60;
  run.dwell = 0;
  const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, {}, run);
  REQUIRE(r.series.size() > 5);
  long bound = 0;
  for (const DetumbleSample& x : r.series) {
    const DetumbleCommand& cmd = x.command;
    REQUIRE_FALSE(cmd.passive);
    REQUIRE(cmd.decay > 0);
    REQUIRE(cmd.decay <= ctrl.decay_cap());
    double worst = 0;
    for (int k = 0; k < 7; ++k) worst = std::max(worst, std::abs(cmd.tau(k)) / lim.joint_torque(k));
    worst = std::max({worst, x.gripper_force.norm() / lim.gripper_force, x.gripper_moment.norm() / lim.gripper_moment});
    REQUIRE(worst <= 1 + 1e-9);
    if (cmd.decay < ctrl.decay_cap()) {
      REQUIRE(worst > 1 - 1e-9);  // the largest that fits: some bound is active
      ++bound;
    }
  }
  CHECK(bound > 3);
  Data d(g.stack);
  // the exact law at the grasp: forward dynamics under the first command
  DetumbleCommand c = ctrl.make_command();
  ctrl.step(g.start, c);
  Eigen::VectorXd tau(g.stack.nv()), a(g.stack.nv());
  tau << c.base_wrench, c.tau;
  aba(g.stack, d, g.start.base, g.start.theta, g.start.v, tau, a);
  const Eigen::VectorXd want = -c.decay * g.start.v.tail(7);
  CHECK((a.tail(7) - want).cwiseAbs().maxCoeff() < 1e-9 * want.cwiseAbs().maxCoeff());
}

TEST_CASE("detumble on robots/paper_7dof_detumble.toml's stack: the limits used, held at rest for 10 s",
          "[detumble]") {
  // the previous law (lambda = 1 1/s, what max_decay = 1 asks while no limit binds) rested in 5.05 s
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  DetumbleOptions opt;
  opt.rest_rate = 0.05 * M_PI / 180;  // the scenario's rest-rate-deg
  DetumbleRunOptions run;
  run.horizon = 60;
  run.dwell = 10;
  DetumbleOptions slow = opt;
  slow.max_decay = 1;
  const DetumbleRunResult before = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, slow, run);
  const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, run);
  INFO("time to rest " << r.time_to_rest << " s (lambda = 1: " << before.time_to_rest << " s), peak torque "
                       << r.peak_joint_torque << " N m, dwell peak rate " << r.dwell_peak_rate);
  CHECK(std::abs(before.time_to_rest - 5.05) < 0.015);
  CHECK(r.at_rest);
  CHECK(r.time_to_rest <= 0.6 * 5.05);
  CHECK(r.dwell_at_rest);
  CHECK(r.dwell_peak_rate < opt.rest_rate);
  CHECK(r.series.back().t >= r.time_to_rest + 10 - 1e-9);
  CHECK(r.momentum_drift < 1e-8);
  CHECK(r.peak_joint_torque > 0.9 * 20);  // it brakes with what it has, not with 5-23 % of it
  check_torques_within_limits(r, lim.joint_torque);
  // with the gripper's limits every sample's load (ABA's Newton-Euler, not the controller's) within them
  DetumbleLimits grip = lim;
  grip.gripper_force = 20;
  grip.gripper_moment = 10;
  const DetumbleRunResult rg = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, grip, opt, run);
  CHECK(rg.at_rest);
  CHECK(rg.time_to_rest <= 0.6 * 5.05);
  CHECK(rg.dwell_at_rest);
  for (const DetumbleSample& x : rg.series) {
    REQUIRE(x.gripper_force.norm() <= 20 * (1 + 1e-9));
    REQUIRE(x.gripper_moment.norm() <= 10 * (1 + 1e-9));
  }
  CHECK(rg.peak_gripper_moment > 10 * (1 - 1e-6));  // the bound binds
  CHECK(r.peak_gripper_moment > 10);                 // and without it the load goes past it
}

TEST_CASE("detumble ticks: energy never rises on a passive tick up to the longest tick, a longer one refused",
          "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  const double longest = detumble_longest_tick(g.stack, g.gripper, g.start);
  INFO("longest tick " << longest << " s");
  CHECK(std::abs(longest - 0.15 / g.start.v.tail(7).cwiseAbs().maxCoeff()) < 1e-12);
  for (const double tick : {0.01, 0.1, 1.0, longest * (1 - 1e-9)}) {
    CAPTURE(tick);
    for (const bool hold : {false, true}) {
      CAPTURE(hold);
      DetumbleOptions opt;
      opt.hold = hold;
      DetumbleRunOptions run;
      run.tick = tick;
      run.horizon = std::max(8.0, 20 * tick);
      run.dwell = 0;
      const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, run);
      long passive = 0;
      for (size_t k = 1; k < r.series.size(); ++k)
        if (r.series[k - 1].command.passive) {
          ++passive;
          REQUIRE(r.series[k].energy <= r.series[k - 1].energy + 1e-12 * r.energy_start);
        }
      CHECK(r.energy_end < r.energy_start);
      CHECK(r.momentum_drift < 1e-8);
      if (!hold) CHECK(passive == static_cast<long>(r.series.size()) - 1);
      check_torques_within_limits(r, lim.joint_torque);
    }
  }
  DetumbleRunOptions run;
  run.tick = longest * 1.001;
  try {
    run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, {}, run);
    FAIL("a tick past the longest was taken");
  } catch (const DetumbleInfeasibleError& e) {
    CHECK(e.bound == DetumbleBound::Tick);
    CHECK_THAT(e.what(), Catch::Matchers::Contains("joint 'joint6'"));
  }
  // an extreme spin (the target at 1e4 deg/s): refused at once, not run for minutes
  Target t;
  t.angular_velocity = Vector3(1e4, -0.5, 2) * M_PI / 180;
  t.contact_offset = Vector3(-0.25, 0.15, 0.1);
  const GraspResult fast = grasp_at_capture(g.robot, g.gripper, BasePose{}, g.start.theta, t, 0.2);
  const Model stack = attach_body(g.robot, g.robot.frame(g.gripper).name, fast.body);
  const DetumbleState start{BasePose{}, g.start.theta, fast.v_after, Vector3::Zero()};
  CHECK_THROWS_AS(run_detumble(stack, g.gripper, fast.body, start, lim, {}, DetumbleRunOptions{}),
                  DetumbleInfeasibleError);
  CHECK(detumble_longest_tick(stack, g.gripper, start) < 1e-3);
}


TEST_CASE("detumble on the published planar problem (Vyas et al. 2022): the law at the limits against 4.095 s",
          "[detumble]") {
  // robots/vyas2022_planar.urdf with the 50 kg target 0.35 m beyond the end-effector, the published start
  // and limits (0.5 N m joints, thrusters of 2 N and 2.5 N m per axis); at rest when every joint rate and
  // every component of the base's twist is <= 1e-3. The published optimized trajectory rests in 4.095 s;
  // the previous law (lambda = 1 1/s, k = 0.1 1/s) took 24.9 s.
  const Model robot = model_from_urdf_file(source_path("robots/vyas2022_planar.urdf"), "ee");
  AttachedBody body;
  body.mass = 50;
  body.inertia = Matrix3::Identity() * 3;
  body.pose.p = Vector3(0, 0, 0.35);
  const Model stack = attach_body(robot, "ee", body);
  DetumbleState s;
  s.theta = Eigen::Vector3d(-0.72, 1.2, 0.72);
  s.v = Eigen::VectorXd(9);
  s.v << -0.0124, 0, -0.0052, 0, 0.0042, 0, 0.0635, -0.1353, 0.1669;
  DetumbleLimits lim;
  lim.joint_torque = Eigen::Vector3d::Constant(0.5);
  lim.actuator = BaseActuator::Thrusters;
  lim.thruster_force = 2;
  lim.thruster_torque = 2.5;
  DetumbleOptions opt;
  opt.stop_stack_spin = true;
  opt.rest_rate = 1e-3;
  DetumbleRunOptions run;
  run.dwell = 2;
  const DetumbleRunResult r = run_detumble(stack, stack.frame_index("ee"), body, s, lim, opt, run);
  INFO("time to rest " << r.time_to_rest << " s");
  REQUIRE(r.at_rest);
  CHECK(r.time_to_rest <= 1.05 * 4.095);  // 4.13 s: the thrusters brake the base while joint 1 brakes the arm
  CHECK(r.dwell_at_rest);
  check_torques_within_limits(r, lim.joint_torque);
  const double mass = 100 + 10 + 8 + 4 + 0.1 + 50;
  for (const DetumbleSample& x : r.series) {
    const Matrix3 R = x.base.orientation.toRotationMatrix();  // the bounds are per base axis
    const Vector3 f = R.transpose() * x.command.base_wrench.head<3>(), m = R.transpose() * x.command.base_wrench.tail<3>();
    for (int k = 0; k < 3; ++k) {
      REQUIRE(std::abs(f(k)) <= 2 * (1 + 1e-12));
      REQUIRE(std::abs(m(k)) <= 2.5 * (1 + 1e-12));
    }
    if (x.t >= r.time_to_rest) {  // the base's twist too: its spin, and its speed (P / m at relative rest)
      REQUIRE(x.command.stack_rate <= 1e-3);
      REQUIRE(x.momentum.head<3>().norm() / mass <= 1e-3);
    }
  }
}

TEST_CASE("detumble with reaction wheels: the stack's spin stopped, the wheels within their bounds",
          "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  lim.actuator = BaseActuator::ReactionWheels;
  lim.wheel_torque = 0.2;
  lim.wheel_momentum = 25;
  DetumbleOptions opt;
  opt.stop_stack_spin = true;
  DetumbleRunOptions run;
  run.horizon = 400;
  run.record_every = 10;
  const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, run);
  INFO("time to rest " << r.time_to_rest << " s, wheels " << r.peak_wheel_momentum << " N m s");
  CHECK(r.at_rest);
  CHECK(r.series.back().command.stack_rate < opt.rest_rate);
  CHECK(r.peak_wheel_momentum <= lim.wheel_momentum);
  CHECK(r.peak_wheel_momentum > 0.1);  // the wheels took the stack's spin
  CHECK(r.momentum_drift < 1e-8);      // stack + wheels
  check_torques_within_limits(r, lim.joint_torque);
  for (const auto& s : r.series)
    REQUIRE((s.command.base_wrench.tail<3>().cwiseAbs().maxCoeff() <= std::sqrt(3.0) * lim.wheel_torque));
}

TEST_CASE("detumble with thrusters: the stack's spin stopped", "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  lim.actuator = BaseActuator::Thrusters;
  lim.thruster_force = 5;
  lim.thruster_torque = 1;
  DetumbleOptions opt;
  opt.stop_stack_spin = true;
  DetumbleRunOptions run;
  run.horizon = 200;
  run.record_every = 10;
  const DetumbleRunResult r = run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, run);
  INFO("time to rest " << r.time_to_rest << " s");
  CHECK(r.at_rest);
  CHECK(r.series.back().command.stack_rate < opt.rest_rate);
  check_torques_within_limits(r, lim.joint_torque);
}

TEST_CASE("detumble: the gripper load is the rate of the target's momentum", "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  DetumbleController ctrl(g.stack, g.gripper, g.grasp.body, lim);
  DetumbleCommand cmd = ctrl.make_command();
  ctrl.step(g.start, cmd);
  REQUIRE(cmd.status != DetumbleStatus::Fault);
  detail::DetumbleSystem sys(g.stack);
  const Eigen::VectorXd y = sys.pack(g.start);
  Vector3 f, n_p;
  sys.gripper_load(y, cmd, g.gripper, g.grasp.body, f, n_p);
  Eigen::VectorXd yd(sys.size());
  sys.rhs(y, cmd, false, yd);
  // the target's momentum about o from the stack's target frame (its centre of mass) and Jacobian
  const int tf = g.stack.frame_index("target");
  auto target_momentum = [&](const Eigen::VectorXd& yy) {
    Data d(g.stack);
    const DetumbleState s = sys.unpack(yy);
    forward_kinematics(g.stack, d, s.base, s.theta);
    frame_jacobian(g.stack, d, tf);
    const Pose X = frame_pose(g.stack, d, tf);
    const Vector6 tw = d.J * s.v;
    Vector6 h;
    h.head<3>() = g.grasp.body.mass * tw.head<3>();
    h.tail<3>() = X.p.cross(h.head<3>()) + X.R * g.grasp.body.inertia * X.R.transpose() * tw.tail<3>();
    return h;
  };
  const double eps = 1e-6;
  const Vector6 dh = (target_momentum(y + eps * yd) - target_momentum(y - eps * yd)) / (2 * eps);
  Data d(g.stack);
  forward_kinematics(g.stack, d, g.start.base, g.start.theta);
  const Vector3 p = frame_pose(g.stack, d, g.gripper).p;
  INFO("force " << f.transpose() << " / " << dh.head<3>().transpose());
  CHECK((f - dh.head<3>()).norm() < 1e-6 * std::max(1.0, dh.head<3>().norm()));
  CHECK((n_p + p.cross(f) - dh.tail<3>()).norm() < 1e-6 * std::max(1.0, dh.tail<3>().norm()));
  CHECK(f.norm() > 1e-2);
}

TEST_CASE("check_detumble_feasible says which bound is too small, at thresholds that agree", "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits l;
  l.joint_torque = limits_7dof();
  DetumbleOptions o;
  o.stop_stack_spin = true;
  const double horizon = 120;
  // the bound it names, or nothing when feasible; an error that is not DetumbleInfeasibleError fails
  auto bound = [&](const DetumbleLimits& x) -> std::optional<DetumbleBound> {
    try {
      check_detumble_feasible(g.stack, g.start, x, o, horizon);
      return std::nullopt;
    } catch (const DetumbleInfeasibleError& e) {
      return e.bound;
    }
  };
  CHECK(bound(l) == DetumbleBound::Actuator);
  o.stop_stack_spin = false;
  CHECK_FALSE(bound(l));  // the stack may keep its spin
  o.stop_stack_spin = true;
  l.actuator = BaseActuator::ReactionWheels;
  l.wheel_torque = 0.2;
  l.wheel_momentum = 0.05;
  CHECK(bound(l) == DetumbleBound::WheelMomentum);
  l.wheel_momentum = 25;
  CHECK_FALSE(bound(l));
  l.wheel_torque = 1e-4;
  CHECK(bound(l) == DetumbleBound::ActuatorTorque);
  l = DetumbleLimits{};
  l.joint_torque = limits_7dof();
  l.actuator = BaseActuator::Thrusters;
  l.thruster_force = 1;
  l.thruster_torque = 1e-4;
  CHECK(bound(l) == DetumbleBound::ActuatorTorque);
  l.thruster_torque = 1;
  CHECK_FALSE(bound(l));
  // the thresholds, by bisection on each bound: the wheels store |L_c| / sqrt(3) per axis, and a
  // torque t removes |L_c| in |L_c| / (sqrt(3) t), so the momentum threshold over the torque
  // threshold is the horizon
  auto threshold = [&](double DetumbleLimits::*field, DetumbleBound b) {
    DetumbleLimits x;
    x.joint_torque = limits_7dof();
    x.actuator = BaseActuator::ReactionWheels;
    x.wheel_torque = x.wheel_momentum = 1e6;
    double lo = 1e-9, hi = 1e6;  // refused at lo, accepted at hi
    for (int k = 0; k < 200; ++k) {
      x.*field = std::sqrt(lo * hi);
      (bound(x) == b ? lo : hi) = x.*field;
    }
    x.*field = hi;
    REQUIRE(bound(x) != b);
    return hi;
  };
  const double m = threshold(&DetumbleLimits::wheel_momentum, DetumbleBound::WheelMomentum);
  const double t = threshold(&DetumbleLimits::wheel_torque, DetumbleBound::ActuatorTorque);
  CHECK(m > 0.05);
  CHECK(m < 25);
  CHECK(m / t == Approx(horizon).epsilon(1e-9));
}

TEST_CASE("detumble refuses bad limits, a spin it cannot stop and an actuator too small", "[detumble]") {
  const Grasped g = grasped_7dof();
  DetumbleLimits lim;
  lim.joint_torque = limits_7dof();
  DetumbleOptions opt;
  DetumbleRunOptions run;
  auto refused = [&](const DetumbleLimits& l, const DetumbleOptions& o, const std::string& words) {
    try {
      run_detumble(g.stack, g.gripper, g.grasp.body, g.start, l, o, run);
      FAIL("accepted: " << words);
    } catch (const InputError& e) {
      CHECK_THAT(e.what(), Catch::Contains(words));
    }
  };
  DetumbleLimits l = lim;
  l.joint_torque(3) = 0;
  refused(l, opt, "torque limit of joint 'joint4' must be positive");
  l.joint_torque(3) = std::numeric_limits<double>::infinity();
  refused(l, opt, "torque limit of joint 'joint4' must be positive and finite");
  l.joint_torque(3) = std::numeric_limits<double>::quiet_NaN();
  refused(l, opt, "joint4");
  DetumbleOptions o = opt;
  o.stop_stack_spin = true;
  refused(lim, o, "its angular momentum about its centre of mass, ");
  refused(lim, o, "N m s, is conserved");
  l = lim;
  l.actuator = BaseActuator::ReactionWheels;
  l.wheel_torque = 0.2;
  l.wheel_momentum = -1;
  refused(l, o, "reaction wheels' momentum must be positive");
  l.wheel_momentum = 0.05;
  refused(l, o, "cannot store the stack's angular momentum");
  l.wheel_momentum = 25;
  l.wheel_torque = 1e-4;
  refused(l, o, "needs at least");
  l = lim;
  l.actuator = BaseActuator::Thrusters;
  l.thruster_force = 1;
  l.thruster_torque = std::numeric_limits<double>::quiet_NaN();
  refused(l, o, "thrusters' torque must be positive and finite");
  DetumbleRunOptions bad = run;
  bad.tick = 0;
  CHECK_THROWS_AS(run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, bad), InputError);
  auto run_refused = [&](const DetumbleRunOptions& r, const std::string& words) {
    try {
      run_detumble(g.stack, g.gripper, g.grasp.body, g.start, lim, opt, r);
      FAIL("accepted: " << words);
    } catch (const InputError& e) {
      CHECK_THAT(e.what(), Catch::Contains(words));
    }
  };
  bad = run;
  bad.horizon = 1;
  bad.tick = 2;
  run_refused(bad, "the tick (2 s) must be shorter than the horizon (1 s)");
  bad.horizon = 1e6;
  bad.tick = 0.01;
  run_refused(bad, "more than 1e7 ticks: (horizon 1000000 s + dwell 5 s) / tick 0.01 s = 100000500");
}

// --- the Detumble keys, from the scenario file to the controller -------------------------------------------

namespace {

// no field list is copied on the way: the sample holds the controller's command, the run's result and
// the global search's figures share one summary, the job's result holds the settings as built
static_assert(std::is_same_v<decltype(DetumbleSample::command), DetumbleCommand>);
static_assert(std::is_base_of_v<DetumbleSummary, DetumbleRunResult>);
static_assert(std::is_base_of_v<DetumbleSummary, PostCaptureFigures>);
static_assert(std::is_same_v<decltype(DetumbleJobResult::settings), DetumbleSettings>);

/// robots/paper_7dof_detumble.toml with its Detumble keys replaced by `detumble` (TOML lines).
ScenarioKeys detumble_scenario(const std::string& detumble) {
  const std::string file = source_path("robots/paper_7dof_detumble.toml");
  std::ifstream in(file);
  std::ostringstream text;
  for (std::string line; std::getline(in, line);) {
    const std::string key = line.substr(0, line.find(' '));
    const ScenarioKey* k = find_scenario_key(key);
    if (!k || k->group != KeyGroup::Detumble) text << line << "\n";
  }
  return read_scenario_text(text.str() + detumble, "scenario " + file, file);
}

void check_same(const DetumbleSettings& a, const DetumbleSettings& b) {
  CHECK(a.limits.joint_torque == b.limits.joint_torque);
  CHECK(a.limits.actuator == b.limits.actuator);
  CHECK(a.limits.wheel_torque == b.limits.wheel_torque);
  CHECK(a.limits.wheel_momentum == b.limits.wheel_momentum);
  CHECK(a.limits.thruster_force == b.limits.thruster_force);
  CHECK(a.limits.thruster_torque == b.limits.thruster_torque);
  CHECK(a.limits.gripper_force == b.limits.gripper_force);
  CHECK(a.limits.gripper_moment == b.limits.gripper_moment);
  CHECK(a.options.max_decay == b.options.max_decay);
  CHECK(a.options.max_base_decay == b.options.max_base_decay);
  CHECK(a.options.rest_rate == b.options.rest_rate);
  CHECK(a.options.stop_stack_spin == b.options.stop_stack_spin);
  CHECK(a.options.hold == b.options.hold);
  CHECK(a.run.tick == b.run.tick);
  CHECK(a.run.horizon == b.run.horizon);
  CHECK(a.run.dwell == b.run.dwell);
  CHECK(a.run.record_every == b.run.record_every);
  CHECK(a.run.rtol == b.run.rtol);
  CHECK(a.run.atol == b.run.atol);
}

}  // namespace

TEST_CASE("a Detumble key from the scenario file to the controller: one conversion, one check",
          "[detumble][scenario]") {
  const std::string keys = "joint-torque-limit = [60, 60, 60, 40, 20, 20, 20]\nrest-rate-deg = 0.1\n"
                           "detumble-horizon = 110\ndetumble-tick = 0.02\n";
  const Scenario sc = build_scenario(detumble_scenario(keys), nullptr, ScenarioScope::Configuration);
  // the one conversion: each field as the keys give it, in the controller's units
  const DetumbleSettings s = detumble_settings(sc.keys, *sc.model);
  Eigen::VectorXd limit(7);
  limit << 60, 60, 60, 40, 20, 20, 20;
  CHECK(s.limits.joint_torque == limit);
  CHECK(s.limits.actuator == BaseActuator::None);
  CHECK(s.options.rest_rate == 0.1 * M_PI / 180.0);
  CHECK_FALSE(s.options.stop_stack_spin);
  CHECK(s.run.tick == 0.02);
  CHECK(s.run.horizon == 110);
  const DetumbleSettings defaults;  // the law's gains and the integrator's tolerances are not keys
  CHECK(s.options.max_decay == defaults.options.max_decay);
  CHECK(s.run.rtol == defaults.run.rtol);

  // the job runs under them as built (the result holds the struct, no field copied on the way), and
  // the controller takes them as they are: its first command at the grasp is the run's first sample's
  const DetumbleJobResult d = detumble(sc);
  check_same(d.settings, s);
  CHECK(d.result.at_rest);
  CHECK(static_cast<double>(d.result.ticks) * s.run.tick < s.run.horizon);
  const Model stack = attach_body(*sc.model, sc.model->frame(sc.problem.frame).name, d.grasp.body);
  DetumbleController ctrl(stack, sc.problem.frame, d.grasp.body, s.limits, s.options, s.run.tick);
  DetumbleCommand first = ctrl.make_command();
  const detail::DetumbleSystem sys(stack);  // the run's state vector: the grasp's state as it packs it
  const DetumbleState start{sc.problem.base, sc.problem.theta, d.grasp.v_after, Vector3::Zero()};
  ctrl.step(sys.unpack(sys.pack(start)), first);
  const DetumbleCommand& recorded = d.result.series.front().command;
  CHECK(recorded.tau == first.tau);
  CHECK(recorded.base_wrench == first.base_wrench);
  CHECK(recorded.brake_scale == first.brake_scale);
  CHECK(recorded.decay == first.decay);
  CHECK(recorded.base_decay == first.base_decay);
  CHECK(recorded.passive == first.passive);
  CHECK(recorded.joint_rate == first.joint_rate);
  CHECK(recorded.relative_rate == first.relative_rate);
  CHECK(recorded.stack_rate == first.stack_rate);
  CHECK(recorded.status == first.status);
  CHECK(recorded.fault == first.fault);
  CHECK(d.result.peak_joint_torque <= limit.maxCoeff());

  // the global search's figures at the same configuration: the run's summary, whole
  const PostCaptureFigures f = post_capture_figures(*sc.model, sc.problem.frame, s, sc.problem.base,
                                                    sc.problem.theta, sc.problem.target,
                                                    sc.problem.approach_speed);
  CHECK(f.failure.empty());
  CHECK(f.at_rest == d.result.at_rest);
  CHECK(f.time_to_rest == d.result.time_to_rest);
  CHECK(f.peak_joint_torque == d.result.peak_joint_torque);
  CHECK(f.peak_joint == d.result.peak_joint);
  CHECK(f.peak_gripper_force == d.result.peak_gripper_force);
  CHECK(f.peak_gripper_moment == d.result.peak_gripper_moment);

  // the actuator's bounds: each from its key
  const Scenario wheels = build_scenario(
      detumble_scenario("joint-torque-limit = 20\nbase-actuator = \"reaction-wheels\"\nwheel-torque = 0.3\n"
                        "wheel-momentum = 7\nstop-stack-spin = true\n"),
      nullptr, ScenarioScope::Configuration);
  const DetumbleSettings w = detumble_settings(wheels.keys, *wheels.model);
  CHECK(w.limits.actuator == BaseActuator::ReactionWheels);
  CHECK(w.limits.wheel_torque == 0.3);
  CHECK(w.limits.wheel_momentum == 7);
  CHECK(w.options.stop_stack_spin);
  CHECK(w.limits.joint_torque == Eigen::VectorXd::Constant(7, 20.0));  // one value for every joint
  CHECK(std::string(actuator_name(w.limits.actuator)) == wheels.keys.base_actuator);

  // one check: a bad limit is refused by the key table, with the controller's own test of a limit, in
  // the file's words (its line), before the robot is loaded
  CHECK_FALSE(detumble_bound_ok(-3));
  try {
    build_scenario(detumble_scenario("joint-torque-limit = [60, 60, 60, 40, 20, 20, -3]\n"), nullptr,
                   ScenarioScope::Configuration);
    FAIL("a negative joint torque limit was taken");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("joint-torque-limit: every limit must be positive, got -3"));
    CHECK_THAT(e.what(), Catch::Contains("paper_7dof_detumble.toml:"));
  }
}

TEST_CASE("detumble job: a tick past the longest refused naming detumble-tick", "[detumble]") {
  const Scenario sc = build_scenario(detumble_scenario("joint-torque-limit = [60, 60, 60, 40, 20, 20, 20]\n"
                                                       "detumble-tick = 1.2\n"),
                                     nullptr, ScenarioScope::Configuration);
  CHECK_THROWS_WITH(detumble(sc), Catch::Matchers::Contains("detumble-tick: detumble: the tick, 1.2 s") &&
                                      Catch::Matchers::Contains("1.08") &&
                                      Catch::Matchers::Contains("joint 'joint6'"));
}

}  // namespace test_detumble
