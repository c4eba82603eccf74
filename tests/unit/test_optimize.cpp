// Capture planning (optimize/capture.hpp): the gradient, the paper's Tables 4 and 7 through the
// shipped scenario files, conservation along the runs, and the failure modes.
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/capture.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace test_optimize {

using namespace ffsr;
using ffsr::test::deg;
using ffsr::test::problem_3dof;
using ffsr::test::kRobots;


namespace {

/// The 3-DOF scenario of robots/paper_3dof.toml: its robot and problem, a planar position task and a
/// 180 s task duration (the other options at their defaults).
struct Planar3dof {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  CaptureProblem pb = problem_3dof(m);
  CaptureTask task = planar();
  CaptureOptions opt = duration(180);
  static CaptureTask planar() {
    CaptureTask t;
    t.axes = {true, true, false};
    return t;
  }
  static CaptureOptions duration(double T) {
    CaptureOptions o;
    o.duration = T;
    return o;
  }
};

}  // namespace

TEST_CASE("The analytic M_ie gradient equals central differences", "[optimize]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (const char* robot : {"paper_3dof.urdf", "paper_7dof.urdf"}) {
    const Model m = model_from_urdf_file(kRobots + robot);
    Data d(m);
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::VectorXd q(m.n());
      for (int i = 0; i < m.n(); ++i) q(i) = 3 * U(rng);
      BasePose b;
      b.position = Vector3(U(rng), U(rng), U(rng));
      b.orientation = Quaternion(Eigen::AngleAxisd(2 * U(rng), Vector3(U(rng), U(rng), U(rng)).normalized()));
      Target t;
      t.contact_offset = Vector3(-0.25, 0.15, 0.1);
      t.attitude = Quaternion(Eigen::AngleAxisd(U(rng), Vector3(U(rng), U(rng), 1).normalized()));
      const Vector3 u = t.normal_world();
      const double c = t.inverse_mass_along_normal();
      Eigen::VectorXd g(m.n());
      const double M = integrated_effective_mass_gradient_dense(m, d, b, q, m.end_effector(), u, c, g);
      CHECK(M == Approx(integrated_effective_mass(m, d, b, q, m.end_effector(), t)).epsilon(1e-12));
      for (int k = 0; k < m.n(); ++k) {
        const double h = 1e-5;
        Eigen::VectorXd qp = q, qm = q;
        qp(k) += h;
        qm(k) -= h;
        const double fd = (integrated_effective_mass(m, d, b, qp, m.end_effector(), t) -
                           integrated_effective_mass(m, d, b, qm, m.end_effector(), t)) /
                          (2 * h);
        INFO(robot << " joint " << k << " analytic " << g(k) << " fd " << fd);
        // central difference error O(h^2) ~ 1e-10 relative to the largest entry
        CHECK(g(k) == Approx(fd).margin(1e-7 * (1 + g.cwiseAbs().maxCoeff())));
      }
    }
  }
}

