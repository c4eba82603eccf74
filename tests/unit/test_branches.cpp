// The branches of the capture manifold (optimize/global.hpp, optimize/branches.hpp,
// docs/branches.md): the orientation residual and its Jacobian, the optima of a pose-task search,
// and the UR5's inverse-kinematics branches against an enumeration written here.
#include <catch2/catch.hpp>

#include "support/global_capture.hpp"
#include "support/paper.hpp"

#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/branches.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>
#include <filesystem>
#include <random>

// The branches of the capture manifold (optimize/global.hpp, optimize/branches.hpp,
// docs/branches.md): the orientation residual (the rotation vector of R_end R_e^T, zero only at the
// wanted orientation) and its Jacobian against central differences, a half-turned gripper off the
// manifold, every optimum of a pose-task search within the orientation tolerance, and for the UR5
// with a pose task (no null space) the inverse-kinematics branches against an enumeration written
// here (a Gauss-Newton on the 12 rows [p - x_cap; R - R_end], finite-difference Jacobian).

namespace test_branches {

using namespace ffsr;

namespace {

const std::string kData = std::string(FFSR_SOURCE_DIR) + "/tests/data/";

bool have_ur5() {
  const std::string f = std::string(FFSR_SOURCE_DIR) + "/../shared/urdf-samples/ur5_robot.urdf";
  if (std::filesystem::exists(f)) return true;
  WARN("skipped: the UR5 URDF sample is not at " << f);
  return false;
}

CaptureOptions search_options(const Scenario& sc) {
  CaptureOptions o = sc.capture;
  o.gain = 0;
  o.record_series = false;
  o.max_joint_rate = sc.keys.max_joint_rate_deg * M_PI / 180.0;
  return o;
}

/// A scenario's search inputs: the setup (gain 0) and the base pose at T of the task-only run.
struct SearchInputs {
  Scenario sc;
  CaptureOptions opt;
  CaptureSetup setup;
  BasePose base;
  Eigen::VectorXd plain_theta;
  explicit SearchInputs(const std::string& file)
      : sc(load_scenario(file)), opt(search_options(sc)), setup(prepare_capture(sc.problem, sc.task, opt)) {
    ServoPolicy none;
    const CaptureResult plain = integrate_capture(sc.problem, sc.task, opt, setup, none);
    base = plain.base;
    plain_theta = plain.theta;
  }
  /// The manifold search of the scenario (its seed and starts) from the paper's method's end.
  ManifoldSearchResult search() const {
    ManifoldSearchOptions so;
    so.seed = sc.seed;
    so.starts = sc.keys.global_starts;
    return search_capture_manifold(sc.problem, sc.task, setup, base, so, {plain_theta});
  }
  /// The branches of `res`, the reachability of the best `reach` of them checked.
  std::vector<CaptureBranch> branches(const ManifoldSearchResult& res, int reach) const {
    return capture_branches(sc.problem, sc.task, opt, setup, res, base, reach);
  }
};

/// The pose residual of this test: [p_e - x_cap; R_e - R_end (9 entries)], zero exactly at the pose.
Eigen::VectorXd pose_rows(const Model& m, Data& d, int frame, const BasePose& base, const Eigen::VectorXd& q,
                          const Vector3& x, const Matrix3& R_end) {
  forward_kinematics(m, d, base, q);
  const Pose ee = frame_pose(m, d, frame);
  Eigen::VectorXd r(12);
  r.head<3>() = ee.p - x;
  const Matrix3 D = ee.R - R_end;
  r.tail<9>() = Eigen::Map<const Eigen::VectorXd>(D.data(), 9);
  return r;
}

/// Gauss-Newton with a fixed damping and a step bound, Jacobian by central differences of
/// pose_rows; true when |r| < 1e-12.
bool test_pose_projection(const Model& m, Data& d, int frame, const BasePose& base, const Vector3& x,
                          const Matrix3& R_end, Eigen::VectorXd& q) {
  const int n = m.n();
  Eigen::MatrixXd J(12, n);
  for (int it = 0; it < 200; ++it) {
    const Eigen::VectorXd r = pose_rows(m, d, frame, base, q, x, R_end);
    if (r.norm() < 1e-12) return true;
    for (int k = 0; k < n; ++k) {
      const double h = 1e-7;
      Eigen::VectorXd qp = q, qm = q;
      qp(k) += h;
      qm(k) -= h;
      J.col(k) =
          (pose_rows(m, d, frame, base, qp, x, R_end) - pose_rows(m, d, frame, base, qm, x, R_end)) / (2 * h);
    }
    const double damping = r.norm() > 1e-6 ? 1e-6 : 0.0;
    const Eigen::MatrixXd A = J.transpose() * J + damping * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd step = A.ldlt().solve(J.transpose() * r);
    if (step.norm() > 0.3) step *= 0.3 / step.norm();
    q -= step;
  }
  return false;
}

/// Every revolute joint's angle wrapped into [-pi, pi) (one value per posture).
Eigen::VectorXd wrapped(const Eigen::VectorXd& q) {
  Eigen::VectorXd w = q;
  for (Eigen::Index k = 0; k < w.size(); ++k) w(k) = q(k) - 2 * M_PI * std::floor((q(k) + M_PI) / (2 * M_PI));
  return w;
}

double wrapped_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd e = wrapped(a) - wrapped(b);
  double d = 0;
  for (Eigen::Index k = 0; k < e.size(); ++k)
    d = std::max(d, std::min(std::abs(e(k)), 2 * M_PI - std::abs(e(k))));
  return d;
}

}  // namespace

