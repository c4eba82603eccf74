// Global capture optimization (optimize/global.hpp): the capture-manifold search, the
// reaching planner, an optimality check that does not use the search, and the failure modes.
// The expensive runs (one global plan per robot) are made once and shared by the checks.
#include <catch2/catch.hpp>

#include "support/global_capture.hpp"
#include "support/paper.hpp"
#include "support/run_command.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/global.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

namespace test_global {

using namespace ffsr;
using ffsr::test::deg, ffsr::test::kRobots, ffsr::test::problem_3dof, ffsr::test::problem_7dof;
using namespace ffsr::test::global_capture;

namespace {

/// A damped-Newton projection onto the capture manifold written here, apart from the library's
/// (position rows only; plain Gauss-Newton with a fixed damping and no line search).
bool test_projection(const Model& m, Data& d, int frame, const BasePose& base, const Vector3& x,
                     const std::array<bool, 3>& axes, Eigen::VectorXd& q) {
  for (int it = 0; it < 200; ++it) {
    crba(m, d, base, q);
    const Vector3 e = frame_pose(m, d, frame).p - x;
    frame_jacobian(m, d, frame);
    std::vector<int> rows;
    for (int r = 0; r < 3; ++r)
      if (axes[static_cast<size_t>(r)]) rows.push_back(r);
    Eigen::MatrixXd J(rows.size(), m.n());
    Eigen::VectorXd r(rows.size());
    for (size_t i = 0; i < rows.size(); ++i) {
      J.row(static_cast<Eigen::Index>(i)) = d.J.row(rows[i]).tail(m.n());
      r(static_cast<Eigen::Index>(i)) = e(rows[i]);
    }
    if (r.norm() < 1e-11) return true;
    const Eigen::MatrixXd A = J * J.transpose() + 1e-6 * Eigen::MatrixXd::Identity(J.rows(), J.rows());
    Eigen::VectorXd step = J.transpose() * A.ldlt().solve(r);
    if (step.norm() > 0.5) step *= 0.5 / step.norm();  // trust region: at most 0.5 rad per iteration
    q -= step;
  }
  return false;
}

}  // namespace

TEST_CASE("Global optimum: no projected random configuration is more than 1 % lower", "[global]") {
  // Independent of the search: 1000 random configurations (fixed seed) put on the capture manifold at
  // the reached base pose by the projection above; M_ie at each must not be below optimum - 1 %.
  for (const Shared* s : {&shared_3dof(), &shared_7dof_position()}) {
    const Model& m = s->model;
    Data d(m);
    const Target cap = propagate_target(s->pb.target, s->opt.duration);
    const Vector3 x = cap.contact_point();
    std::mt19937_64 rng(20261122);
    std::uniform_real_distribution<double> U(-M_PI, M_PI);
    int on = 0;
    double lowest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 1000; ++i) {
      Eigen::VectorXd q(m.n());
      for (int k = 0; k < m.n(); ++k) q(k) = U(rng);
      if (!test_projection(m, d, s->pb.frame, s->global.run.base, x, s->task.axes, q)) continue;
      ++on;
      lowest = std::min(lowest, integrated_effective_mass(m, d, s->global.run.base, q, s->pb.frame, cap));
    }
    INFO(m.n() << "-DOF: " << on << " of 1000 projected, lowest M_ie " << lowest << ", reported optimum "
               << s->global.manifold_optimum);
    CHECK(on >= 900);
    CHECK(lowest >= 0.99 * s->global.manifold_optimum);
    std::printf(
        "%d-DOF: %d of 1000 random configurations projected, lowest M_ie %.4f kg >= optimum %.4f kg\n", m.n(),
        on, lowest, s->global.manifold_optimum);
  }
}

TEST_CASE("Manifold search: deterministic for a seed, exact-force has the mass optimum", "[global]") {
  const Shared& s = shared_3dof();
  const CaptureSetup setup = prepare_capture(s.pb, s.task, s.opt);
  ManifoldSearchOptions so;
  so.starts = 8;
  so.seed = 42;
  const ManifoldSearchResult a = search_capture_manifold(s.pb, s.task, setup, s.global.run.base, so);
  const ManifoldSearchResult b = search_capture_manifold(s.pb, s.task, setup, s.global.run.base, so);
  CHECK(a.best.theta == b.best.theta);  // bitwise: same draws, same SLSQP path
  CHECK(a.evaluations == b.evaluations);
  so.objective = GlobalObjective::ExactForce;
  const ManifoldSearchResult f = search_capture_manifold(s.pb, s.task, setup, s.global.run.base, so);
  CHECK(f.best.theta == a.best.theta);  // a monotone function of M_ie has the same minimizer
  CHECK(f.best.objective == Approx(max_force_exact(setup.capture.law, a.best.M_ie)).epsilon(1e-12));
  // the optimum is on the manifold: the end-effector on the capture point in x and y
  Data d(s.model);
  crba(s.model, d, s.global.run.base, a.best.theta);
  const Vector3 e = frame_pose(s.model, d, s.pb.frame).p - setup.capture.x_cap;
  CHECK(e.head<2>().norm() < 1e-9);
}

