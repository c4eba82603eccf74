// The reaction-null-space approach (optimize/base_attitude.hpp, TaskSolver's extra rows, the scenario
// key base-attitude): the stacked rate law holds the base's angular velocity at zero, the 7-DOF
// position scenario with hold keeps its attitude, and the robots without the freedom are refused.
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/base_attitude.hpp"

#include <string>

namespace test_base_attitude {

using namespace ffsr;
using ffsr::test::deg, ffsr::test::kRobots;

TEST_CASE(
    "TaskSolver with the base-attitude rows: task tracked, w_0 = 0, projector on the stack's null space",
    "[base_attitude]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  Data d(m);
  const BasePose base;
  const Eigen::VectorXd q = deg({10, 70, 80, -60, 40, 100, -20});
  const Eigen::MatrixXd Q = base_attitude_directions(m, d, base, q, m.end_effector());
  REQUIRE(Q.cols() == 3);
  const Eigen::MatrixXd A = Q.transpose() * base_angular_rows(d);
  TaskSolver plain(m.n(), {0, 1, 2}, 1e-3, 1e-2), held(m.n(), {0, 1, 2}, 3, 1e-3, 1e-2);
  Vector6 cmd;
  cmd << 0.01, -0.02, 0.005, 0, 0, 0;
  const Eigen::VectorXd free_rates = plain.solve(d.Jf, cmd, true).theta_dot;
  const Eigen::VectorXd rates = held.solve(d.Jf, cmd, true, A).theta_dot;
  CHECK((d.Jf.topRows<3>() * rates - cmd.head<3>()).norm() < 1e-12);
  CHECK((d.Jf.topRows<3>() * free_rates - cmd.head<3>()).norm() < 1e-12);
  // the base's angular velocity from zero momentum (an independent construction: momentum.hpp)
  const Vector6 xb_held = base_velocity_from_momentum(m, d, rates);
  const Vector6 xb_free = base_velocity_from_momentum(m, d, free_rates);
  CHECK(xb_held.tail<3>().norm() < 1e-12 * xb_free.tail<3>().norm() + 1e-15);
  CHECK(xb_free.tail<3>().norm() > 1e-4);
  const Eigen::MatrixXd& N = held.projector();
  CHECK((d.Jf.topRows<3>() * N).norm() < 1e-12);
  CHECK((A * N).norm() < 1e-12);
  CHECK(N.trace() == Approx(1.0));  // 7 - 3 - 3: one direction left for the objective
  CHECK_THROWS_AS(held.solve(d.Jf, cmd, true), InputError);
  CHECK_THROWS_AS(held.solve(d.Jf, cmd, true, Eigen::MatrixXd::Zero(2, m.n())), InputError);
}

TEST_CASE("Planar arm: one base-attitude direction, the plane's normal", "[base_attitude]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  Data d(m);
  const Eigen::MatrixXd Q = base_attitude_directions(m, d, BasePose{}, deg({0, 150, -100}), m.end_effector());
  REQUIRE(Q.cols() == 1);
  CHECK(std::abs(Q.col(0).normalized().dot(Vector3::UnitZ())) == Approx(1.0));
  // scaled so that the held row has unit singular value
  CHECK((Q.transpose() * base_angular_rows(d)).norm() == Approx(1.0));
}

Scenario scenario(const std::string& file, const std::string& mode) {
  ScenarioKeys k = read_scenario_file(kRobots + file);
  override_scenario_key(k, "base-attitude", mode);
  override_scenario_key(k, "global", "false");
  return build_scenario(std::move(k));
}

TEST_CASE(
    "Reaction-null-space approach on the 7-DOF robot: the base attitude stays, capture within tolerance",
    "[base_attitude]") {
  // a short approach (10 s, the capture point a few centimetres from the end-effector) that meets no
  // algorithmic singularity of J_t N_A (robots/paper_7dof_position.toml's 157 s approach does: see
  // the next test case)
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  CaptureProblem pb = ffsr::test::problem_7dof(m);
  pb.contact = ffsr::test::kPaperContact;
  Data d(m);
  crba(m, d, pb.base, pb.theta);
  CaptureOptions opt;
  opt.duration = 10;
  opt.step = 0.05;
  opt.gain = -0.01;
  const Target at_T = propagate_target(pb.target, opt.duration);
  pb.target.position += frame_pose(m, d, pb.frame).p + Vector3(0.03, -0.02, 0.04) - at_T.contact_point();
  const CaptureResult free_run = plan_capture(pb, CaptureTask{}, opt);
  opt.hold_base_attitude = true;
  const CaptureResult held = plan_capture(pb, CaptureTask{}, opt);
  INFO("M_ie free " << free_run.M_ie << " hold " << held.M_ie << "; attitude drift free "
                    << free_run.base_attitude_drift * 180 / M_PI << " deg, hold "
                    << held.base_attitude_drift * 180 / M_PI << " deg; momentum " << held.max_momentum);
  CHECK(held.base_attitude_drift * 180.0 / M_PI < 0.01);
  CHECK(held.base_attitude_drift < 1e-3 * free_run.base_attitude_drift);
  CHECK(held.tracking_error <= opt.tolerance);
  CHECK(held.max_momentum < 1e-9 * held.max_body_momentum + 1e-12);
  CHECK(held.damped_steps == 0);
  CHECK(held.M_ie >= free_run.M_ie * (1 - 1e-9));  // the objective has less freedom
}

TEST_CASE("7-DOF position scenario with base-attitude = hold: the approach meets an algorithmic singularity",
          "[base_attitude]") {
  // the plain run (pose task) is the one without the key; the held optimized run lags the line from
  // t = 99.7 s, where J_t N_A loses rank, and fails the tracking check at t = 106 s instead of turning
  // the base. The error says why: the only freedom the position task and the held rows leave is
  // joint 7, which turns the end-effector about its own axis (the robot's last link), so the
  // objective cannot steer joints 1-6 away from the singularity.
  const Scenario free_sc = scenario("paper_7dof_position.toml", "free");
  const Scenario hold_sc = scenario("paper_7dof_position.toml", "hold");
  CHECK_FALSE(free_sc.hold_base_attitude);
  CHECK(hold_sc.hold_base_attitude);
  try {
    plan_plain_and_optimized(hold_sc);
    FAIL("expected the held run to stop at the singularity");
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.rfind("optimized run: plan_capture: holding the base attitude, the arm meets an algorithmic "
                     "singularity: from t = 99.7 s",
                     0) == 0);
    CHECK(what.find("at t = 106 s the end-effector is 0.0102 m off the line") != std::string::npos);
    CHECK(what.find("the freedom the task and the held rows leave at t = 0 is in joint7 (100 %)") !=
          std::string::npos);
    CHECK(what.find('\n') == std::string::npos);
  }
}

