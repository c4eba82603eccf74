// The parts of the capture planner, each alone: the line reference, the task solver (rate law of
// Eq. 30-31), the null-space policies, the free-floating RK4 step and the run monitors.
// Expected values come from identities (end points, finite differences, J_t N = 0, N N = N,
// conservation of the centre of mass under zero momentum) or from independent computations.

// The rate law must not allocate per call: Eigen's runtime malloc check, made to throw (in a release
// build eigen_assert is otherwise compiled out). Defined before any Eigen header.
#define EIGEN_RUNTIME_NO_MALLOC
#include <stdexcept>
#define eigen_assert(x)                                           \
  do {                                                            \
    if (!(x)) throw std::logic_error("eigen_assert failed: " #x); \
  } while (false)

#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/capture.hpp"

#include <fstream>
#include <random>
#include <sstream>

namespace test_planner {

using namespace ffsr;
using ffsr::test::kRobots;

namespace {

Eigen::VectorXd random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> U(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = U(rng);
  return v;
}

BasePose random_base(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  BasePose b;
  b.position = Vector3(U(rng), U(rng), U(rng));
  b.orientation = Quaternion(Eigen::AngleAxisd(2 * U(rng), Vector3(U(rng), U(rng), U(rng)).normalized()));
  return b;
}

/// paper_7dof with joint `name` made revolute within [lower, upper].
Model limited_7dof(const std::string& name, double lower, double upper) {
  std::ifstream in(kRobots + "paper_7dof.urdf");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  const std::string from = "<joint name=\"" + name + "\" type=\"continuous\">";
  s.replace(s.find(from), from.size(),
            "<joint name=\"" + name + "\" type=\"revolute\"><limit lower=\"" + std::to_string(lower) +
                "\" upper=\"" + std::to_string(upper) + "\" effort=\"1\" velocity=\"1\"/>");
  return model_from_urdf_string(s, "limited");
}

Vector3 centre_of_mass(const Model& m, Data& d, const BasePose& b, const Eigen::VectorXd& q) {
  crba(m, d, b, q);
  double mass = 0;
  Vector3 c = Vector3::Zero();
  for (int i = 0; i < m.nb(); ++i) {  // body by body, independent of the composite inertias
    const Inertia& in = m.body(i).inertia;
    c += in.mass * (d.p[static_cast<size_t>(i)] + d.R[static_cast<size_t>(i)] * in.com);
    mass += in.mass;
  }
  return c / mass;
}

/// A capture setup with nothing but what a policy reads filled in by the test.
CaptureSetup bare_setup() {
  return CaptureSetup{{Target{}, {}, {}, 0, 0, make_contact_law("hunt-crossley", ContactParams{}, 1.0), {}},
                      {},
                      {},
                      {},
                      {}};
}

}  // namespace

TEST_CASE("The line reference starts and ends at rest on its end points", "[planner]") {
  LineReference line;
  line.x0 = Vector3(1, 2, 3);
  line.x_cap = Vector3(-0.5, 4, 2.5);
  line.R0 = Quaternion(Eigen::AngleAxisd(0.7, Vector3(1, 2, -1).normalized())).toRotationMatrix();
  const Matrix3 R_end = Quaternion(Eigen::AngleAxisd(-1.1, Vector3(0, 1, 3).normalized())).toRotationMatrix();
  line.rot_total = detail::rotation_log(R_end * line.R0.transpose());
  line.duration = 50;
  Vector3 x, v, w;
  Matrix3 R;
  line.at(0, x, v, R, w);
  CHECK((x - line.x0).norm() < 1e-15);  // end points: exact by s(0) = 0
  CHECK(v.norm() == 0.0);
  CHECK(w.norm() == 0.0);
  CHECK((R - line.R0).norm() < 1e-15);
  line.at(line.duration, x, v, R, w);
  CHECK((x - line.x_cap).norm() < 1e-14);  // s(1) = 1 up to rounding
  CHECK(v.norm() == 0.0);
  CHECK(w.norm() == 0.0);
  CHECK((R - R_end).norm() < 1e-12);
  // velocity and angular velocity against central differences (error O(h^2) ~ 1e-10 here)
  const double h = 1e-4;
  for (double t : {3.0, 17.5, 25.0, 41.0}) {
    Vector3 xp, xm, vp, wp;
    Matrix3 Rp, Rm;
    line.at(t, x, v, R, w);
    line.at(t + h, xp, vp, Rp, wp);
    line.at(t - h, xm, vp, Rm, wp);
    CHECK((v - (xp - xm) / (2 * h)).norm() < 1e-8 * (1 + v.norm()));
    CHECK((w - detail::rotation_log(Rp * Rm.transpose()) / (2 * h)).norm() < 1e-8 * (1 + w.norm()));
    CHECK((line.position(t) - x).norm() == 0.0);
    // on the segment: x - x0 parallel to x_cap - x0
    CHECK((x - line.x0).cross(line.x_cap - line.x0).norm() < 1e-12);
  }
}

TEST_CASE("The task velocity command is the reference velocity on the reference", "[planner]") {
  LineReference line;
  line.x0 = Vector3(0, 0, 0);
  line.x_cap = Vector3(1, 1, 0);
  line.rot_total = Vector3(0, 0, 0.5);
  line.duration = 10;
  Vector3 x, v, w;
  Matrix3 R;
  line.at(4, x, v, R, w);
  const Vector6 on = task_velocity_command(line, 4, Pose{x, R}, 2.0, true);
  CHECK((on.head<3>() - v).norm() < 1e-15);
  CHECK((on.tail<3>() - w).norm() < 1e-12);
  // off the reference by d: the linear part gains k_p d; a position task has no angular part
  const Vector3 d(0.01, -0.02, 0.03);
  const Vector6 off = task_velocity_command(line, 4, Pose{x - d, R}, 2.0, false);
  CHECK((off.head<3>() - (v + 2.0 * d)).norm() < 1e-15);
  CHECK(off.tail<3>().norm() == 0.0);
}

TEST_CASE("The task solver's rates follow the task and its projector spans the null space", "[planner]") {
  std::mt19937 rng(11);
  const int n = 7;
  TaskSolver solver(n, {0, 1, 2, 4}, 1e-3, 1e-2);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::MatrixXd Jf = Eigen::MatrixXd(random_vector(rng, 6 * n, 1.0).reshaped(6, n));
    const Vector6 cmd = random_vector(rng, 6, 0.1);
    const TaskRates& r = solver.solve(Jf, cmd, true);
    Eigen::MatrixXd Jt(4, n);
    Eigen::VectorXd ct(4);
    const int rows[4] = {0, 1, 2, 4};
    for (int i = 0; i < 4; ++i) {
      Jt.row(i) = Jf.row(rows[i]);
      ct(i) = cmd(rows[i]);
    }
    // an independent SVD gives the smallest singular value; a random 4x7 matrix is far from singular
    const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(Jt).singularValues();
    CHECK(std::abs(r.sigma_min - sv(3)) < 1e-12);
    REQUIRE_FALSE(r.damped);
    CHECK((Jt * r.theta_dot - ct).norm() < 1e-12);  // J_t J_t^+ = E (full row rank)
    // the minimum-norm solution: orthogonal to the null space
    const Eigen::MatrixXd& N = solver.projector();
    CHECK((N * r.theta_dot).norm() < 1e-12);
    CHECK((N * N - N).norm() < 1e-12);             // idempotent
    CHECK((N - N.transpose()).norm() < 1e-12);     // symmetric
    CHECK((Jt * N).norm() < 1e-12);                // J_t N = 0
    CHECK(std::abs(N.trace() - (n - 4)) < 1e-12);  // rank n - m
  }
}

TEST_CASE("The task solver damps near a singularity and scales the null-space rates to the limit",
          "[planner]") {
  std::mt19937 rng(5);
  const int n = 6;
  TaskSolver solver(n, {0, 1, 2}, 1e-3, 1e-2);
  Eigen::MatrixXd Jf = Eigen::MatrixXd(random_vector(rng, 6 * n, 1.0).reshaped(6, n));
  Jf.row(2) = Jf.row(0) + 1e-6 * Jf.row(1);  // sigma_min ~ 1e-6, below the threshold
  const Vector6 cmd = random_vector(rng, 6, 0.1);
  const TaskRates& r = solver.solve(Jf, cmd, true);
  CHECK(r.damped);
  CHECK(r.sigma_min < 1e-5);
  const double q = r.sigma_min / 1e-3;
  CHECK(std::abs(r.lambda2 - (1 - q * q) * 1e-4) < 1e-18);
  // damped least squares: theta_dot = J_t^T (J_t J_t^T + lambda^2 E)^-1 cmd_t, computed independently
  const Eigen::MatrixXd Jt = Jf.topRows(3);
  const Eigen::VectorXd expect =
      Jt.transpose() *
      (Jt * Jt.transpose() + r.lambda2 * Eigen::MatrixXd::Identity(3, 3)).ldlt().solve(cmd.head(3));
  CHECK((r.theta_dot - expect).norm() < 1e-9 * expect.norm());

  // scaling: task rates well inside the limit, a large null-space term
  TaskSolver s2(n, {0, 1}, 1e-3, 1e-2);
  Jf = Eigen::MatrixXd(random_vector(rng, 6 * n, 1.0).reshaped(6, n));
  const TaskRates& a = s2.solve(Jf, 0.01 * cmd, true);
  const double L = 2 * a.theta_dot.cwiseAbs().maxCoeff() + 0.01;
  const Eigen::VectorXd task_part = a.theta_dot;
  Eigen::VectorXd qd = s2.projector() * random_vector(rng, n, 10.0);
  const Eigen::VectorXd qd0 = qd;
  const TaskRates& b = s2.add_null_space(qd, L);
  CHECK(b.null_scale > 0);
  CHECK(b.null_scale < 1);
  CHECK(b.theta_dot.cwiseAbs().maxCoeff() <= L * (1 + 1e-12));
  CHECK(std::abs(b.theta_dot.cwiseAbs().maxCoeff() - L) < 1e-12 * L);  // the limit is reached
  CHECK((b.theta_dot - task_part - b.null_scale * qd0).norm() < 1e-12);
  CHECK((Jf.topRows(2) * (b.theta_dot - task_part)).norm() < 1e-10);  // the task is untouched
}

TEST_CASE("The task solver does not allocate per call", "[planner]") {
  std::mt19937 rng(3);
  const int n = 7;
  TaskSolver solver(n, {0, 1, 2, 3, 4, 5}, 1e-3, 1e-2);
  const Eigen::MatrixXd Jf = Eigen::MatrixXd(random_vector(rng, 6 * n, 1.0).reshaped(6, n));
  const Vector6 cmd = random_vector(rng, 6, 0.1);
  Eigen::VectorXd qd = random_vector(rng, n, 1.0);
  const Eigen::Index m_alloc_probe_size = 16;
  solver.solve(Jf, cmd, true);  // warm-up (no allocation expected either)
  Eigen::internal::set_is_malloc_allowed(false);
  // the check is live: a heap allocation throws
  CHECK_THROWS_AS(Eigen::VectorXd(m_alloc_probe_size), std::logic_error);
  bool ok = true;
  try {
    solver.solve(Jf, cmd, true);
    solver.add_null_space(qd, 0.5);
  } catch (const std::logic_error&) {
    ok = false;
  }
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(ok);
}

TEST_CASE("The null-space policies", "[planner]") {
  SECTION("servo: k (goal - theta) with continuous joints the short way round") {
    const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
    Data d(m);
    CaptureSetup s = bare_setup();
    s.line.duration = 20;
    ServoPolicy servo;
    servo.theta_goal = Eigen::VectorXd::Constant(m.n(), 3.0);
    const Eigen::VectorXd theta =
        Eigen::VectorXd::Constant(m.n(), -3.0);  // 6 rad apart: -0.283 the short way
    Eigen::VectorXd qd(m.n());
    servo(m, d, CaptureProblem{}, s, 0, BasePose{}, theta, Eigen::MatrixXd::Identity(m.n(), m.n()), qd);
    for (int k = 0; k < m.n(); ++k) CHECK(std::abs(qd(k) - 0.5 * (6.0 - 2 * M_PI)) < 1e-14);
  }
  SECTION("joint-limit repulsion inside the 10 % margin only") {
    const Model m = limited_7dof("joint2", -1.0, 1.0);
    Eigen::VectorXd theta = Eigen::VectorXd::Zero(m.n());
    Eigen::VectorXd g = Eigen::VectorXd::Constant(m.n(), 0.5);
    detail::add_joint_limit_repulsion(m, theta, g);
    CHECK(g == Eigen::VectorXd::Constant(m.n(), 0.5));  // far from the limit: unchanged
    theta(1) = -0.95;                                   // half-way into the lower margin [-1, -0.8]
    detail::add_joint_limit_repulsion(m, theta, g);
    CHECK(std::abs(g(1) - (0.5 - 1.5 * 0.75)) < 1e-14);  // scale |g|max + 1 = 1.5, depth 0.15/0.2
    theta(1) = 0.95;
    g.setConstant(0.5);
    detail::add_joint_limit_repulsion(m, theta, g);
    CHECK(std::abs(g(1) - (0.5 + 1.5 * 0.75)) < 1e-14);
  }
  SECTION("gradient: rho N grad M_ie, in the null space of the task") {
    const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
    Data d(m);
    std::mt19937 rng(2);
    const BasePose base = random_base(rng);
    const Eigen::VectorXd theta = random_vector(rng, m.n(), 2.0);
    CaptureProblem pb;
    pb.model = &m;
    pb.frame = m.end_effector();
    CaptureSetup s = bare_setup();
    s.capture.u_cap = Vector3(1, 2, -1).normalized();
    s.capture.target_inv_mass = 1.0 / 200;
    crba(m, d, base, theta);
    frame_jacobian(m, d, pb.frame);
    generalized_jacobian(m, d);
    TaskSolver solver(m.n(), {0, 1, 2}, 1e-3, 1e-2);
    solver.solve(d.Jf, Vector6::Zero(), true);
    GradientPolicy policy;
    policy.gain = -0.1;
    Eigen::VectorXd qd(m.n());
    policy(m, d, pb, s, 0, base, theta, solver.projector(), qd);
    CHECK((solver.task_jacobian() * qd).norm() < 1e-12 * (1 + qd.norm()));
    // with N = E: rho times the central difference of M_ie (no joint limits on this robot)
    policy(m, d, pb, s, 0, base, theta, Eigen::MatrixXd::Identity(m.n(), m.n()), qd);
    const double h = 1e-6, b = s.capture.target_inv_mass;
    for (int k = 0; k < m.n(); ++k) {
      Eigen::VectorXd tp = theta, tm = theta;
      tp(k) += h;
      tm(k) -= h;
      crba(m, d, base, tp);
      const double Mp = 1.0 / (inverse_effective_mass(m, d, pb.frame, s.capture.u_cap) + b);
      crba(m, d, base, tm);
      const double Mm = 1.0 / (inverse_effective_mass(m, d, pb.frame, s.capture.u_cap) + b);
      CHECK(std::abs(qd(k) - policy.gain * (Mp - Mm) / (2 * h)) < 1e-5 * (1 + std::abs(qd(k))));
    }
  }
}

TEST_CASE("One free-floating RK4 step keeps the momentum zero and the centre of mass still", "[planner]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  Data d(m);
  std::mt19937 rng(9);
  for (int trial = 0; trial < 3; ++trial) {
    BasePose base = random_base(rng);
    Eigen::VectorXd theta = random_vector(rng, m.n(), 2.0);
    const Eigen::VectorXd rates = random_vector(rng, m.n(), 0.1);
    auto field = [&](double t, const BasePose& b, const Eigen::VectorXd& q, Eigen::VectorXd& qd,
                     Vector6& xb) {
      crba(m, d, b, q);
      qd = rates * std::cos(t);
      xb = base_velocity_from_momentum(m, d, qd);
    };
    const Vector3 c0 = centre_of_mass(m, d, base, theta);
    FreeFloatingRK4 rk4(m.n());
    const double qerr = rk4.step(field, 0.3, 0.01, base, theta);
    CHECK(qerr < 1e-6);                                      // O(h^2 |w|^2)
    CHECK(std::abs(base.orientation.norm() - 1.0) < 1e-15);  // renormalized
    const Vector3 c1 = centre_of_mass(m, d, base, theta);
    CHECK((c1 - c0).norm() < 1e-12);  // zero linear momentum: the centre of mass stays (RK4 error ~h^5)
    // the total momentum of the stage rates at the new state
    Eigen::VectorXd qd(m.n());
    Vector6 xb;
    field(0.31, base, theta, qd, xb);
    Eigen::VectorXd v(m.nv());
    v << xb, qd;
    CHECK(momentum(m, d, v).norm() < 1e-12);
  }
}

TEST_CASE("Each run monitor trips on its violation", "[planner]") {
  const Model m = limited_7dof("joint3", -1.0, 1.0);
  Data d(m);
  RunMonitors mon(m, "test", 0.01);
  SECTION("tracking: only the constrained rows count") {
    CHECK(mon.check_tracking(Vector3(0.003, 0.004, 0.5), {0, 1}, 1.0) == Approx(0.005).epsilon(1e-14));
    CHECK(mon.max_tracking_error == Approx(0.005).epsilon(1e-14));
    CHECK_THROWS_WITH(mon.check_tracking(Vector3(0.02, 0, 0), {0, 1}, 2.0),
                      Catch::Contains("test: the end-effector cannot follow the line"));
  }
  SECTION("state: joint limits and finiteness") {
    Eigen::VectorXd theta = Eigen::VectorXd::Zero(m.n());
    CHECK_NOTHROW(mon.check_state(m, BasePose{}, theta, 1.0));
    theta(2) = 1.1;
    CHECK_THROWS_AS(mon.check_state(m, BasePose{}, theta, 1.0), JointLimitError);
    CHECK_THROWS_WITH(mon.check_state(m, BasePose{}, theta, 1.0), Catch::Contains("joint3"));
    theta(2) = std::nan("");
    CHECK_THROWS_WITH(mon.check_state(m, BasePose{}, theta, 1.0), Catch::Contains("non-finite"));
  }
  SECTION("momentum and centre of mass") {
    std::mt19937 rng(4);
    const BasePose base = random_base(rng);
    const Eigen::VectorXd theta = random_vector(rng, m.n(), 0.5);
    const Eigen::VectorXd qd = random_vector(rng, m.n(), 0.1);
    crba(m, d, base, theta);
    mon.check_motion(m, d, base_velocity_from_momentum(m, d, qd), qd);
    CHECK(mon.max_momentum < 1e-12);
    CHECK(mon.max_com_drift == 0.0);
    mon.check_motion(m, d, Vector6::Zero(), qd);  // the base held still: the arm's momentum shows
    CHECK(mon.max_momentum > 1e-3);
    BasePose moved = base;
    moved.position += Vector3(0.03, 0, -0.04);
    crba(m, d, moved, theta);
    mon.check_motion(m, d, Vector6::Zero(), qd);
    CHECK(std::abs(mon.max_com_drift - 0.05) < 1e-12);
  }
  SECTION("quaternion norm and the record") {
    mon.check_quaternion(2e-9);
    mon.check_quaternion(1e-9);
    CaptureResult r;
    mon.record(r);
    CHECK(r.max_quaternion_error == 2e-9);
  }
}

}  // namespace test_planner
