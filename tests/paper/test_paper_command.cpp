// The paper's tables and figures through the ffsr-optimize command: inspect and contact at a row of
// Table 3, the 7-DOF end-effector, the main job on the 3-DOF scenario against Table 4 (the built-in
// default and robots/paper_3dof.toml), and the map over the ranges of Figure 8.
#include "support/command.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace test_paper_command {

namespace fs = std::filesystem;
using namespace ffsr::test;
using nlohmann::json;

namespace {

/// The main job on the 3-DOF scenario against Table 4: both runs reach the capture point, the plain
/// run near the paper's configuration, the optimized one with M_ie and F_max lowered.
void check_table4(const json& j) {
  check_result_keys(j);
  const auto& base = j.at("baseline");
  const auto& opt = j.at("optimized");
  CHECK(base.at("tracking_error").get<double>() < 1e-3);
  CHECK(opt.at("tracking_error").get<double>() < 1e-3);
  const auto theta = numbers(base.at("capture_configuration_deg"));
  const std::vector<double> paper{-2.29, 91.75, -79.77};
  REQUIRE(theta.size() == 3);
  for (size_t i = 0; i < 3; ++i) {
    INFO("joint " << i + 1 << ": " << theta[i] << " deg, paper " << paper[i]);
    CHECK(std::abs(theta[i] - paper[i]) <= 10.0);
  }
  const double M_base = base.at("integrated_effective_mass").get<double>();
  const double M_opt = opt.at("integrated_effective_mass").get<double>();
  CHECK(M_base >= 5.0);
  CHECK(M_base <= 6.0);
  CHECK(M_opt <= 1.4);
  CHECK(j.at("force_reduction_percent").get<double>() >= 50.0);
  CHECK(j.at("mass_reduction_percent").get<double>() ==
        Approx(100.0 * (M_base - M_opt) / M_base).epsilon(1e-9));
  const double F_base = base.at("f_max_closed_form").get<double>(),
               F_opt = opt.at("f_max_closed_form").get<double>();
  CHECK(j.at("force_reduction_percent").get<double>() ==
        Approx(100.0 * (F_base - F_opt) / F_base).epsilon(1e-9));
}

void check_series_csv(const std::string& path, size_t n_joints) {
  const Csv c = read_csv(path);
  REQUIRE(c.column("run") == 0);
  for (const char* col : {"t", "M_ie", "F_max_estimate", "ee_x", "ee_y", "ee_z", "base_x", "base_qw"}) {
    INFO(col);
    CHECK(c.column(col) >= 0);
  }
  // run, t, joints, base, ee, M_ie, F_max, target pose, a pose per moving body (one per joint here), phase
  CHECK(c.header.size() == 2 + n_joints + 7 + 3 + 2 + 7 + 7 * n_joints + 1);
  for (const std::string& col : std::vector<std::string>{"target_x", "target_qz", "body1_x",
                                                          "body" + std::to_string(n_joints) + "_qz"}) {
    INFO(col);
    CHECK(c.column(col) >= 0);
  }
  REQUIRE(c.column("phase") == static_cast<int>(c.header.size()) - 1);
  size_t baseline = 0, optimized = 0, global = 0;
  for (const auto& row : c.rows) {
    REQUIRE(row.size() == c.header.size());
    // the paper's scenarios need no reconfiguration: every row is the approach
    CHECK(row.back() == "approach");
    if (row[0] == "baseline") ++baseline;
    if (row[0] == "optimized") ++optimized;
    if (row[0] == "global") ++global;
  }
  CHECK(baseline > 10);
  CHECK(optimized > 10);
  CHECK(global > 10);  // the global run (on by default) has its series too
  CHECK(baseline + optimized + global == c.rows.size());
}

}  // namespace