TEST_CASE("held_freedom_shares: the joints the null space of the task and held rows moves",
          "[base_attitude]") {
  // stacks with a known null space
  Eigen::MatrixXd Jt = Eigen::MatrixXd::Zero(3, 7), A = Eigen::MatrixXd::Zero(3, 7);
  Jt.leftCols(3).setIdentity();
  A.middleCols(3, 3).setIdentity();
  Eigen::VectorXd expected = Eigen::VectorXd::Zero(7);
  expected(6) = 1;
  CHECK((held_freedom_shares(Jt, A) - expected).norm() < 1e-12);
  A(2, 5) = 0;  // the null space is now joints 6 and 7: half each
  A(2, 6) = 0;
  expected(5) = expected(6) = 0.5;
  CHECK((held_freedom_shares(Jt, A.topRows(2)) - expected).norm() < 1e-12);
  CHECK(held_freedom_shares(Eigen::MatrixXd::Identity(3, 3), Eigen::MatrixXd::Zero(0, 3)).isZero());

  // the paper's 7-DOF robot, position task, held base: joint 7 moves neither the end-effector
  // (finite difference of its position) nor, by the rows' construction, the base attitude much; the
  // shares put the whole freedom there
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  const CaptureProblem pb = ffsr::test::problem_7dof(m);
  Data d(m);
  Eigen::VectorXd th = pb.theta;
  crba(m, d, pb.base, th);
  const Vector3 p0 = frame_pose(m, d, pb.frame).p;
  th(6) += 0.3;
  crba(m, d, pb.base, th);
  CHECK((frame_pose(m, d, pb.frame).p - p0).norm() < 1e-12);
  const Eigen::MatrixXd Q = base_attitude_directions(m, d, pb.base, pb.theta, pb.frame);
  const Eigen::VectorXd shares =
      held_freedom_shares(d.Jf.topRows(3), Q.transpose() * base_angular_rows(d));
  INFO("shares " << shares.transpose());
  CHECK(std::abs(shares.sum() - 1) < 1e-12);
  CHECK(shares(6) > 0.9999);
}

TEST_CASE("base-attitude: bad modes and robots without the freedom, one line naming the key",
          "[base_attitude]") {
  auto message = [](const std::string& file, const std::string& mode) {
    try {
      scenario(file, mode);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string planar = message("paper_3dof.toml", "hold");
  CHECK(planar.rfind("--base-attitude:", 0) == 0);
  CHECK(planar.find("2 task rows + 1 base-attitude row = 3 of the robot's 3 joints") != std::string::npos);
  CHECK(planar.find("it needs 4 joints") != std::string::npos);
  CHECK(planar.find('\n') == std::string::npos);
  const std::string pose = message("paper_7dof_pose.toml", "hold");
  CHECK(pose.find("6 task rows + 3 base-attitude rows = 9 of the robot's 7 joints") != std::string::npos);
  CHECK(pose.find("gain = 0") == std::string::npos);  // 9 rows: no tracking either
  const std::string bad = message("paper_7dof_position.toml", "lock");
  CHECK(bad == "--base-attitude: unknown mode 'lock'; expected 'free' or 'hold'");
  // pure tracking (gain 0) on the planar arm: 2 + 1 = 3 joints suffice
  ScenarioKeys k = read_scenario_file(kRobots + "paper_3dof.toml");
  override_scenario_key(k, "base-attitude", "hold");
  override_scenario_key(k, "gain", "0");
  CHECK(build_scenario(std::move(k)).hold_base_attitude);
}

}  // namespace test_base_attitude