TEST_CASE("Capture residual: orientation rows' Jacobian equals central differences", "[global]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  CaptureProblem pb = problem_7dof(m);
  CaptureTask task;
  task.kind = CaptureTask::Kind::Pose;
  task.final_orientation = Matrix3(Eigen::AngleAxisd(0.7, Vector3(1, 2, 3).normalized()));
  const CaptureSetup s = prepare_capture(pb, task, options(157));
  BasePose b;
  b.position = Vector3(0.1, -0.2, 0.05);
  check_residual_jacobian(m, pb, task, s, b, deg({10, 80, 70, -60, 100, 80, 20}));
}

TEST_CASE("Global capture: bad inputs", "[global]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  const CaptureProblem pb = problem_3dof(m);
  const CaptureTask task = position_task(true);
  CaptureOptions o = options(180);
  GlobalCaptureOptions g;
  g.search.starts = 0;
  CHECK_THROWS_WITH(plan_capture_global(pb, task, o, g), Catch::Contains("starts must be >= 1"));
  g.search.starts = 4;
  o.max_joint_rate = -1;
  CHECK_THROWS_AS(plan_capture_global(pb, task, o, g), InputError);
  o.max_joint_rate = 0.01 * M_PI / 180;  // 0.01 deg/s: the line alone needs more
  CHECK_THROWS_WITH(plan_capture_global(pb, task, o, g), Catch::Contains("below what the task alone needs"));
  // a capture point out of reach from the base pose at T: no configuration on the manifold
  o.max_joint_rate = kRate;
  const CaptureSetup s = prepare_capture(pb, task, o);
  BasePose far;
  far.position = Vector3(-5, 0, 0);
  CHECK_THROWS_WITH(search_capture_manifold(pb, task, s, far, g.search), Catch::Contains("out of reach"));
  // a target 10 m away: the task alone cannot follow the line; with a reconfiguration allowed the
  // search at the initial base pose finds nothing either, and the error (a NumericalError, as without
  // a reconfiguration) names both
  CaptureProblem away = pb;
  away.target.position += Vector3(10, 0, 0);
  for (const ReconfigureMode mode : {ReconfigureMode::Never, ReconfigureMode::Auto, ReconfigureMode::Always}) {
    g.reconfigure.mode = mode;
    INFO(reconfigure_mode_name(mode));
    try {
      plan_capture_global(away, task, o, g);
      FAIL("no error");
    } catch (const InputError& e) {
      FAIL("an InputError: " << e.what());
    } catch (const NumericalError& e) {
      const std::string what = e.what();
      CHECK_THAT(what, Catch::Contains("cannot follow the line"));
      if (mode != ReconfigureMode::Never) CHECK_THAT(what, Catch::Contains("the search at the initial base pose"));
      CHECK(what.find('\n') == std::string::npos);
    }
  }
}

namespace {

/// Runs ffsr-optimize in a temporary directory.
ffsr::test::CommandResult cli(std::vector<std::string> args) {
  args.insert(args.begin(), FFSR_CLI);
  ffsr::test::TempDir tmp;
  return ffsr::test::run_command(args, tmp.str());
}

}  // namespace

TEST_CASE("ffsr-optimize: bad global inputs give one error line naming the key", "[global][cli]") {
  const std::string sc = kRobots + "paper_3dof.toml";
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--max-joint-rate-deg", "0"}, "--max-joint-rate-deg"},
      {{"--max-joint-rate-deg", "-3"}, "--max-joint-rate-deg"},
      {{"--max-joint-rate-deg", "0.01"}, "--max-joint-rate-deg"},  // the line alone needs more
      {{"--seed", "abc"}, "--seed"},
      {{"--seed", "1.5"}, "--seed"},
      {{"--global-starts", "0"}, "--global-starts"},
      {{"--objective", "energy"}, "--objective"},
  };
  for (const auto& [extra, key] : cases) {
    std::vector<std::string> args{"--quiet", "--config", sc};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = cli(args);
    INFO(extra[0] << " " << extra[1] << " -> " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.out.empty());
    CHECK(r.err.rfind("ffsr-optimize: error: " + key, 0) == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  }
}

}  // namespace test_global