TEST_CASE("Orientation residual: the rotation vector, its Jacobian equals central differences",
          "[branches]") {
  const Model m = model_from_urdf_file(ffsr::test::kRobots + "paper_7dof.urdf");
  CaptureProblem pb = ffsr::test::problem_7dof(m);
  CaptureTask task;
  task.kind = CaptureTask::Kind::Pose;
  Data d(m);
  BasePose b;
  b.position = Vector3(0.1, -0.2, 0.05);
  const Eigen::VectorXd q = ffsr::test::deg({10, 80, 70, -60, 100, 80, 20});
  crba(m, d, b, q);
  const Matrix3 Re = frame_pose(m, d, pb.frame).R;
  CaptureOptions o;
  o.duration = 157;
  o.step = 0.1;
  // angles from 1e-5 rad to 179 deg: R_end = Rot(angle, axis) Re, so log(R_end Re^T) = angle axis
  for (double angle_deg : {0.0, 1e-4, 0.5, 30.0, 90.0, 150.0, 170.0, 179.0}) {
    const Vector3 axis = Vector3(1, -2, 0.5).normalized();
    task.final_orientation = Matrix3(Eigen::AngleAxisd(angle_deg * M_PI / 180, axis)) * Re;
    const CaptureSetup s = prepare_capture(pb, task, o);
    Eigen::VectorXd r;
    capture_residual(m, d, pb, task, s, b, q, r, nullptr);
    CHECK((r.tail<3>() - angle_deg * M_PI / 180 * axis).norm() < 1e-12);  // the rotation vector itself
    INFO(angle_deg << " deg");
    ffsr::test::global_capture::check_residual_jacobian(m, pb, task, s, b, q);
  }
}

TEST_CASE("Orientation residual: a gripper turned half a turn is not on the manifold", "[branches]") {
  const Model m = model_from_urdf_file(ffsr::test::kRobots + "paper_7dof.urdf");
  CaptureProblem pb = ffsr::test::problem_7dof(m);
  Data d(m);
  BasePose b;
  const Eigen::VectorXd q = ffsr::test::deg({10, 80, 70, -60, 100, 80, 20});
  crba(m, d, b, q);
  const Pose ee = frame_pose(m, d, pb.frame);
  CaptureOptions o;
  o.duration = 157;
  o.step = 0.1;
  for (const Vector3& axis : {Vector3(1, 0, 0), Vector3(0, 0, 1), Vector3(Vector3(1, 1, -1).normalized())}) {
    CaptureTask task;
    task.kind = CaptureTask::Kind::Pose;
    task.final_orientation = Matrix3(Eigen::AngleAxisd(M_PI, axis)) * ee.R;
    const CaptureSetup s = prepare_capture(pb, task, o);
    Eigen::VectorXd r;
    capture_residual(m, d, pb, task, s, b, q, r, nullptr);
    // |log| = pi for a half turn (vee(skew(R)) would be 0 here): far from any tolerance
    CHECK(r.tail<3>().norm() == Approx(M_PI).epsilon(1e-9));
    // a wanted orientation that the arm holds already: residual 0
    task.final_orientation = ee.R;
    capture_residual(m, d, pb, task, prepare_capture(pb, task, o), b, q, r, nullptr);
    CHECK(r.tail<3>().norm() < 1e-12);
  }
}

TEST_CASE("Manifold search, paper 7-DOF pose task: every optimum in the final orientation", "[branches]") {
  const SearchInputs in(ffsr::test::kRobots + "paper_7dof_pose.toml");
  const ManifoldSearchResult res = in.search();
  const std::vector<CaptureBranch> br = in.branches(res, 0);
  REQUIRE(!br.empty());
  for (const CaptureBranch& b : br) {
    std::printf("paper 7-DOF pose branch: M_ie %.4f kg, orientation error %.2e deg\n", b.M_ie,
                b.orientation_error * 180 / M_PI);
    CHECK(b.orientation_error < 1e-8);  // the search's tolerance 1e-10 on |c|
    CHECK(b.position_error < 1e-8);
  }
  std::printf("paper 7-DOF pose: %zu local optima, best %.4f kg, %.3f s\n", br.size(), res.best.M_ie,
              res.seconds);
}

