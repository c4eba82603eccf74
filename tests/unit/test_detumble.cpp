// The post-capture phase: the stack model (a body attached at a frame) against sums over bodies from
// finite differences of forward kinematics; the grasp's plastic impulse (momentum conserved, relative
// twist zero, the stack's momentum equal to the two bodies'); the detumbling controller and its run.

#include <catch2/catch.hpp>

#include "support/dynamics_helpers.hpp"

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/algorithm/forward_dynamics.hpp"
#include "ffsr/algorithm/grasp.hpp"
#include "ffsr/model/attach.hpp"

#include <cmath>
#include <limits>
#include <string>

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

}  // namespace test_detumble