TEST_CASE("Along a run the momentum stays zero and the quaternion unit", "[optimize]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  CaptureProblem pb;
  pb.model = &m;
  pb.frame = m.end_effector();
  pb.theta = deg({0, 90, 90, -90, 90, 90, 0});
  pb.base.orientation = Quaternion(Eigen::AngleAxisd(0.3, Vector3(1, 1, 0).normalized()));
  pb.base.position = Vector3(0.1, 0.2, -0.3);
  pb.target.position = pb.base.position + pb.base.orientation * Vector3(2.3, -0.8, 2);
  pb.target.angular_velocity = Vector3(1, -0.5, 2) * (M_PI / 180);
  pb.target.contact_offset = Vector3(-0.25, 0.15, 0.1);
  pb.target.inertia << 120, 4, 0, 4, 90, 0, 0, 0, 100;  // non-isotropic: the target tumbles (Euler)
  CaptureTask task;
  CaptureOptions opt;
  opt.duration = 157;
  opt.gain = -0.01;
  opt.record_series = true;
  opt.record_every = 50;
  const CaptureResult r = plan_capture(pb, task, opt);
  REQUIRE(r.max_body_momentum > 0);
  // momentum() sums over bodies; the base velocity came from H_b, H_bm (momentum conservation)
  CHECK(r.max_momentum < 1e-9 * r.max_body_momentum);
  CHECK(r.max_quaternion_error < 1e-6);
  // zero momentum: the system centre of mass does not move (an independent check of the integration)
  CHECK(r.max_com_drift < 1e-9);
  CHECK(r.max_tracking_error < 1e-3);
  CHECK(r.tracking_error < 1e-3);
  REQUIRE(r.series.size() > 10);
  for (const auto& s : r.series) CHECK(std::abs(s.base.orientation.norm() - 1.0) < 1e-12);
  // the capture point is the target's contact point at T (independent propagation: the angular
  // momentum of the torque-free target is constant in the inertial frame)
  const Target tT = propagate_target(pb.target, opt.duration);
  const Matrix3 R0 = pb.target.rotation(), RT = tT.rotation();
  const Vector3 L0 = R0 * pb.target.inertia * pb.target.angular_velocity;
  const Vector3 LT = RT * tT.inertia * tT.angular_velocity;
  CHECK((L0 - LT).norm() < 1e-8 * L0.norm());
  CHECK((r.capture_point - tT.contact_point()).norm() < 1e-12);
}

TEST_CASE_METHOD(Planar3dof, "The exact-force objective also lowers the force", "[optimize]") {
  const CaptureOptions plain = opt;
  CaptureOptions exact = plain;
  exact.gain = -0.01 / 300;  // dF/dtheta is about (alpha/(alpha+1)) F / M_ie times dM/dtheta: ~300 N/kg here
  exact.objective = CaptureObjective::ExactMaxForce;
  const CaptureResult a = plan_capture(pb, task, plain);
  const CaptureResult b = plan_capture(pb, task, exact);
  CHECK(b.f_max_exact < 0.6 * a.f_max_exact);
  CHECK(b.f_max_exact >= b.f_max_closed_form);
}

TEST_CASE_METHOD(Planar3dof, "Capture planning failures are typed errors", "[optimize]") {
  // a pose task has 6 rows, the robot 3 joints: no null space
  CaptureTask pose;
  pose.kind = CaptureTask::Kind::Pose;
  opt.gain = -0.01;
  CHECK_THROWS_AS(plan_capture(pb, pose, opt), InputError);
  // out of reach: the capture point is 10 m away
  CaptureProblem far = pb;
  far.target.position = Vector3(12, 1.45, 0);
  opt.gain = 0;
  CHECK_THROWS_WITH(plan_capture(far, task, opt), Catch::Contains("out of reach"));
  // a joint limit that the plain run crosses
  const std::string urdf_text = [] {
    std::ifstream in(kRobots + "paper_3dof.urdf");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string s = ss.str();
    const std::string from = "<joint name=\"joint3\" type=\"continuous\">";
    s.replace(s.find(from), from.size(),
              "<joint name=\"joint3\" type=\"revolute\"><limit lower=\"-1.8\" upper=\"-1.6\" effort=\"1\" "
              "velocity=\"1\"/>");
    return s;
  }();
  const Model limited = model_from_urdf_string(urdf_text, "limited");
  CaptureProblem lp = pb;
  lp.model = &limited;
  lp.frame = limited.end_effector();
  CHECK_THROWS_WITH(plan_capture(lp, task, opt), Catch::Contains("joint3"));
  // bad options
  CaptureOptions bad = opt;
  bad.step = 0;
  CHECK_THROWS_AS(plan_capture(pb, task, bad), InputError);
  bad = opt;
  bad.duration = std::nan("");
  CHECK_THROWS_AS(plan_capture(pb, task, bad), InputError);
  CaptureProblem badq = pb;
  badq.theta(1) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(plan_capture(badq, task, opt), InputError);
}

}  // namespace test_optimize
