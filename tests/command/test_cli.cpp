// End-to-end tests of the ffsr-optimize command: inspect, contact and the main job (a capture
// scenario), their JSON/CSV outputs against the paper (Tables 3 and 4), and a catalogue of bad
// inputs, each of which must give exit code 2 (3 for a capture point out of reach) and one error
// line on stderr naming the offending input, print no result and leave no output file behind.
#include "support/command.hpp"

#include "ffsr/contact/contact_law.hpp"
#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

// The command is run without a shell (tests/support/run_command.hpp), from a fresh temporary
// directory, with absolute paths to the repository's files, so nothing depends on the working
// directory of the test runner.

namespace test_cli {

namespace fs = std::filesystem;
using namespace ffsr::test;
using nlohmann::json;

namespace {

const std::string kBadScenarios = kSource + "/tests/data/bad_scenarios";
const std::string kBadUrdfs = kSource + "/tests/data/bad_urdf";

std::string describe(const Args& args) {
  std::string s = "ffsr-optimize";
  for (const auto& a : args) s += " " + a;
  return s;
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// 1. inspect
// ------------------------------------------------------------------------------------------------

TEST_CASE("inspect: negative angles work as --joints-deg=... and as --joints-deg ...", "[cli]") {
  const auto eq = parse_json(cli({"inspect", "--urdf", kUrdf3, "--joints-deg=-2.29,91.75,-79.77", "--json"}));
  const auto sp =
      parse_json(cli({"inspect", "--urdf", kUrdf3, "--joints-deg", "-2.29,91.75,-79.77", "--json"}));
  const auto deg_eq = numbers(eq.at("joints_deg"));
  const auto deg_sp = numbers(sp.at("joints_deg"));
  REQUIRE(deg_eq.size() == 3);
  CHECK(deg_eq[0] == Approx(-2.29));
  CHECK(deg_eq[1] == Approx(91.75));
  CHECK(deg_eq[2] == Approx(-79.77));
  CHECK(deg_eq == deg_sp);
  CHECK(eq.at("integrated_effective_mass").get<double>() == sp.at("integrated_effective_mass").get<double>());
  CHECK(eq.at("end_effector_position") == sp.at("end_effector_position"));
  // Table 4, plain run: the paper's capture configuration has M_ie = 5.43 kg
  CHECK(eq.at("integrated_effective_mass").get<double>() == Approx(5.43).epsilon(0.01));
}

TEST_CASE("inspect without --json prints a readable summary", "[cli]") {
  const auto r = cli({"inspect", "--urdf", kUrdf3, "--joints-deg", "0,90,-90"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(r.out.find("M_ie") != std::string::npos);
  CHECK(r.out.find("5.81") != std::string::npos);
}

TEST_CASE("inspect, contact and map evaluate a scenario's start state (--config), flags override it",
          "[cli]") {
  // robots/paper_7dof_position.toml's robot at its start state and its target, evaluated here through
  // the library from the values the file states (an independent path: no scenario reader)
  const std::string file = kSource + "/robots/paper_7dof_position.toml";
  const ffsr::Model m = ffsr::model_from_urdf_file(kUrdf7);
  ffsr::Data d(m);
  ffsr::Target target;  // mass 200, inertia 100 I, upright, normal x: the defaults; the offset is the file's
  target.contact_offset = ffsr::Vector3(-0.25, 0.15, 0.1);
  Eigen::VectorXd q(7);
  q << 0, 90, 90, -90, 90, 90, 0;
  q *= M_PI / 180;
  const double M_start = ffsr::integrated_effective_mass(m, d, ffsr::BasePose{}, q, m.end_effector(), target);
  q(5) = 80 * M_PI / 180;  // joint 7 turns about the contact normal through the hand: M_ie would not move
  const double M_moved = ffsr::integrated_effective_mass(m, d, ffsr::BasePose{}, q, m.end_effector(), target);
  REQUIRE(std::abs(M_moved - M_start) > 1e-3 * M_start);

  const auto i = cli({"inspect", "--config", file, "--json"});
  INFO(i.err);
  REQUIRE(i.exit_code == 0);
  CHECK(nlohmann::json::parse(i.out).at("integrated_effective_mass").get<double>() ==
        Approx(M_start).epsilon(1e-12));
  const auto o = cli({"inspect", "--config", file, "--joints-deg", "0,90,90,-90,90,80,0", "--json"});
  REQUIRE(o.exit_code == 0);
  CHECK(nlohmann::json::parse(o.out).at("integrated_effective_mass").get<double>() ==
        Approx(M_moved).epsilon(1e-12));
  const auto c = cli({"contact", "--config", file, "--json"});
  INFO(c.err);
  REQUIRE(c.exit_code == 0);
  const auto cj = nlohmann::json::parse(c.out);
  CHECK(cj.at("integrated_effective_mass").get<double>() == Approx(M_start).epsilon(1e-12));
  CHECK(cj.at("parameters").at("urdf").get<std::string>() == kSource + "/robots/paper_7dof.urdf");
  // one grid point of map at the start angle of joint 7
  const auto g = cli({"map", "--config", file, "--vary", "7", "--range-deg", "0,1", "--step-deg", "1",
                      "--csv", "-", "--quiet"});
  INFO(g.err);
  REQUIRE(g.exit_code == 0);
  const std::string row = g.out.substr(g.out.find('\n') + 1);
  CHECK(std::stod(row.substr(row.find(',') + 1)) == Approx(M_start).epsilon(1e-12));
  // no arguments: the built-in scenario's start state, the paper's 3-DOF robot at [0, 150, -100] deg
  const auto b = cli({"inspect", "--json"});
  REQUIRE(b.exit_code == 0);
  const auto bj = nlohmann::json::parse(b.out);
  const auto joints = bj.at("joints_deg").get<std::vector<double>>();
  REQUIRE(joints.size() == 3);
  CHECK(joints[0] == Approx(0).margin(1e-12));
  CHECK(joints[1] == Approx(150));
  CHECK(joints[2] == Approx(-100));
  const ffsr::Model m3 = ffsr::model_from_urdf_file(kUrdf3);
  ffsr::Data d3(m3);
  ffsr::Target paper;
  Eigen::VectorXd q3(3);
  q3 << 0, 150, -100;
  q3 *= M_PI / 180;
  CHECK(bj.at("integrated_effective_mass").get<double>() ==
        Approx(ffsr::integrated_effective_mass(m3, d3, ffsr::BasePose{}, q3, m3.end_effector(), paper))
            .epsilon(1e-12));
}

TEST_CASE("xi holds a scenario's contact law fixed (--config), flags override it", "[cli]") {
  // robots/paper_7dof_position_cr03.toml: c_r = 0.3. The first row of the stiffness study (K = 1e7,
  // the first law) against the library's relative error at the file's c_r and approach speed
  const std::string file = kSource + "/robots/paper_7dof_position_cr03.toml";
  auto first_row = [](const CommandResult& r) {
    REQUIRE(r.exit_code == 0);
    std::stringstream ss(r.out);
    std::string header, row;
    std::getline(ss, header);
    std::getline(ss, row);
    std::vector<std::string> f;
    ss = std::stringstream(row);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    REQUIRE(f.size() == 4);
    CHECK(f[0] == "stiffness");
    CHECK(std::stod(f[1]) == Approx(1e7));
    return std::make_pair(f[2], std::stod(f[3]));
  };
  for (const auto& [args, c_r, v] :
       {std::make_tuple(std::vector<std::string>{"xi", "--config", file, "--points", "2"}, 0.3, 0.2),
        std::make_tuple(
            std::vector<std::string>{"xi", "--config", file, "--points", "2", "--restitution", "0.6"}, 0.6,
            0.2)}) {
    const auto [law, xi] = first_row(cli(args));
    const double expected =
        ffsr::relative_error(ffsr::make_contact_law(law, ffsr::ContactParams{1e7, 1.5, c_r}, v));
    CHECK(xi == Approx(expected).epsilon(1e-9));
  }
  const auto plain = first_row(cli({"xi", "--points", "2"}));  // the built-in scenario: c_r = 0.9
  CHECK(plain.second == Approx(ffsr::relative_error(ffsr::make_contact_law(
                                   plain.first, ffsr::ContactParams{1e7, 1.5, 0.9}, 0.2)))
                            .epsilon(1e-9));
}

TEST_CASE("inspect: the distances of a configuration with shapes, against a closed form", "[cli]") {
  // robots/paper_3dof_clearance.toml: the target a 0.5 m cube (upright, centred on its centre of mass),
  // the links capsules of radius 0.05 m between their joint origins. link2 is the nearest link; its
  // distance to the cube is the least over the segment of the point-box distance, minus the radius
  // (convex along the segment: a ternary search finds it)
  const std::string file = kSource + "/robots/paper_3dof_clearance.toml";
  const ffsr::Model m = ffsr::model_from_urdf_file(kUrdf3);
  ffsr::Data d(m);
  Eigen::VectorXd q(3);
  q << 10, 120, -80;
  ffsr::forward_kinematics(m, d, ffsr::BasePose{}, q * (M_PI / 180));
  const ffsr::Vector3 a = d.p[2], b = d.p[3];  // joint2 and joint3 origins: link2's segment
  for (double x : {2.75, 3.25, 3.75}) {
    const ffsr::Vector3 centre(x, 1.45, 0);
    auto box_distance = [&](double t) {
      const ffsr::Vector3 p = a + t * (b - a) - centre;
      return (p.cwiseAbs() - ffsr::Vector3::Constant(0.25)).cwiseMax(0.0).norm();
    };
    double lo = 0, hi = 1;
    for (int i = 0; i < 200; ++i) {
      const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
      if (box_distance(m1) < box_distance(m2))
        hi = m2;
      else
        lo = m1;
    }
    const double expected = box_distance(0.5 * (lo + hi)) - 0.05;
    const auto r = cli({"inspect", "--config", file, "--joints-deg", "10,120,-80", "--target-position",
                        std::to_string(x) + ",1.45,0", "--json"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const auto c = nlohmann::json::parse(r.out).at("clearance").at("arm_target");
    CHECK(c.at("pair").get<std::string>() == "link2 - target");
    CHECK(c.at("distance").get<double>() == Approx(expected).margin(1e-9));
  }
  // without shapes: no distances
  const auto plain = cli({"inspect", "--json"});
  REQUIRE(plain.exit_code == 0);
  CHECK(nlohmann::json::parse(plain.out).at("clearance").is_null());
}

// ------------------------------------------------------------------------------------------------
// 2. contact
// ------------------------------------------------------------------------------------------------

TEST_CASE("the main job names a plain or paper's-method run that the clearance barrier could not keep",
          "[cli]") {
  // robots/paper_7dof_position_clearance.toml with 9 cm: the plain run tracks the pose (one null-space
  // direction) and its last link passes closer to the target; the paper's method (position task, four
  // directions) keeps 9 cm. The distances come from the JSON, the line from the table.
  const std::string file = kSource + "/robots/paper_7dof_position_clearance.toml";
  const auto j =
      cli({"--config", file, "--clearance", "0.09", "--global", "false", "--quiet", "--json", "-"});
  INFO(j.err);
  REQUIRE(j.exit_code == 0);
  const auto res = nlohmann::json::parse(j.out);
  const double plain = res.at("baseline").at("min_clearance").at("distance").get<double>();
  CHECK(plain < 0.09);
  CHECK(res.at("optimized").at("min_clearance").at("distance").get<double>() >= 0.09 - 1e-6);
  const auto t = cli({"--config", file, "--clearance", "0.09", "--global", "false"});
  REQUIRE(t.exit_code == 0);
  const std::string line =
      "clearance: the plain run comes closer than the clearance (the clearance barrier could "
      "not keep it with the freedom its task leaves): " +
      res.at("baseline").at("min_clearance").at("pair").get<std::string>() + " ";
  CHECK(t.out.find(line) != std::string::npos);
  CHECK(t.out.find("clearance: the optimized run") == std::string::npos);
}

TEST_CASE("the main job reports a plain and a paper's-method row that fail and goes on to the global row",
          "[cli]") {
  // robots/paper_7dof_grasp.toml: a grasp orientation 134 deg from the initial one; the straight line
  // alone loses it, the global run reconfigures first. Exit 0, the failed rows' errors in the JSON,
  // table and no CSV rows for them; the global row's series has both phases.
  TempDir tmp;
  const auto r = cli({"--config", kSource + "/robots/paper_7dof_grasp.toml", "--quiet", "--json", "out.json",
                      "--csv", "out.csv"},
                     tmp.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json j = read_json_file(tmp.str() + "/out.json");
  const std::string plain_error = j.at("baseline").at("error").get<std::string>();
  CHECK(plain_error.rfind("plain run: ", 0) == 0);
  CHECK(j.at("optimized").at("error").get<std::string>().rfind("optimized run: ", 0) == 0);
  CHECK(j.at("mass_reduction_percent").is_null());
  CHECK(j.at("global_mass_reduction_percent").is_null());
  const json& g = j.at("global");
  CHECK(g.at("reconfigured").get<bool>());
  CHECK(g.at("reached_manifold_optimum").get<bool>());
  CHECK(g.at("integrated_effective_mass").get<double>() <= 1.31);
  CHECK(g.at("orientation_error_deg").get<double>() < 1e-3);
  CHECK(r.out.find("Without optimization    failed (below)") != std::string::npos);
  CHECK(r.out.find("failed: " + plain_error + "\n") != std::string::npos);
  CHECK(r.out.find("nan") == std::string::npos);
  const std::string csv = read_file(tmp.str() + "/out.csv");
  CHECK(csv.find("\nbaseline,") == std::string::npos);
  CHECK(csv.find("\noptimized,") == std::string::npos);
  CHECK(csv.find(",reconfiguration\n") != std::string::npos);
  CHECK(csv.find(",approach\n") != std::string::npos);

  // without the global row the first failure is the job's error (exit 3, as a point out of reach)
  const auto off =
      cli({"--config", kSource + "/robots/paper_7dof_grasp.toml", "--global", "false", "--quiet"});
  CHECK(off.exit_code == 3);
  CHECK(off.err.rfind(kErrorPrefix + " plain run: ", 0) == 0);
  CHECK(off.out.empty());
}

TEST_CASE("contact --model all --json lists the eight laws", "[cli]") {
  const auto j =
      parse_json(cli({"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--model", "all", "--json"}));
  REQUIRE(j.contains("laws"));
  const auto& laws = j.at("laws");
  REQUIRE(laws.is_array());
  REQUIRE(laws.size() == 8);
  std::vector<std::string> names;
  for (const auto& law : laws) {
    REQUIRE(law.contains("model"));
    names.push_back(law.at("model").get<std::string>());
    CHECK(law.at("f_max_closed_form").get<double>() > 0);
    CHECK(law.at("f_max_multibody").get<double>() > 0);
  }
  CHECK(names == std::vector<std::string>{"hunt-crossley", "herbert-mcwhannell", "lankarani-nikravesh",
                                          "lee-wang", "flores", "gonthier", "zhiying-qishao", "hu-guo"});
}

TEST_CASE("contact --series writes F(t) and delta(t)", "[cli]") {
  TempDir tmp;
  const auto r =
      cli({"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--series", "series.csv"}, tmp.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(tmp.entries() == std::vector<std::string>{"series.csv"});  // no temporary file left
  const Csv c = read_csv(tmp / "series.csv");
  const int t_col = c.column("t_s"), f_col = c.column("force_N"), d_col = c.column("delta_m");
  REQUIRE(t_col >= 0);
  REQUIRE(f_col >= 0);
  REQUIRE(d_col >= 0);
  REQUIRE(c.rows.size() > 10);
  CHECK(std::stod(c.rows.front()[static_cast<size_t>(t_col)]) == 0.0);
  double f_max = 0, t_prev = -1;
  for (const auto& row : c.rows) {
    REQUIRE(row.size() == c.header.size());
    const double t = std::stod(row[static_cast<size_t>(t_col)]),
                 f = std::stod(row[static_cast<size_t>(f_col)]);
    CHECK(f >= 0.0);
    CHECK(t >= t_prev);
    t_prev = t;
    f_max = std::max(f_max, f);
  }
  CHECK(f_max == Approx(1861.0).epsilon(0.025));
}

// ------------------------------------------------------------------------------------------------
// 3. the main job
// ------------------------------------------------------------------------------------------------

namespace {}  // namespace

TEST_CASE("a flag on the command line overrides the scenario file", "[cli]") {
  TempDir tmp;
  const auto r = cli({"--config", kScenario3, "--gain", "0", "--json", "out.json", "--quiet"}, tmp.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json j = read_json_file(tmp / "out.json");
  check_result_keys(j);
  CHECK(j.at("optimized").at("gain").get<double>() == 0.0);
  CHECK(j.at("scenario").at("gain").get<double>() == 0.0);
  CHECK(j.at("optimized").at("integrated_effective_mass").get<double>() ==
        Approx(j.at("baseline").at("integrated_effective_mass").get<double>()).epsilon(1e-12));
  CHECK(j.at("mass_reduction_percent").get<double>() == Approx(0.0).margin(1e-9));

  SECTION("also over the built-in default, with negative numbers after a space") {
    const auto d = cli({"--joints-deg", "-10,150,-100", "--json", "d.json", "--quiet"}, tmp.str());
    INFO(d.err);
    REQUIRE(d.exit_code == 0);
    const json jd = read_json_file(tmp / "d.json");
    CHECK(numbers(jd.at("scenario").at("joints-deg")) == std::vector<double>{-10, 150, -100});
    const auto e = cli({"--joints-deg=-10,150,-100", "--json", "e.json", "--quiet"}, tmp.str());
    REQUIRE(e.exit_code == 0);
    CHECK(read_json_file(tmp / "e.json").at("baseline") == jd.at("baseline"));
  }
}

// ------------------------------------------------------------------------------------------------
// 4. bad inputs
// ------------------------------------------------------------------------------------------------

namespace {

struct BadCase {
  const char* name;
  Args args;                           ///< "{TMP}" is replaced by the case's working directory
  std::vector<std::string> must_name;  ///< substrings the error line must contain
  int exit_code = 2;
  std::vector<std::string> dirs = {};  ///< directories to create in the working directory first
};

const std::string kLaws =
    "hunt-crossley, herbert-mcwhannell, lankarani-nikravesh, lee-wang, flores, gonthier, "
    "zhiying-qishao, hu-guo";

Args inspect3(Args extra) {
  Args a{"inspect", "--urdf", kUrdf3};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}
Args inspect3q(Args extra) {  // with valid angles
  Args a{"inspect", "--urdf", kUrdf3, "--joints-deg", "0,90,-90"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}
Args contact3(Args extra) {
  Args a{"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}
// The catalogue's main-job cases run without the global search: their errors come from other keys
// (the global keys' errors are tested in test_global), and at -O0 with ASan a global search per case
// would cost a minute.
Args run_default(Args extra) {  // the built-in scenario, asking for both output files
  Args a{"--quiet", "--global", "false", "--json", "out.json", "--csv", "out.csv"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}
/// "FILE:LINE: key:": how an error of a bad scenario's key begins (after "scenario DIR/").
std::string at_key(const std::string& file, int line, const std::string& key) {
  return file + ":" + std::to_string(line) + ": " + key + ":";
}
Args detumble3(Args extra, bool limit = true) {  // the built-in scenario, asking for both output files
  Args a{"detumble", "--quiet", "--json", "out.json", "--csv", "out.csv"};
  if (limit) a.insert(a.end(), {"--joint-torque-limit", "20"});
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}
Args scenario(const std::string& file) {
  return {
      "--config", kBadScenarios + "/" + file, "--quiet", "--global", "false", "--json", "out.json", "--csv",
      "out.csv"};
}

std::vector<BadCase> bad_cases() {
  return {
      // --- inspect: robot -----------------------------------------------------------------------
      {"missing URDF file",
       {"inspect", "--urdf", "{TMP}/no_such_robot.urdf", "--joints-deg", "0,90,-90"},
       {"no_such_robot.urdf", "cannot open"}},
      {"missing scenario file",
       {"inspect", "--config", "{TMP}/no_such_scenario.toml"},
       {"--config", "no_such_scenario.toml"}},
      {"--urdf without --joints-deg",
       {"inspect", "--urdf", kUrdf7},
       {"--joints-deg", "required with --urdf"}},
      {"wrong joint count", inspect3({"--joints-deg", "0,90"}), {"--joints-deg", "3 joints"}},
      {"wrong joint count, 7-DOF",
       {"inspect", "--urdf", kUrdf7, "--joints-deg", "0,90,-90"},
       {"--joints-deg", "7 joints"}},
      {"non-numeric angle", inspect3({"--joints-deg", "0,abc,-90"}), {"--joints-deg", "'abc'"}},
      {"NaN angle", inspect3({"--joints-deg", "0,nan,-90"}), {"--joints-deg", "nan", "finite"}},
      {"inf angle", inspect3({"--joints-deg", "0,inf,-90"}), {"--joints-deg", "inf", "finite"}},
      {"overflowing angle", inspect3({"--joints-deg", "0,1e999,-90"}), {"--joints-deg", "1e999"}},
      {"trailing comma", inspect3({"--joints-deg", "0,90,"}), {"--joints-deg", "trailing comma"}},
      {"empty angle list", inspect3({"--joints-deg", ""}), {"--joints-deg", "empty"}},
      {"unknown flag", inspect3q({"--bogus"}), {"--bogus"}},
      {"base position of 2 values", inspect3q({"--base-position", "1,2"}), {"--base-position", "got 2"}},
      {"base rpy of 2 values", inspect3q({"--base-rpy-deg", "1,2"}), {"--base-rpy-deg"}},
      {"unknown end-effector",
       inspect3q({"--end-effector", "nope"}),
       {"'nope'", "base, link1, link2, link3, ee"}},
      // --- inspect: target ----------------------------------------------------------------------
      {"target inertia of 4 values",
       inspect3q({"--target-inertia", "100,100,100,0"}),
       {"--target-inertia", "3 or 6", "got 4"}},
      {"contact offset of 2 values",
       inspect3q({"--contact-offset", "-0.25,0.15"}),
       {"--contact-offset", "got 2"}},
      {"normal of 4 values", inspect3q({"--normal", "1,0,0,0"}), {"--normal", "got 4"}},
      {"zero normal", inspect3q({"--normal", "0,0,0"}), {"--normal", "non-zero"}},
      {"negative target mass", inspect3q({"--target-mass", "-200"}), {"--target-mass", "-200"}},
      {"zero target mass", inspect3q({"--target-mass", "0"}), {"--target-mass", "positive"}},
      {"NaN target mass", inspect3q({"--target-mass", "nan"}), {"--target-mass"}},
      {"non-PD target inertia",
       inspect3q({"--target-inertia", "100,100,100,200,0,0"}),
       {"--target-inertia", "positive definite"}},
      {"negative target moment",
       inspect3q({"--target-inertia", "-100,100,100"}),
       {"--target-inertia", "positive definite"}},
      {"triangle inequality",
       inspect3q({"--target-inertia", "1,1,10"}),
       {"--target-inertia", "triangle inequality"}},
      {"NaN target attitude", inspect3q({"--target-rpy-deg", "nan,0,0"}), {"--target-rpy-deg", "nan"}},
      // --- contact --------------------------------------------------------------------------------
      {"negative stiffness",
       contact3({"--stiffness", "-1e9"}),
       {"--stiffness", "stiffness K must be positive"}},
      {"non-numeric stiffness", contact3({"--stiffness", "abc"}), {"--stiffness", "abc"}},
      {"zero exponent", contact3({"--exponent", "0"}), {"--exponent", "alpha must be positive"}},
      {"c_r = 0", contact3({"--restitution", "0"}), {"--restitution", "0 < c_r <= 1", "got 0"}},
      {"c_r > 1", contact3({"--restitution", "1.5"}), {"--restitution", "0 < c_r <= 1", "got 1.5"}},
      {"c_r NaN", contact3({"--restitution", "nan"}), {"--restitution", "0 < c_r <= 1", "got nan"}},
      {"unknown contact law", contact3({"--model", "newton", "--json"}), {"--model", "'newton'", kLaws}},
      // the main job's bound on the key, in every subcommand
      {"receding bodies", contact3({"--approach-speed", "-0.2"}), {"--approach-speed: must be positive, got -0.2"}},
      {"zero approach speed, no spin",
       contact3({"--approach-speed", "0", "--target-angular-velocity-deg", "0,0,0"}),
       {"--approach-speed: must be positive, got 0"}},
      {"infinite approach speed", contact3({"--approach-speed", "inf"}), {"--approach-speed", "finite"}},
      {"target spin of 2 values",
       contact3({"--target-angular-velocity-deg", "0,2"}),
       {"--target-angular-velocity-deg"}},
      {"--series into a missing directory",
       contact3({"--series", "missing_dir/series.csv"}),
       {"missing_dir/series.csv", "cannot write"}},
      {"--series onto a directory",
       contact3({"--series", "a_dir", "--json"}),
       {"a_dir", "cannot write"},
       2,
       {"a_dir"}},
      // --- main job, flags over the built-in scenario ---------------------------------------------
      {"run: wrong joint count", run_default({"--joints-deg", "1,2"}), {"--joints-deg", "got 2"}},
      {"run: non-numeric angle", run_default({"--joints-deg", "1,abc,3"}), {"--joints-deg", "abc"}},
      {"run: unknown contact law", run_default({"--model", "newton"}), {"--model", "'newton'", kLaws}},
      {"run: c_r = 0", run_default({"--restitution", "0"}), {"--restitution", "c_r"}},
      {"run: target inertia of 4 values",
       run_default({"--target-inertia", "100,100,100,0"}),
       {"--target-inertia", "got 4"}},
      {"run: negative target mass", run_default({"--target-mass", "-5"}), {"--target-mass", "-5"}},
      {"run: zero normal", run_default({"--normal", "0,0,0"}), {"--normal", "non-zero"}},
      {"run: base position of 2 values",
       run_default({"--base-position", "1,2"}),
       {"--base-position", "got 2"}},
      {"run: zero approach speed", run_default({"--approach-speed", "0"}), {"--approach-speed", "positive"}},
      {"run: zero tolerance", run_default({"--tolerance", "0"}), {"--tolerance", "positive"}},
      {"run: NaN gain", run_default({"--gain", "nan"}), {"--gain", "finite"}},
      {"run: pose task on 3 joints with gain", run_default({"--task", "pose"}), {"--gain", "no null space"}},
      {"run: unknown task", run_default({"--task", "orbit"}), {"--task", "'orbit'"}},
      {"run: unknown baseline task",
       run_default({"--baseline-task", "orbit"}),
       {"--baseline-task", "'orbit'"}},
      {"run: bad task axes", run_default({"--task-axes", "xw"}), {"--task-axes", "'xw'"}},
      {"run: negative duration", run_default({"--duration", "-1"}), {"--duration", "positive"}},
      {"run: zero step", run_default({"--step", "0"}), {"--step", "got 0"}},
      {"run: step > duration", run_default({"--step", "500"}), {"--step", "got 500"}},
      {"run: unknown objective", run_default({"--objective", "speed"}), {"--objective", "'speed'"}},
      {"run: unknown end-effector", run_default({"--end-effector", "nope"}), {"'nope'", "link3, ee"}},
      {"run: missing URDF", run_default({"--urdf", "{TMP}/no_such_robot.urdf"}), {"no_such_robot.urdf"}},
      {"run: stray positional argument", run_default({"orbit"}), {"orbit"}},
      {"xi: non-existent --config",
       {"xi", "--config", "{TMP}/no_such_scenario.toml"},
       {"--config", "no_such_scenario.toml"}},
      {"run: non-existent --config",
       run_default({"--config", "{TMP}/no_such_scenario.toml"}),
       {"--config", "no_such_scenario.toml"}},
      {"run: --json into a missing directory",
       {"--quiet", "--json", "missing_dir/out.json"},
       {"missing_dir/out.json", "cannot write"}},
      {"run: --csv into a missing directory, --json fine",
       {"--quiet", "--json", "out.json", "--csv", "missing_dir/out.csv"},
       {"missing_dir/out.csv", "cannot write"}},
      {"run: --csv onto a directory, --json fine",
       {"--quiet", "--json", "out.json", "--csv", "a_dir"},
       {"a_dir", "cannot write"},
       2,
       {"a_dir"}},
      {"run: capture point out of reach",
       run_default({"--target-position", "20,1.45,0"}),
       {"out of reach"},
       3},
      // --- detumble ----------------------------------------------------------------------------------
      {"detumble: zero torque limit",
       detumble3({"--joint-torque-limit", "0"}, false),
       {"--joint-torque-limit", "positive", "got 0"}},
      {"detumble: negative torque limit",
       detumble3({"--joint-torque-limit", "20,-1,20"}, false),
       {"--joint-torque-limit", "got -1"}},
      {"detumble: NaN torque limit",
       detumble3({"--joint-torque-limit", "nan"}, false),
       {"--joint-torque-limit", "finite"}},
      {"detumble: infinite torque limit",
       detumble3({"--joint-torque-limit", "inf"}, false),
       {"--joint-torque-limit", "finite"}},
      {"detumble: two limits for three joints",
       detumble3({"--joint-torque-limit", "20,20"}, false),
       {"--joint-torque-limit", "2 values for 3 joints"}},
      {"detumble: no limit, none in the URDF",
       detumble3({}, false),
       {"--joint-torque-limit", "<limit effort>", "joint1"}},
      {"detumble: unknown actuator",
       detumble3({"--base-actuator", "ion-drive"}),
       {"--base-actuator", "'ion-drive'"}},
      {"detumble: wheels without their torque",
       detumble3({"--base-actuator", "reaction-wheels", "--stop-stack-spin", "true"}),
       {"--wheel-torque", "needed"}},
      {"detumble: a wheel bound without wheels",
       detumble3({"--wheel-torque", "1"}),
       {"--wheel-torque", "reaction-wheels only"}},
      {"detumble: an actuator that is not asked to stop the stack's spin",
       detumble3({"--base-actuator", "thrusters", "--thruster-force", "1", "--thruster-torque", "1"}),
       {"--base-actuator", "stop-stack-spin"}},
      {"detumble: zero thruster torque",
       detumble3({"--base-actuator", "thrusters", "--thruster-force", "1", "--thruster-torque", "0",
                  "--stop-stack-spin", "true"}),
       {"--thruster-torque", "positive"}},
      {"detumble: stop the stack's spin without an actuator",
       detumble3({"--stop-stack-spin", "true"}),
       {"--stop-stack-spin", "conserved"}},
      {"detumble: wheels too small to store the stack's momentum",
       detumble3({"--base-actuator", "reaction-wheels", "--wheel-torque", "0.2", "--wheel-momentum", "0.05",
                  "--stop-stack-spin", "true"}),
       {"--wheel-momentum", "cannot store", "(0.05 per axis)"}},
      {"detumble: wheel torque too small for the horizon",
       detumble3({"--base-actuator", "reaction-wheels", "--wheel-torque", "0.001", "--wheel-momentum", "25",
                  "--stop-stack-spin", "true"}),
       {"--wheel-torque", "the horizon is 120 s"}},
      {"detumble: thruster torque too small for the horizon",
       detumble3({"--base-actuator", "thrusters", "--thruster-force", "1", "--thruster-torque", "0.001",
                  "--stop-stack-spin", "true"}),
       {"--thruster-torque", "the horizon is 120 s"}},
      {"detumble: not at rest within the horizon",
       detumble3({"--detumble-horizon", "0.1"}),
       {"--detumble-horizon", "not at rest after 0.1 s"}},
      {"detumble: zero tick", detumble3({"--detumble-tick", "0"}), {"--detumble-tick", "positive"}},
      {"detumble: tick longer than the horizon",
       detumble3({"--detumble-horizon", "1", "--detumble-tick", "2"}),
       {"--detumble-tick", "shorter than detumble-horizon"}},
      {"detumble: NaN rest rate", detumble3({"--rest-rate-deg", "nan"}), {"--rest-rate-deg", "finite"}},
      {"detumble: unknown gripper frame", detumble3({"--end-effector", "nope"}), {"'nope'", "link3, ee"}},
      {"detumble: the contact law does not act", detumble3({"--stiffness", "1e9"}), {"--stiffness"}},
      {"detumble: scenario with a zero torque limit",
       {"detumble", "--config", kBadScenarios + "/detumble_zero_limit.toml", "--quiet", "--json", "out.json"},
       {at_key("detumble_zero_limit.toml", 33, "joint-torque-limit"), "got 0"}},
      {"detumble: scenario with an unknown actuator",
       {"detumble", "--config", kBadScenarios + "/detumble_unknown_actuator.toml", "--quiet", "--json",
        "out.json"},
       {at_key("detumble_unknown_actuator.toml", 34, "base-actuator"), "'magnetorquer'"}},
      {"detumble: more ticks than the run takes",
       detumble3({"--detumble-horizon", "1e6"}),
       {"--detumble-tick", "at most 1e7 ticks", "(100000500 ticks)"}},
      {"detumble: wheel torque not a number",
       detumble3({"--base-actuator", "reaction-wheels", "--wheel-torque", "nan", "--wheel-momentum", "1",
                  "--stop-stack-spin", "true"}),
       {"--wheel-torque", "finite"}},
      {"detumble: thruster force given text",
       detumble3({"--base-actuator", "thrusters", "--thruster-force", "strong", "--thruster-torque", "1",
                  "--stop-stack-spin", "true"}),
       {"--thruster-force", "'strong' is not a number"}},
      {"detumble: zero rest rate",
       detumble3({"--rest-rate-deg", "0"}),
       {"--rest-rate-deg", "positive, got 0"}},
      {"detumble: a target inertia near zero",
       detumble3({"--target-inertia", "1e-300,1e-300,1e-300"}),
       {"grasp:", "--target-inertia"},
       3},
      // a scenario file's key of another job is checked by every subcommand (not used there)
      {"inspect: a file's bad detumble key",
       {"inspect", "--config", kBadScenarios + "/detumble_zero_limit.toml", "--quiet", "--json", "out.json"},
       {at_key("detumble_zero_limit.toml", 33, "joint-torque-limit"), "got 0"}},
      {"contact: a file's bad detumble key",
       {"contact", "--config", kBadScenarios + "/detumble_unknown_actuator.toml", "--quiet", "--json",
        "out.json"},
       {at_key("detumble_unknown_actuator.toml", 34, "base-actuator"), "'magnetorquer'"}},
      {"xi: a file's bad detumble key",
       {"xi", "--config", kBadScenarios + "/detumble_unknown_actuator.toml", "--quiet", "--json", "out.json"},
       {at_key("detumble_unknown_actuator.toml", 34, "base-actuator"), "'magnetorquer'"}},
      {"map: a file's bad detumble key",
       {"map", "--config", kBadScenarios + "/detumble_zero_limit.toml", "--vary", "1", "--quiet", "--csv",
        "out.csv"},
       {at_key("detumble_zero_limit.toml", 33, "joint-torque-limit"), "got 0"}},
      // --- scenario files -------------------------------------------------------------------------
      {"scenario: missing key",
       scenario("missing_duration.toml"),
       {"missing key 'duration'", "missing_duration.toml"}},
      {"scenario: unknown key", scenario("unknown_key.toml"), {"colour"}},
      {"scenario: unreadable URDF",
       scenario("unreadable_urdf.toml"),
       {"bad_scenarios/no_such_robot.urdf", "cannot open"}},
      {"scenario: capture point out of reach", scenario("out_of_reach.toml"), {"out of reach"}, 3},
      // a key of a file is named as the file writes it, after the file and the line: "FILE:LINE: key:"
      {"scenario: non-redundant task with gain",
       scenario("pose_with_gain.toml"),
       {at_key("pose_with_gain.toml", 28, "gain"), "no null space"}},
      {"scenario: unknown task",
       scenario("unknown_task.toml"),
       {at_key("unknown_task.toml", 24, "task"), "'orbit'"}},
      {"scenario: bad task axes",
       scenario("bad_task_axes.toml"),
       {at_key("bad_task_axes.toml", 25, "task-axes"), "'xw'"}},
      {"scenario: negative duration",
       scenario("negative_duration.toml"),
       {at_key("negative_duration.toml", 26, "duration"), "-180"}},
      {"scenario: NaN duration",
       scenario("nan_duration.toml"),
       {at_key("nan_duration.toml", 26, "duration"), "finite"}},
      {"scenario: zero step", scenario("zero_step.toml"), {at_key("zero_step.toml", 27, "step"), "got 0"}},
      {"scenario: step > duration",
       scenario("step_too_large.toml"),
       {at_key("step_too_large.toml", 27, "step"), "got 200"}},
      {"scenario: zero tolerance",
       scenario("zero_tolerance.toml"),
       {at_key("zero_tolerance.toml", 30, "tolerance")}},
      {"scenario: unknown objective",
       scenario("unknown_objective.toml"),
       {at_key("unknown_objective.toml", 31, "objective"), "'speed'"}},
      {"scenario: unknown contact law",
       scenario("unknown_model.toml"),
       {at_key("unknown_model.toml", 18, "model"), "'newton'", kLaws}},
      {"scenario: c_r = 0", scenario("zero_restitution.toml"), {"stiffness/exponent/restitution: ", "c_r"}},
      {"scenario: wrong joint count",
       scenario("wrong_joint_count.toml"),
       {at_key("wrong_joint_count.toml", 5, "joints-deg"), "got 2"}},
      {"scenario: receding approach",
       scenario("receding.toml"),
       {at_key("receding.toml", 22, "approach-speed"), "positive"}},
      {"scenario: target inertia of 4 values",
       scenario("bad_target_inertia.toml"),
       {at_key("bad_target_inertia.toml", 10, "target-inertia"), "got 4"}},
      {"scenario: zero normal",
       scenario("zero_normal.toml"),
       {at_key("zero_normal.toml", 16, "normal"), "non-zero"}},
      // a value of the wrong type, one case per kind of key
      {"scenario: number given text",
       scenario("wrong_type_number.toml"),
       {at_key("wrong_type_number.toml", 26, "duration"), "'long' is not a number"}},
      {"scenario: integer given a fraction",
       scenario("wrong_type_integer.toml"),
       {at_key("wrong_type_integer.toml", 31, "global-starts"), "'2.5' is not an integer"}},
      {"scenario: boolean given a word",
       scenario("wrong_type_boolean.toml"),
       {at_key("wrong_type_boolean.toml", 31, "global"), "expected true or false, got 'maybe'"}},
      {"scenario: list with text",
       scenario("joints_not_numbers.toml"),
       {at_key("joints_not_numbers.toml", 5, "joints-deg"), "'zero' is not a number"}},
      {"scenario: list given a table",
       scenario("wrong_type_table.toml"),
       {at_key("wrong_type_table.toml", 11, "target-position"), "expected a list of numbers, got a table"}},
      {"scenario: unknown mode",
       scenario("wrong_type_choice.toml"),
       {at_key("wrong_type_choice.toml", 31, "base-attitude"), "unknown mode 'sideways'"}},
      {"scenario: a command key given text",
       scenario("wrong_type_command_key.toml"),
       {at_key("wrong_type_command_key.toml", 31, "rtol"), "'tight' is not a number"}},
      {"scenario: the [uncertainty] table with text for a number",
       {"robust", "--config", kBadScenarios + "/wrong_type_uncertainty.toml", "--quiet", "--json",
        "out.json"},
       {at_key("wrong_type_uncertainty.toml", 34, "uncertainty.target-mass.relative"), "expected a number"}},
  };
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t pos = s.find(from); pos != std::string::npos; pos = s.find(from, pos + to.size()))
    s.replace(pos, from.size(), to);
  return s;
}

/// The checks every bad input must pass. `expected_entries`: what the working directory holds
/// afterwards (what was there before: no output and no temporary file may appear).
void check_bad(const CommandResult& r, int exit_code, const std::vector<std::string>& must_name,
               const std::vector<std::string>& expected_entries, const TempDir& dir) {
  INFO("exit code " << r.exit_code << "\nstdout: [" << r.out << "]\nstderr: [" << r.err << "]");
  CHECK_FALSE(r.signaled);
  CHECK(r.exit_code == exit_code);
  // exactly one line, with the prefix
  CHECK(r.err.rfind(kErrorPrefix, 0) == 0);
  CHECK(!r.err.empty());
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK((!r.err.empty() && r.err.back() == '\n'));
  for (const auto& s : must_name) {
    INFO("the error must name: " << s);
    CHECK(r.err.find(s) != std::string::npos);
  }
  CHECK(r.out.empty());  // no result, no table, no JSON
  CHECK(dir.entries() == expected_entries);
  // numbers as a person writes them: a value given with at most 9 digits, a computed one with 6
  // (not 0.050000000000000003 or 1.7320508075688772)
  static const std::regex long_number("[0-9]*\\.[0-9]{10,}");
  CHECK_FALSE(std::regex_search(r.err, long_number));
}

}  // namespace

TEST_CASE("bad inputs: one error line naming the input, exit 2 (3 when out of reach), no output", "[cli]") {
  const auto cases = bad_cases();
  REQUIRE(cases.size() >= 40);
  for (const auto& c : cases) {
    TempDir tmp;
    std::vector<std::string> before;
    for (const auto& d : c.dirs) {
      fs::create_directory(tmp.path() / d);
      before.push_back(d);
    }
    std::sort(before.begin(), before.end());
    Args args;
    for (const auto& a : c.args) args.push_back(replace_all(a, "{TMP}", tmp.str()));
    INFO("case: " << c.name << "\n  " << describe(args));
    const auto r = cli(args, tmp.str());
    check_bad(r, c.exit_code, c.must_name, before, tmp);
  }
}

// Not run by default: prints the catalogue with what each case printed (ffsr-optimize's messages).
TEST_CASE("print the bad-input catalogue", "[.][cli-table]") {
  for (const auto& c : bad_cases()) {
    TempDir tmp;
    for (const auto& d : c.dirs) fs::create_directory(tmp.path() / d);
    Args args;
    for (const auto& a : c.args) args.push_back(replace_all(a, "{TMP}", tmp.str()));
    const auto r = cli(args, tmp.str());
    std::string err = replace_all(replace_all(r.err, tmp.str(), "$TMP"), kSource, "$SRC");
    if (!err.empty() && err.back() == '\n') err.pop_back();
    std::cout << "| " << c.name << " | " << r.exit_code << " | " << err << " |\n";
  }
}

TEST_CASE("bad inputs: every malformed URDF in tests/data/bad_urdf gives exit 2 naming the file", "[cli]") {
  if (!fs::is_directory(kBadUrdfs)) {
    WARN("tests/data/bad_urdf is missing: nothing to check");
    return;
  }
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(kBadUrdfs))
    if (e.path().extension() == ".urdf") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  CHECK(files.size() >= 15);
  for (const auto& f : files) {
    TempDir tmp;
    // the angles are never looked at: the model must be rejected first
    const Args args{"inspect", "--urdf", f.string(), "--joints-deg", "0", "--json"};
    INFO("case: " << f.filename().string() << "\n  " << describe(args));
    const auto r = cli(args, tmp.str());
    check_bad(r, 2, {f.string()}, {}, tmp);
  }
}

TEST_CASE("an output file from an earlier run is not replaced by a failing run", "[cli]") {
  TempDir tmp;
  { std::ofstream(tmp / "out.json") << "{\"earlier\": true}\n"; }
  const auto r = cli({"--quiet", "--json", "out.json", "--target-position", "20,1.45,0"}, tmp.str());
  CHECK(r.exit_code == 3);
  CHECK(tmp.entries() == std::vector<std::string>{"out.json"});
  CHECK(read_json_file(tmp / "out.json") == json({{"earlier", true}}));
}

// ------------------------------------------------------------------------------------------------
// 5. help and version
// ------------------------------------------------------------------------------------------------

TEST_CASE("help and version: --help lists the subcommands, --version prints the version", "[cli]") {
  const auto h = cli({"--help"});
  REQUIRE(h.exit_code == 0);
  CHECK(h.out.find("inspect") != std::string::npos);
  CHECK(h.out.find("contact") != std::string::npos);
  CHECK(h.out.find("--config") != std::string::npos);
  CHECK(h.err.empty());

  for (const char* sub : {"inspect", "contact"}) {
    const auto s = cli({sub, "--help"});
    INFO(sub);
    CHECK(s.exit_code == 0);
    CHECK(s.out.find("--urdf") != std::string::npos);
    CHECK(s.out.find("--joints-deg") != std::string::npos);
  }

  const auto v = cli({"--version"});
  REQUIRE(v.exit_code == 0);
  const std::string version = project_version();
  REQUIRE(!version.empty());
  CHECK(v.out.find(version) != std::string::npos);
  CHECK(v.err.empty());
}

}  // namespace test_cli
