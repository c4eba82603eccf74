// Scenario keys of the shapes and the clearance (scenario/geometry.hpp): each bad input gives one
// line naming the key; every run of the clearance scenarios (plain, paper's method through the clearance
// barrier, global) keeps the clearance along its path; the barrier's free-floating distance rate
// against central differences.
#include "ffsr/jobs/scenario_run.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <random>

namespace test_geometry_scenario {

using namespace ffsr;

const std::string kRobots = std::string(FFSR_SOURCE_DIR) + "/robots/";

std::string error_of(const std::string& file, const std::string& key, const std::string& value) {
  try {
    ScenarioKeys k = read_scenario_file(kRobots + file);
    override_scenario_key(k, key, value);
    build_scenario(k);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST_CASE("geometry scenario: bad shapes, radii, clearances and contact points name the key") {
  const std::string f = "paper_3dof_clearance.toml";
  CHECK(error_of(f, "target-shape", "cone") == "--target-shape: unknown shape 'cone' (box, sphere or cylinder)");
  CHECK(error_of(f, "target-size", "0.5,-0.5,0.5") == "--target-size: box sizes must be positive and finite, got -0.5");
  CHECK(error_of(f, "target-size", "nan,0.5,0.5") == "--target-size: box sizes must be positive and finite, got nan");
  CHECK(error_of(f, "link-radius", "-0.5") == "--link-radius: must be positive and finite, got -0.5");
  CHECK(error_of(f, "link-radius", "nan") == "--link-radius: must be positive and finite, got nan");
  CHECK(error_of(f, "clearance", "-1") == "--clearance: must be >= 0 and finite, got -1");
  CHECK(error_of(f, "contact-exemption", "-1") == "--contact-exemption: must be >= 0 and finite, got -1");
  // r_tp = (-0.35, 0.15, 0): 0.1 m outside the cube's -x face (closed form)
  CHECK(error_of(f, "contact-offset", "-0.35,0.15,0") ==
        "--contact-offset: the contact point is 0.1 m outside the target-shape's surface (it must lie on it)");
  // at the start [0, 150, -100] deg link 2 passes 0.130 m from the bus (its capsule: 0.05 m radius)
  const std::string start = error_of(f, "clearance", "0.2");
  CHECK(start.rfind("--clearance: the start configuration is already closer than 0.2 m: link2 - base (arm-bus) 0.13", 0) == 0);
}

TEST_CASE("geometry scenario: without the keys a scenario has no geometry and its numbers do not change") {
  const Scenario plain = load_scenario(kRobots + "paper_3dof.toml");
  CHECK(!plain.geometry);
  CHECK(!plain.capture.record_series);
}

/// Every run of a scenario's main job (plain, paper's method, global) keeps the clearance along its
/// whole path, by every kind of pair.
void check_every_run(const ScenarioResult& r, double clearance) {
  REQUIRE(r.clearances.size() == 3);
  const char* names[] = {"baseline", "optimized", "global"};
  for (size_t i = 0; i < 3; ++i) {
    const ClearanceReport& c = r.clearances[i].second;
    CHECK(r.clearances[i].first == names[i]);
    INFO(names[i] << ": " << c.overall.distance << " m (" << c.overall.pair << ", t = " << c.overall.time << " s)");
    CHECK(c.arm_target.distance >= clearance - 1e-6);
    CHECK(c.arm_bus.distance >= clearance - 1e-6);
    CHECK(c.self.distance >= clearance - 1e-6);
  }
}

/// The paper's method without the clearance barrier (the capture run as the scenario gives it): its
/// smallest distance along the path.
double paper_method_without_barrier(const Scenario& sc) {
  CaptureOptions opt = sc.capture;
  opt.record_series = true;
  REQUIRE(!opt.rate_guard);
  return run_clearance(sc, plan_capture(sc.problem, sc.task, opt)).overall.distance;
}

TEST_CASE("geometry scenario: every run of the paper robots' clearance scenarios keeps 5 cm along its path") {
  for (const char* file : {"paper_3dof_clearance.toml", "paper_7dof_position_clearance.toml"}) {
    INFO(file);
    const Scenario sc = load_scenario(kRobots + file);
    REQUIRE(sc.geometry);
    const ScenarioResult r = run_scenario(sc);
    REQUIRE(r.global);
    check_every_run(r, 0.05);
    // the JSON reports the same smallest distance
    const nlohmann::json j = scenario_json(sc, r, "test");
    CHECK(j["global"]["min_clearance"]["distance"].get<double>() == Approx(r.clearances[2].second.overall.distance));
    // without the clearance barrier the paper's method goes closer (through the target on the 3-DOF
    // robot, into the bus on the 7-DOF): the barrier was needed
    CHECK(paper_method_without_barrier(sc) < 0.0);
  }
}

TEST_CASE("geometry scenario: the free-floating distance rate equals central differences along a zero-momentum motion") {
  const Scenario sc = load_scenario(kRobots + "paper_7dof_position_clearance.toml");
  REQUIRE(sc.geometry);
  const Model& m = *sc.model;
  const CollisionChecker& cc = *sc.geometry->checker;
  Target target0 = sc.problem.target;
  target0.velocity = Vector3(0.02, -0.01, 0.03);  // a drifting, tumbling target
  Data d(m), dh(m);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  const double t = 10.0, h = 1e-5;
  const Target tt = propagate_target(target0, t), tp = propagate_target(target0, t + h),
               tm = propagate_target(target0, t - h);
  int checked = 0, arm_target = 0;
  Eigen::VectorXd g(m.n());
  for (int s = 0; s < 40; ++s) {
    Eigen::VectorXd th(m.n()), thd(m.n());
    for (int k = 0; k < m.n(); ++k) th(k) = M_PI * U(rng), thd(k) = 0.1 * U(rng);
    BasePose base;
    base.position = Vector3(U(rng), U(rng), U(rng)) * 0.2;
    base.orientation = Quaternion(Eigen::AngleAxisd(0.3 * U(rng), Vector3(U(rng), U(rng), 1).normalized()));
    crba(m, d, base, th);
    const Vector6 xb = base_velocity_from_momentum(m, d, thd);  // [v_0; w_0]
    const Eigen::LLT<Matrix6> hb(d.H.topLeftCorner<6, 6>());
    auto moved = [&](double sign) {
      BasePose b;
      b.position = base.position + sign * h * xb.head<3>();
      b.orientation = Quaternion(Eigen::AngleAxisd(h * xb.tail<3>().norm(), xb.tail<3>().normalized()));
      if (sign < 0) b.orientation = b.orientation.inverse();
      b.orientation = b.orientation * base.orientation;
      forward_kinematics(m, dh, b, th + sign * h * thd);
    };
    for (size_t i = 0; i < cc.pairs().size(); ++i) {
      const PairDistance pd = cc.pair_distance(d, target_pose(tt), static_cast<int>(i));
      if (pd.distance < 1e-3) continue;
      const double b = free_floating_distance_rate(m, d, cc, pd, tt, hb, g);
      moved(+1);
      const double fp = cc.pair_distance(dh, target_pose(tp), static_cast<int>(i)).distance;
      moved(-1);
      const double fm = cc.pair_distance(dh, target_pose(tm), static_cast<int>(i)).distance;
      INFO(cc.pair_name(static_cast<int>(i)) << " sample " << s);
      CHECK(std::abs(g.dot(thd) + b - (fp - fm) / (2 * h)) < 1e-7);
      ++checked;
      if (cc.pairs()[i].kind == PairKind::ArmTarget) ++arm_target;
    }
  }
  CHECK(checked > 300);
  CHECK(arm_target > 100);
}

std::string samples_dir() {
  if (const char* env = std::getenv("FFSR_URDF_SAMPLES")) return env;
  return std::string(FFSR_SOURCE_DIR) + "/../shared/urdf-samples";
}

/// A reference arm's clearance scenario: every run keeps the clearance along the whole path, by
/// every kind of pair; without the clearance the global run comes closer (the bound was needed).
void check_arm_clearance(const std::string& file) {
  const std::string path = std::string(FFSR_SOURCE_DIR) + "/tests/data/" + file;
  ScenarioKeys k = read_scenario_file(path);
  if (std::getenv("FFSR_URDF_SAMPLES")) override_scenario_key(k, "urdf", samples_dir() + "/" +
                                                               std::filesystem::path(k.urdf).filename().string());
  const Scenario sc = build_scenario(k);
  REQUIRE(sc.geometry);
  const ScenarioResult r = run_scenario(sc);
  REQUIRE(r.global);
  REQUIRE(r.clearances.size() == 3);
  INFO(file);
  check_every_run(r, 0.05);
  override_scenario_key(k, "clearance", "0");
  const Scenario free_sc = build_scenario(k);
  const ScenarioResult f = run_scenario(free_sc);
  REQUIRE(f.global);
  INFO("without the clearance: " << f.clearances[2].second.overall.distance << " m, M_ie " << f.global->result.run.M_ie
                                 << " kg; with it " << r.global->result.run.M_ie << " kg");
  CHECK(f.clearances[2].second.overall.distance < 0.05);
}

TEST_CASE("geometry scenario: Panda and UR5 with capsule links, every run keeps 5 cm") {
  if (!std::filesystem::exists(samples_dir() + "/panda.urdf")) {
    WARN("skipped Panda and UR5: the URDF samples are not in " << samples_dir());
    return;
  }
  check_arm_clearance("panda_clearance.toml");
  check_arm_clearance("ur5_clearance.toml");
}

}  // namespace test_geometry_scenario