TEST_CASE("inspect --json on the 3-DOF robot at [0, 90, -90] deg (Table 3, row 5)", "[cli][paper]") {
  const auto j = parse_json(cli({"inspect", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--json"}));
  for (const char* key :
       {"H", "J_f", "end_effector_position", "effective_mass", "integrated_effective_mass", "joint_names"})
    CHECK(j.contains(key));

  // H: (6 + 3) x (6 + 3), symmetric
  const auto& H = j.at("H");
  REQUIRE(H.size() == 9);
  for (size_t r = 0; r < 9; ++r) {
    REQUIRE(H[r].size() == 9);
    for (size_t c = 0; c < 9; ++c) {
      INFO("H(" << r << ", " << c << ")");
      CHECK(H[r][c].get<double>() == Approx(H[c][r].get<double>()).margin(1e-9));
    }
  }
  // J_f: 6 rows of n = 3
  const auto& Jf = j.at("J_f");
  REQUIRE(Jf.size() == 6);
  for (const auto& row : Jf) CHECK(row.size() == 3);

  // End-effector by hand: the base at the origin, joint 1 at a = 0.6 along x; link 1 (b = 1.4) at
  // 0 deg along x, link 2 (c = 1.6) at 0 + 90 = 90 deg along y, link 3 (d = 0.5) at 90 - 90 = 0 deg
  // along x: p_e = (a + b + d, c, 0) = (2.5, 1.6, 0).
  const double a = 0.6, b = 1.4, c = 1.6, d = 0.5;
  const auto p = numbers(j.at("end_effector_position"));
  REQUIRE(p.size() == 3);
  CHECK(p[0] == Approx(a + b + d).margin(1e-9));
  CHECK(p[1] == Approx(c).margin(1e-9));
  CHECK(p[2] == Approx(0.0).margin(1e-9));

  // Table 3: M_ie = 5.817 kg at [0, 90, -90] deg, within 0.1 %
  const double M_ie = j.at("integrated_effective_mass").get<double>();
  CHECK(M_ie == Approx(5.817).epsilon(1e-3));
  // m_e is the robot side alone, so it exceeds M_ie = 1 / (1/m_e + 1/m_t,eff) and is finite
  const double m_e = j.at("effective_mass").get<double>();
  CHECK(std::isfinite(m_e));
  CHECK(m_e > M_ie);
  CHECK(j.at("joint_names") == json({"joint1", "joint2", "joint3"}));
}

TEST_CASE("inspect: the 7-DOF robot's end-effector at [0, 90, 90, -90, 90, 90, 0] deg", "[cli][paper]") {
  const auto j =
      parse_json(cli({"inspect", "--urdf", kUrdf7, "--joints-deg", "0,90,90,-90,90,90,0", "--json"}));
  const auto p = numbers(j.at("end_effector_position"));
  REQUIRE(p.size() == 3);
  CHECK(p[0] == Approx(1.8).margin(0.05));
  CHECK(p[1] == Approx(-0.6).margin(0.05));
  CHECK(p[2] == Approx(1.8).margin(0.05));
  CHECK(j.at("H").size() == 13);
  CHECK(j.at("J_f").size() == 6);
  CHECK(j.at("J_f")[0].size() == 7);
  CHECK(j.at("joint_names").size() == 7);
}

TEST_CASE("contact --json at [0, 90, -90] deg reproduces Table 3, row 5", "[cli][paper]") {
  const auto j = parse_json(cli({"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--json"}));
  for (const char* key : {"integrated_effective_mass", "approach_velocity", "f_max_closed_form",
                          "f_max_exact", "f_max_multibody", "model_accuracy"})
    CHECK(j.contains(key));
  CHECK(j.at("integrated_effective_mass").get<double>() == Approx(5.817).epsilon(1e-3));
  // 0.2 m/s along the normal plus the target's 2 deg/s spin at r_tp = (-0.25, 0.15, 0)
  CHECK(j.at("approach_velocity").get<double>() == Approx(0.2 + 0.15 * 2.0 * M_PI / 180.0).epsilon(1e-6));
  CHECK(j.at("approach_velocity").get<double>() == Approx(0.2052).epsilon(1e-3));
  CHECK(j.at("f_max_closed_form").get<double>() == Approx(1840.0).epsilon(3e-3));  // Proposed Method
  CHECK(j.at("f_max_multibody").get<double>() == Approx(1861.0).epsilon(0.025));   // Numerical Integration
  const double exact = j.at("f_max_exact").get<double>();
  CHECK(exact == Approx(j.at("f_max_multibody").get<double>()).epsilon(5e-3));
  CHECK(exact > j.at("f_max_closed_form").get<double>());
  const double acc = j.at("model_accuracy").get<double>();
  CHECK(acc > 98.5);
  CHECK(acc < 99.5);
}

TEST_CASE("the built-in default scenario (no arguments) reproduces Table 4", "[cli][paper]") {
  TempDir tmp;  // an empty working directory: the default must not read robots/ from it
  const auto r = cli({"--json", "out.json", "--csv", "out.csv", "--quiet"}, tmp.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(r.out.find("Without optimization") != std::string::npos);
  CHECK(r.out.find("With optimization") != std::string::npos);
  CHECK(tmp.entries() == std::vector<std::string>{"out.csv", "out.json"});
  const json j = read_json_file(tmp / "out.json");
  check_table4(j);
  CHECK(j.at("version").get<std::string>() == project_version());
  check_series_csv(tmp / "out.csv", 3);
}

TEST_CASE("run: --config robots/paper_3dof.toml from another directory finds its URDF", "[cli][paper]") {
  TempDir tmp;
  const auto r =
      cli({"--config", kScenario3, "--json", "out.json", "--csv", "out.csv", "--quiet"}, tmp.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json j = read_json_file(tmp / "out.json");
  check_table4(j);
  // the URDF was resolved next to the scenario file, not in the working directory
  CHECK(fs::equivalent(j.at("scenario").at("urdf").get<std::string>(), kUrdf3));
  check_series_csv(tmp / "out.csv", 3);

  {  // the scenario and the built-in default give the same result
    const auto d = cli({"--json", "default.json", "--quiet"}, tmp.str());
    REQUIRE(d.exit_code == 0);
    const json jd = read_json_file(tmp / "default.json");
    CHECK(jd.at("baseline").at("integrated_effective_mass").get<double>() ==
          Approx(j.at("baseline").at("integrated_effective_mass").get<double>()).epsilon(1e-12));
    CHECK(jd.at("optimized").at("integrated_effective_mass").get<double>() ==
          Approx(j.at("optimized").at("integrated_effective_mass").get<double>()).epsilon(1e-12));
  }
  {  // a relative --config path is resolved against the working directory, the URDF against the file
    const auto rel = cli({"--config", "robots/paper_3dof.toml", "--quiet"}, kSource);
    INFO(rel.err);
    CHECK(rel.exit_code == 0);
  }
}

TEST_CASE("map: over the paper's ranges (Figure 8) the maximum is the stretched arm alone", "[map][cli][paper]") {
  TempDir dir;
  const CommandResult r =
      cli_sub("map", {"--urdf", kUrdf3, "--joints-deg", "0,0,0", "--vary", "1,2,3", "--range-deg",
               "-90,90,-120,120,-120,120", "--step-deg", "6", "--csv", "m.csv"},
              dir.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const NumericCsv csv = parse_numeric_csv(read_existing_file(dir.str() + "/m.csv"));
  REQUIRE(csv.rows.size() == 30u * 40u * 40u);
  size_t best = 0;
  for (size_t k = 1; k < csv.rows.size(); ++k)
    if (csv.rows[k][3] > csv.rows[best][3]) best = k;
  CHECK(csv.rows[best][0] == 0.0);
  CHECK(csv.rows[best][1] == 0.0);
  CHECK(csv.rows[best][2] == 0.0);
  size_t near_max = 0;  // other points within 1e-6 of the maximum
  for (size_t k = 0; k < csv.rows.size(); ++k)
    near_max += k != best && csv.rows[k][3] >= csv.rows[best][3] * (1 - 1e-6);
  CHECK(near_max == 0u);
  CHECK_THAT(r.out,
             Catch::Matchers::Contains("max M_ie = ") && Catch::Matchers::Contains("at [0, 0, 0] deg"));
}

}  // namespace test_paper_command