TEST_CASE("UR5 pose task: the branches equal an independent enumeration of the IK solutions", "[branches]") {
  if (!have_ur5()) return;
  const SearchInputs in(kData + "ur5_pose.toml");
  const Model& m = *in.sc.model;
  const ManifoldSearchResult res = in.search();
  const std::vector<CaptureBranch> br = in.branches(res, 8);
  REQUIRE(!br.empty());
  for (size_t i = 0; i < br.size(); ++i) {
    std::printf("UR5 pose branch %zu: M_ie %.4f kg, [", i, br[i].M_ie);
    for (Eigen::Index k = 0; k < br[i].theta.size(); ++k) std::printf(" %.2f", br[i].theta(k) * 180 / M_PI);
    std::printf(" ] deg, orientation error %.1e deg, reachable %d\n", br[i].orientation_error * 180 / M_PI,
                int(br[i].reachable_without_reconfiguration.value_or(false)));
    CHECK(br[i].orientation_error < 1e-9);
    CHECK(br[i].position_error < 1e-9);
    if (i > 0) CHECK(br[i - 1].objective <= br[i].objective);  // sorted
  }
  // without a null space the approach ends on one branch: the task-only run's
  int reachable = 0;
  for (const CaptureBranch& b : br) {
    REQUIRE(b.reachable_without_reconfiguration.has_value());
    reachable += *b.reachable_without_reconfiguration;
    if (*b.reachable_without_reconfiguration) CHECK(wrapped_distance(b.theta, in.plain_theta) < 1e-3);
  }
  CHECK(reachable == 1);

  // the enumeration of this test: 500 random configurations (fixed seed) within the limits
  Data d(m);
  std::mt19937_64 rng(20261124);
  std::vector<Eigen::VectorXd> mine;
  int converged = 0;
  for (int i = 0; i < 500; ++i) {
    Eigen::VectorXd q(m.n());
    for (int k = 0; k < m.n(); ++k) {
      const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
      q(k) = m.joint(k).lower + (m.joint(k).upper - m.joint(k).lower) * u;
    }
    const CaptureAtT& c = in.setup.capture;
    if (!test_pose_projection(m, d, in.sc.problem.frame, in.base, c.x_cap, c.R_end, q)) continue;
    ++converged;
    bool known = false;
    for (const Eigen::VectorXd& k : mine) known = known || wrapped_distance(k, q) < 1e-6;
    if (!known) mine.push_back(q);
  }
  INFO(converged << " of 500 converged, " << mine.size() << " distinct solutions, " << br.size()
                 << " branches");
  CHECK(converged >= 250);
  CHECK(mine.size() == br.size());
  for (const Eigen::VectorXd& q : mine) {  // each solution of this test is a reported branch ...
    double nearest = 1e9;
    for (const CaptureBranch& b : br) nearest = std::min(nearest, wrapped_distance(b.theta, q));
    CHECK(nearest < 1e-6);
    // ... and none has a lower M_ie than the best branch
    CHECK(integrated_effective_mass(m, d, in.base, q, in.sc.problem.frame, in.setup.capture.target) >=
          br.front().M_ie * (1 - 1e-9));
  }
  for (const CaptureBranch& b : br) {  // each branch is a solution of this test
    double nearest = 1e9;
    for (const Eigen::VectorXd& q : mine) nearest = std::min(nearest, wrapped_distance(b.theta, q));
    CHECK(nearest < 1e-6);
  }
  std::printf("UR5 pose: %zu branches, %d of 500 random starts converged, %zu distinct\n", br.size(),
              converged, mine.size());
}

