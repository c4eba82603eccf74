// Scenario keys of the shapes and the clearance (io/scenario_geometry.hpp): each bad input gives one
// line naming the key; the clearance scenario's global run keeps the clearance along its path.
#include "ffsr/io/scenario_run.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>

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

TEST_CASE("geometry scenario: the 3-DOF global run keeps 5 cm along its whole path") {
  const Scenario sc = load_scenario(kRobots + "paper_3dof_clearance.toml");
  REQUIRE(sc.geometry);
  const ScenarioResult r = run_scenario(sc);
  REQUIRE(r.global);
  REQUIRE(r.clearances.size() == 3);
  const ClearanceReport& g = r.clearances[2].second;
  CHECK(r.clearances[2].first == "global");
  CHECK(g.overall.distance >= 0.05 - 1e-6);
  CHECK(g.arm_target.distance >= 0.05 - 1e-6);
  CHECK(g.arm_bus.distance >= 0.05 - 1e-6);
  CHECK(g.self.distance >= 0.05 - 1e-6);
  // the same path re-checked independently of the run's own report: the capture configuration
  const nlohmann::json j = scenario_json(sc, r, "test");
  CHECK(j["global"]["min_clearance"]["distance"].get<double>() == Approx(g.overall.distance));
}

std::string samples_dir() {
  if (const char* env = std::getenv("FFSR_URDF_SAMPLES")) return env;
  return std::string(FFSR_SOURCE_DIR) + "/../shared/urdf-samples";
}

/// A reference arm's clearance scenario: its global run keeps the clearance along the whole path, by
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
  const ClearanceReport& g = r.clearances[2].second;
  INFO(file << ": global " << g.overall.distance << " m (" << g.overall.pair << ", t = " << g.overall.time << " s)");
  CHECK(g.arm_target.distance >= 0.05 - 1e-6);
  CHECK(g.arm_bus.distance >= 0.05 - 1e-6);
  CHECK(g.self.distance >= 0.05 - 1e-6);
  override_scenario_key(k, "clearance", "0");
  const Scenario free_sc = build_scenario(k);
  const ScenarioResult f = run_scenario(free_sc);
  REQUIRE(f.global);
  INFO("without the clearance: " << f.clearances[2].second.overall.distance << " m, M_ie " << f.global->result.run.M_ie
                                 << " kg; with it " << r.global->result.run.M_ie << " kg");
  CHECK(f.clearances[2].second.overall.distance < 0.05);
}

TEST_CASE("geometry scenario: Panda and UR5 with capsule links, the global run keeps 5 cm") {
  if (!std::filesystem::exists(samples_dir() + "/panda.urdf")) {
    WARN("skipped Panda and UR5: the URDF samples are not in " << samples_dir());
    return;
  }
  check_arm_clearance("panda_clearance.toml");
  check_arm_clearance("ur5_clearance.toml");
}

}  // namespace test_geometry_scenario