TEST_CASE("UR5 pose task: the main job's JSON lists the branches", "[branches]") {
  if (!have_ur5()) return;
  const Scenario sc = load_scenario(kData + "ur5_pose.toml");
  const ScenarioResult r = run_scenario(sc, {});
  const nlohmann::json j = scenario_json(sc, r, "test");
  const nlohmann::json& g = j["global"];
  const nlohmann::json& br = g["branches"];
  REQUIRE(br.size() == 8);  // the UR5's inverse-kinematics solutions at this capture point
  auto config = [](const nlohmann::json& deg) {
    Eigen::VectorXd q(static_cast<Eigen::Index>(deg.size()));
    for (Eigen::Index k = 0; k < q.size(); ++k) q[k] = deg[static_cast<size_t>(k)].get<double>() * M_PI / 180;
    return q;
  };
  const Eigen::VectorXd reached = config(g["capture_configuration_deg"]);
  int reachable = -1, ends_on = -1;
  double nearest = 1e9;
  for (size_t i = 0; i < br.size(); ++i) {
    CHECK(br[i]["configuration_deg"].size() == 6);
    CHECK(br[i]["orientation_error_deg"].get<double>() < 1e-6);
    if (i > 0) CHECK(br[i - 1]["objective_value"].get<double>() <= br[i]["objective_value"].get<double>());
    if (br[i]["reachable_without_reconfiguration"].is_boolean() &&
        br[i]["reachable_without_reconfiguration"].get<bool>()) {
      CHECK(reachable == -1);  // one branch is reachable by the task-only run
      reachable = static_cast<int>(i);
    }
    const double dist = wrapped_distance(config(br[i]["configuration_deg"]), reached);
    if (dist < nearest) nearest = dist, ends_on = static_cast<int>(i);
  }
  REQUIRE(reachable >= 0);
  // the global run ends on a branch, with that branch's M_ie (the branches are evaluated at the base
  // pose the global run reaches) ...
  CHECK(nearest < 1e-4);
  CHECK(br[static_cast<size_t>(ends_on)]["integrated_effective_mass"].get<double>() ==
        Approx(g["integrated_effective_mass"].get<double>()).epsilon(1e-6));
  // ... the reachable one when it does not reconfigure, the best one when it does (a reconfiguration
  // is only chosen for a lower M_ie)
  if (g["reconfigured"].get<bool>()) {
    CHECK(ends_on == 0);
    CHECK(ends_on != reachable);
  } else {
    CHECK(ends_on == reachable);
  }
}

TEST_CASE("order_ties: tied optima in a fixed order, kept under rounding-level noise", "[branches]") {
  // groups of optima with one M_ie each (as the 7-DOF position task's: joints 1-6 shared up to SLSQP's
  // noise, the last joint free), the groups' values apart by more than the tie tolerance
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0), noise(-1.0, 1.0);
  std::vector<ManifoldPoint> points;
  const std::vector<double> masses{1.2764065182458, 1.2802743782277, 1.3448467139430, 2.4723316613};
  for (size_t g = 0; g < masses.size(); ++g) {
    Eigen::VectorXd shared(7);
    for (int k = 0; k < 6; ++k) shared(k) = u(rng);
    for (int i = 0; i < 12; ++i) {
      ManifoldPoint p;
      p.theta = shared;
      for (int k = 0; k < 6; ++k) p.theta(k) += 1e-7 * noise(rng);
      p.theta(6) = u(rng);
      p.M_ie = p.objective = masses[g] * (1 + 1e-11 * noise(rng));
      points.push_back(p);
    }
  }
  const auto by_objective = [](const ManifoldPoint& a, const ManifoldPoint& b) {
    return a.objective < b.objective;
  };
  std::shuffle(points.begin(), points.end(), rng);
  std::vector<ManifoldPoint> sorted = points;
  std::sort(sorted.begin(), sorted.end(), by_objective);  // as the search sorts them
  detail::order_ties(sorted);
  // the rule: groups by objective, within a group by the last joint (the first six are tied)
  for (size_t i = 1; i < sorted.size(); ++i) {
    const bool same_group = std::abs(sorted[i].objective / sorted[i - 1].objective - 1) < 1e-9;
    if (same_group)
      CHECK(sorted[i - 1].theta(6) < sorted[i].theta(6));
    else
      CHECK(sorted[i - 1].objective < sorted[i].objective);
  }
  // the same optima as another run's roundoff leaves them (SLSQP ends within ~1e-11 in M_ie and
  // ~1e-7 rad in the shared joints: redrawn), given in another order: the same order. Sorting by the
  // objective alone would follow the redrawn noise.
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<ManifoldPoint> perturbed = points;
    for (ManifoldPoint& p : perturbed) {
      p.objective *= 1 + 1e-11 * noise(rng);
      p.M_ie = p.objective;
      for (int k = 0; k < 6; ++k) p.theta(k) += 1e-7 * noise(rng);
    }
    std::shuffle(perturbed.begin(), perturbed.end(), rng);
    std::sort(perturbed.begin(), perturbed.end(), by_objective);
    detail::order_ties(perturbed);
    REQUIRE(perturbed.size() == sorted.size());
    for (size_t i = 0; i < sorted.size(); ++i)
      CHECK(std::abs(perturbed[i].theta(6) - sorted[i].theta(6)) < 1e-12);
  }
}

}  // namespace test_branches
