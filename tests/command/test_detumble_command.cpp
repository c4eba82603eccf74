// ffsr-optimize detumble: the post-capture run through the command, checked against its own limits and
// conservation laws (the series of --csv against the limits of the scenario, the momentum drift, the
// rest threshold), the URDF's <limit effort> as the default joint torque limit, the reaction wheels.
#include "support/command.hpp"

#include "ffsr/control/detumble_run.hpp"
#include "ffsr/model/attach.hpp"
#include "ffsr/parsers/urdf.hpp"
#if defined(FFSR_HAVE_PLAN)
#include "ffsr/control/detumble_planner.hpp"
#endif

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace test_detumble_command {

using ffsr::test::Args;
using ffsr::test::cli;
using ffsr::test::kSource;
using ffsr::test::kUrdf3;
using nlohmann::json;

const std::string kDetumbleToml = kSource + "/robots/paper_7dof_detumble.toml";

/// The columns of a CSV with a header line.
std::map<std::string, std::vector<double>> read_csv(const std::string& text) {
  std::istringstream in(text);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::istringstream h(line); std::getline(h, cell, ',');) names.push_back(cell);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    for (size_t k = 0; std::getline(r, cell, ','); ++k) cols[names.at(k)].push_back(std::stod(cell));
  }
  return cols;
}

const std::string kVyasToml = kSource + "/robots/vyas2022_planar.toml";

/// The published planar problem (Vyas et al. 2022) built from its numbers as the planner's unit test
/// builds it (tests/unit/test_detumble_plan.cpp), independently of the scenario file: the target
/// attached 0.35 m beyond the end-effector along the last link (the end-effector's axes), the start
/// state in radians, the limits; the run settings are the scenario's (tick 0.01 s, horizon 30 s, hold 2 s).
struct PublishedPlanar {
  ffsr::Model robot = ffsr::model_from_urdf_file(kSource + "/robots/vyas2022_planar.urdf", "ee");
  ffsr::AttachedBody body;
  ffsr::Model stack;
  int ee = 0;
  ffsr::DetumbleState start;
  ffsr::DetumbleLimits limits;
  ffsr::DetumbleOptions options;
  ffsr::DetumbleRunOptions run;
  PublishedPlanar() {
    body.mass = 50;
    body.inertia = ffsr::Matrix3::Identity() * 3;
    body.pose.p = ffsr::Vector3(0, 0, 0.35);
    stack = ffsr::attach_body(robot, "ee", body);
    ee = stack.frame_index("ee");
    start.theta = Eigen::Vector3d(-0.72, 1.2, 0.72);
    start.v = Eigen::VectorXd(9);
    start.v << -0.0124, 0, -0.0052, 0, 0.0042, 0, 0.0635, -0.1353, 0.1669;
    limits.joint_torque = Eigen::Vector3d::Constant(0.5);
    limits.actuator = ffsr::BaseActuator::Thrusters;
    limits.thruster_force = 2;
    limits.thruster_torque = 2.5;
    options.stop_stack_spin = true;
    options.rest_rate = 1e-3;
    run.horizon = 30;
    run.dwell = 2;
  }
};

/// `text` with the line that sets `key` replaced by `line` (the key must be there).
std::string with_line(std::string text, const std::string& key, const std::string& line) {
  const std::regex set("\n" + key + " = [^\n]*\n");
  REQUIRE(std::regex_search(text, set));
  return std::regex_replace(text, set, "\n" + line + "\n");
}

}  // namespace test_detumble_command

using namespace test_detumble_command;

TEST_CASE("detumble on robots/vyas2022_planar.toml: the held stack's run equals the published problem built from its numbers",
          "[cli]") {
  const PublishedPlanar pb;
  const ffsr::DetumbleRunResult law =
      ffsr::run_detumble(pb.stack, pb.ee, pb.body, pb.start, pb.limits, pb.options, pb.run);
  REQUIRE(law.at_rest);
  ffsr::test::TempDir dir;
  const auto r =
      cli({"detumble", "--config", kVyasToml, "--quiet", "--json", "-", "--csv", "series.csv"}, dir.str());
  const json j = ffsr::test::parse_json(r);
  // no grasp: the target welded where the file puts it, which is 0.35 m along the end-effector's z
  const json& g = j.at("grasp");
  CHECK(g.at("start") == "held");
  CHECK(g.at("impulse_force").get<std::vector<double>>() == std::vector<double>{0, 0, 0});
  CHECK(g.at("impulse_moment").get<std::vector<double>>() == std::vector<double>{0, 0, 0});
  CHECK(g.at("energy_before").get<double>() == g.at("energy_after").get<double>());
  CHECK(g.at("energy_after").get<double>() == Approx(law.energy_start).epsilon(1e-12));
  const json& a = g.at("attachment");
  CHECK(a.at("frame") == "ee");
  CHECK(a.at("mass").get<double>() == 50);
  const auto p = a.at("position").get<std::vector<double>>();
  const auto q = a.at("quaternion_wxyz").get<std::vector<double>>();
  for (size_t k = 0; k < 3; ++k)
    CHECK(std::abs(p[k] - pb.body.pose.p(static_cast<Eigen::Index>(k))) <= 1e-12);
  CHECK(std::abs(std::abs(q[0]) - 1) <= 1e-12);
  // the run: the same ticks, the same figures
  INFO("command " << j.at("time_to_rest").get<double>() << " s, C++ " << law.time_to_rest << " s");
  CHECK(j.at("at_rest").get<bool>());
  CHECK(j.at("ticks").get<long>() == law.ticks);
  CHECK(std::abs(j.at("time_to_rest").get<double>() - law.time_to_rest) <= 1e-9);
  CHECK(j.at("peak_joint_torque").get<double>() == Approx(law.peak_joint_torque).epsilon(1e-9));
  CHECK(j.at("peak_gripper_force").get<double>() == Approx(law.peak_gripper_force).epsilon(1e-9));
  CHECK(j.at("peak_gripper_moment").get<double>() == Approx(law.peak_gripper_moment).epsilon(1e-9));
  CHECK(j.at("base_attitude_excursion").get<double>() == Approx(law.base_attitude_excursion).epsilon(1e-9));
  CHECK(j.at("energy_start").get<double>() == Approx(law.energy_start).epsilon(1e-12));
  CHECK(j.at("dwell_peak_rate").get<double>() == Approx(law.dwell_peak_rate).epsilon(1e-6));
  CHECK(j.at("parameters").at("rest_rate").get<double>() == Approx(1e-3).epsilon(1e-15));
  // every tick of the series: the joints, the base's pose
  const auto cols = read_csv(ffsr::test::read_file(dir.str() + "/series.csv"));
  REQUIRE(cols.at("t").size() == law.series.size());
  double worst = 0;
  for (size_t i = 0; i < law.series.size(); ++i) {
    const ffsr::DetumbleSample& x = law.series[i];
    for (Eigen::Index k = 0; k < 3; ++k) {
      const std::string n = std::to_string(k + 1);
      worst = std::max(worst, std::abs(cols.at("theta_dot_" + n)[i] - x.theta_dot(k)));
      worst = std::max(worst, std::abs(cols.at("theta_" + n)[i] - x.theta(k)));
      worst = std::max(worst, std::abs(cols.at("tau_" + n)[i] - x.command.tau(k)));
    }
    worst = std::max(worst, std::abs(cols.at("base_x")[i] - x.base.position.x()));
    worst = std::max(worst, std::abs(cols.at("base_z")[i] - x.base.position.z()));
  }
  CHECK(worst <= 1e-9);
}

TEST_CASE("detumble: the held stack's start keys refused without grasp-after = held, of a wrong length or not finite",
          "[cli]") {
  ffsr::test::TempDir dir;
  std::string vyas = ffsr::test::read_file(kVyasToml);
  vyas = std::regex_replace(vyas, std::regex("urdf = \"vyas2022_planar.urdf\""),
                            "urdf = \"" + kSource + "/robots/vyas2022_planar.urdf\"");
  std::string seven = ffsr::test::read_file(kDetumbleToml);
  seven = std::regex_replace(seven, std::regex("urdf = \"paper_7dof.urdf\""),
                             "urdf = \"" + kSource + "/robots/paper_7dof.urdf\"");
  struct Bad {
    std::string name, text;
    std::string says;  ///< FILE:LINE: key: what
  };
  const std::vector<Bad> cases = {
      // a start key in a scenario whose stack is captured, not held (the file's line named)
      {"captured", seven + "start-base-velocity = [0, 0, 0.1]\n",
       "captured.toml:\\d+: start-base-velocity: acts with grasp-after = held only"},
      {"approach", with_line(vyas, "grasp-after", "grasp-after = \"approach\""),
       "approach.toml:\\d+: start-(joint-rates-deg|base-angular-velocity-deg|base-velocity): acts with "
       "grasp-after = held only"},
      {"short_rates", with_line(vyas, "start-joint-rates-deg", "start-joint-rates-deg = [1, 2]"),
       "short_rates.toml:\\d+: start-joint-rates-deg: got 2 rates, the robot has 3 joints"},
      {"short_velocity", with_line(vyas, "start-base-velocity", "start-base-velocity = [1, 2]"),
       "short_velocity.toml:\\d+: start-base-velocity: expected 3 numbers, got 2"},
      {"nan_spin",
       with_line(vyas, "start-base-angular-velocity-deg", "start-base-angular-velocity-deg = [0, nan, 0]"),
       "nan_spin.toml:\\d+: start-base-angular-velocity-deg: values must be finite, got nan"},
      {"inf_rates", with_line(vyas, "start-joint-rates-deg", "start-joint-rates-deg = [1, inf, 2]"),
       "inf_rates.toml:\\d+: start-joint-rates-deg: values must be finite, got inf"},
      {"unknown_start", with_line(vyas, "grasp-after", "grasp-after = \"welded\""),
       "unknown_start.toml:\\d+: grasp-after: expected approach, contact or held, got 'welded'"},
  };
  for (const Bad& b : cases) {
    INFO(b.name);
    const std::string file = b.name + ".toml";
    std::ofstream(dir.str() + "/" + file) << b.text;
    const auto r = cli({"detumble", "--config", file, "--quiet", "--json", "out.json"}, dir.str());
    INFO(r.err);
    CHECK(r.exit_code == 2);
    CHECK(std::regex_search(r.err, std::regex(b.says)));
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(!std::ifstream(dir.str() + "/out.json").good());  // nothing written
  }
  // as flags: named as flags; the capture's flags with held, and a run from a capture
  const std::vector<std::pair<Args, std::string>> flags = {
      {{"--config", kDetumbleToml, "--start-joint-rates-deg", "1,2,3,4,5,6,7"},
       "--start-joint-rates-deg: acts with grasp-after = held only"},
      {{"--config", kVyasToml, "--start-joint-rates-deg", "1,2,3,4"},
       "start-joint-rates-deg: got 4 rates, the robot has 3 joints"},
      {{"--config", kVyasToml, "--start-base-velocity", "0,inf,0"},
       "--start-base-velocity: values must be finite"},
      {{"--config", kVyasToml, "--contact-offset", "0.1,0,0"}, "--contact-offset: acts on the capture"},
      {{"--config", kVyasToml, "--stiffness", "1e9"},
       "--stiffness: acts on detumble only with grasp-after = contact"},
      {{"--config", kVyasToml, "--run", "all"}, "grasp-after: held starts from the scenario's start state"},
  };
  for (const auto& [args, says] : flags) {
    Args a{"detumble"};
    a.insert(a.end(), args.begin(), args.end());
    a.insert(a.end(), {"--quiet", "--json", "out.json"});
    const auto r = cli(a, dir.str());
    INFO(args[2] << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(says) != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  }
  // the jobs that start from a capture: the main job's post-capture phase refuses held before its runs
  const auto main_job = cli({"--config", kDetumbleToml, "--grasp-after", "held", "--global", "false", "--quiet",
                             "--json", "out.json"},
                            dir.str());
  CHECK(main_job.exit_code == 2);
  CHECK(main_job.err.find("--grasp-after: held starts from the scenario's start state") != std::string::npos);
  // a subcommand that evaluates the capture asks for the capture's keys the held scenario leaves out
  const auto inspect = cli({"inspect", "--config", kVyasToml, "--quiet", "--json", "out.json"}, dir.str());
  CHECK(inspect.exit_code == 2);
  CHECK(inspect.err.find("missing key 'target-angular-velocity-deg' (grasp-after = held") !=
        std::string::npos);
  CHECK(!std::ifstream(dir.str() + "/out.json").good());
}

TEST_CASE("detumble on the 7-DOF scenario: at rest, every torque within its limit, momentum kept", "[cli]") {
  ffsr::test::TempDir dir;
  const auto r = cli({"detumble", "--config", kDetumbleToml, "--quiet", "--json", "-", "--csv", "series.csv"},
                     dir.str());
  const json j = ffsr::test::parse_json(r);
  const auto limits = j.at("parameters").at("joint_torque_limit").get<std::vector<double>>();
  CHECK(limits == std::vector<double>{60, 60, 60, 40, 20, 20, 20});
  CHECK(j.at("at_rest").get<bool>());
  CHECK(j.at("status") == "at-rest");
  CHECK(j.at("momentum_drift").get<double>() < 1e-8);  // free-floating: the stack's momentum is conserved
  const double rest = 0.05 * M_PI / 180;
  CHECK(j.at("final_joint_rate").get<double>() < rest);
  CHECK(j.at("final_relative_rate").get<double>() < rest);
  CHECK(j.at("energy_end").get<double>() < j.at("energy_start").get<double>());
  CHECK(j.at("grasp").at("energy_after").get<double>() <= j.at("grasp").at("energy_before").get<double>());
  const auto cols = read_csv(ffsr::test::read_file(dir.str() + "/series.csv"));
  const std::vector<double>& t = cols.at("t");
  REQUIRE(t.size() == size_t(j.at("ticks").get<long>()) + 1);
  // the series goes on for the dwell after the first tick at rest (held there: every rate below it)
  CHECK(t.back() == Approx(j.at("time_to_rest").get<double>() + 5).margin(1e-9));
  CHECK(j.at("dwell_at_rest").get<bool>());
  CHECK(j.at("dwell_peak_rate").get<double>() < rest);
  CHECK(j.at("parameters").at("dwell").get<double>() == 5);
  CHECK(j.at("parameters").at("gripper_force_limit").is_null());
  double peak = 0;
  for (size_t k = 0; k < limits.size(); ++k)
    for (double tau : cols.at("tau_" + std::to_string(k + 1))) {
      CHECK(std::abs(tau) <= limits[k] * (1 + 1e-12));
      peak = std::max(peak, std::abs(tau));
    }
  CHECK(peak == Approx(j.at("peak_joint_torque").get<double>()).epsilon(1e-9));
  double gripper = 0;
  for (double f : cols.at("gripper_force")) gripper = std::max(gripper, f);
  CHECK(gripper == Approx(j.at("peak_gripper_force").get<double>()).epsilon(1e-9));
  // the largest joint rate of each row is the largest |theta_dot_k| of the row
  for (size_t i = 0; i < t.size(); ++i) {
    double m = 0;
    for (size_t k = 0; k < limits.size(); ++k)
      m = std::max(m, std::abs(cols.at("theta_dot_" + std::to_string(k + 1))[i]));
    CHECK(m == Approx(cols.at("joint_rate")[i]).epsilon(1e-9));
  }
}

TEST_CASE("detumble: the URDF's <limit effort> is the joint torque limit when the key is not given",
          "[cli]") {
  ffsr::test::TempDir dir;
  const std::string urdf = dir.str() + "/effort.urdf";
  std::ofstream(urdf) << std::regex_replace(
      ffsr::test::read_file(kUrdf3), std::regex("type=\"continuous\">"),
      "type=\"continuous\">\n    <limit effort=\"1.5\" velocity=\"1\"/>");
  const Args common{"detumble", "--joints-deg", "0,150,-100", "--quiet", "--json", "-"};
  Args with_effort = common, with_key = common;
  with_effort.insert(with_effort.end(), {"--urdf", urdf});
  with_key.insert(with_key.end(), {"--urdf", kUrdf3, "--joint-torque-limit", "1.5"});
  json a = ffsr::test::parse_json(cli(with_effort));
  json b = ffsr::test::parse_json(cli(with_key));
  CHECK(a.at("parameters").at("joint_torque_limit").get<std::vector<double>>() ==
        std::vector<double>{1.5, 1.5, 1.5});
  CHECK(a.at("peak_joint_torque").get<double>() <= 1.5 * (1 + 1e-12));
  CHECK(a.at("peak_joint_torque").get<double>() == Approx(1.5));  // the limit binds: 2.2 N m unlimited
  a.erase("version");
  b.erase("version");
  CHECK(a == b);
}

TEST_CASE("detumble with reaction wheels: the stack's spin stopped, the stored momentum within its bound",
          "[cli]") {
  const json j = ffsr::test::parse_json(
      cli({"detumble", "--joint-torque-limit", "20", "--base-actuator", "reaction-wheels", "--wheel-torque",
           "0.2", "--wheel-momentum", "25", "--stop-stack-spin", "true", "--quiet", "--json", "-"}));
  CHECK(j.at("at_rest").get<bool>());
  CHECK(j.at("final_stack_rate").get<double>() < 0.05 * M_PI / 180);
  CHECK(j.at("peak_wheel_momentum").get<double>() <= 25.0);
  CHECK(j.at("peak_wheel_momentum").get<double>() > 0.0);
  // the torque bound: at least |L_c| / (sqrt(3) 0.2 N m) to remove the stack's momentum
  const json free =
      ffsr::test::parse_json(cli({"detumble", "--joint-torque-limit", "20", "--quiet", "--json", "-"}));
  CHECK(free.at("final_stack_rate").get<double>() >
        0.05 * M_PI / 180);  // free-floating: the stack keeps its spin
  CHECK(j.at("time_to_rest").get<double>() > free.at("time_to_rest").get<double>());
}

TEST_CASE("detumble --run: from the capture configurations of the main job's runs", "[cli]") {
  // the main job with the Detumble keys of the file runs each run's post-capture phase: its table
  // (standard output) and its JSON (a file) from one run, `detumble --run all` from another process
  ffsr::test::TempDir dir;
  const auto main_run = cli({"--config", kDetumbleToml, "--json", "main.json"}, dir.str());
  REQUIRE(main_run.exit_code == 0);
  const json main = json::parse(ffsr::test::read_existing_file(dir.str() + "/main.json"));
  const json all = ffsr::test::parse_json(
      cli({"detumble", "--config", kDetumbleToml, "--run", "all", "--quiet", "--json", "-"}));
  REQUIRE(all.at("runs").size() == 3);
  for (const json& r : all.at("runs")) {
    const std::string name = r.at("run");
    INFO(name);
    const auto q = r.at("joints_deg").get<std::vector<double>>();
    const auto qm = main.at(name).at("capture_configuration_deg").get<std::vector<double>>();
    REQUIRE(q.size() == qm.size());
    for (size_t k = 0; k < q.size(); ++k) CHECK(q[k] == Approx(qm[k]).margin(1e-9));
    CHECK(r.at("at_rest").get<bool>());
    CHECK(r.at("momentum_drift").get<double>() < 1e-8);
    // the main job's figures of the run: the same names and values, to the last bit
    json expected = r;
    expected.erase("run");
    CHECK(main.at(name).at("post_capture") == expected);
    // its row of the table: time to rest, peak torque and joint, peak gripper force and moment, base
    // attitude excursion (deg), no wheels
    const std::string label = name == "baseline"    ? "Without optimization"
                              : name == "optimized" ? "With optimization"
                                                    : "Global";
    char cells[256];
    std::snprintf(cells, sizeof cells, "e-\\d+ +%.2f +%.2f +%s +%.2f +%.2f +%.3f +-\\s",
                  r.at("time_to_rest").get<double>(), r.at("peak_joint_torque").get<double>(),
                  r.at("peak_joint").get<std::string>().c_str(), r.at("peak_gripper_force").get<double>(),
                  r.at("peak_gripper_moment").get<double>(),
                  r.at("base_attitude_excursion").get<double>() * 180 / M_PI);
    INFO(main_run.out);
    CHECK(std::regex_search(main_run.out, std::regex("\n" + label + " +\\[[^\n]*" + cells)));
  }
  // one run alone: the same result as within 'all'
  json one = ffsr::test::parse_json(
      cli({"detumble", "--config", kDetumbleToml, "--run", "optimized", "--quiet", "--json", "-"}));
  CHECK(one.at("runs").at(0) == all.at("runs").at(1));
  // the configuration differs from the scenario's start, so does the result
  const json start =
      ffsr::test::parse_json(cli({"detumble", "--config", kDetumbleToml, "--quiet", "--json", "-"}));
  CHECK(start.at("time_to_rest") != one.at("runs").at(0).at("time_to_rest"));
  const auto bad = cli({"detumble", "--config", kDetumbleToml, "--run", "best", "--quiet"});
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("--run") != std::string::npos);
}

TEST_CASE("detumble --grasp-after contact: the Hertz phase before the lock, reported and checked", "[cli]") {
  const Args base{"detumble", "--config", kDetumbleToml, "--quiet", "--json", "-"};
  auto with = [&base](const Args& more) {
    Args a = base;
    a.insert(a.end(), more.begin(), more.end());
    return cli(a);
  };
  const json approach = ffsr::test::parse_json(with({}));
  const json contact = ffsr::test::parse_json(with({"--grasp-after", "contact"}));
  CHECK(approach.at("grasp").at("start") == "approach");
  CHECK(!approach.at("grasp").contains("contact"));
  REQUIRE(contact.at("grasp").at("start") == "contact");
  const json& c = contact.at("grasp").at("contact");
  // the contact phase is the contact subcommand's multibody run of the same scenario
  const json ref =
      ffsr::test::parse_json(cli({"contact", "--config", kDetumbleToml, "--quiet", "--json", "-"}));
  CHECK(c.at("model") == ref.at("model"));
  CHECK(c.at("peak_force").get<double>() == Approx(ref.at("f_max_multibody").get<double>()).epsilon(1e-12));
  CHECK(c.at("duration").get<double>() == Approx(ref.at("contact_duration").get<double>()).epsilon(1e-12));
  // the grasp starts where the contact ends: its energy before the lock is the contact's at separation
  CHECK(contact.at("grasp").at("energy_before").get<double>() ==
        Approx(c.at("energy_end").get<double>()).epsilon(1e-12));
  // contact impulse + lock impulse = the approach lock's impulse, to first order in the contact's
  // duration (docs/detumble.md; tests/unit/test_contact_grasp.cpp checks the order)
  const auto pa = approach.at("grasp").at("impulse_force").get<std::vector<double>>();
  const auto pl = contact.at("grasp").at("impulse_force").get<std::vector<double>>();
  const auto pc = c.at("impulse_force").get<std::vector<double>>();
  double diff = 0, size = 0;
  for (int k = 0; k < 3; ++k) {
    diff += std::pow(pl[k] + pc[k] - pa[k], 2);
    size += pa[k] * pa[k];
  }
  CHECK(std::sqrt(diff) < 1e-3 * std::sqrt(size));
  CHECK(contact.at("at_rest").get<bool>());
  CHECK(contact.at("momentum_drift").get<double>() < 1e-8);
  // the contact law's flags act with grasp-after = contact: refused without it, one line naming the flag
  const auto refused = with({"--model", "hunt-crossley"});
  CHECK(refused.exit_code == 2);
  CHECK(refused.err.find("--model: acts on detumble only with grasp-after = contact") != std::string::npos);
  CHECK(std::count(refused.err.begin(), refused.err.end(), '\n') == 1);
  CHECK(refused.out.empty());
  const json hc = ffsr::test::parse_json(with({"--grasp-after", "contact", "--model", "hunt-crossley"}));
  CHECK(hc.at("grasp").at("contact").at("model") == "hunt-crossley");
  const auto all = with({"--grasp-after", "contact", "--model", "all"});
  CHECK(all.exit_code == 2);
  CHECK(all.err.find("--model") != std::string::npos);
  const auto bad = with({"--grasp-after", "impact"});
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("--grasp-after: expected approach, contact or held, got 'impact'") != std::string::npos);
}

TEST_CASE("detumble --csv: the joint angles, the base's, the target's and the bodies' poses move rigidly",
          "[cli]") {
  // the built-in 3-DOF scenario from its three captures: the target held by the gripper (body 3)
  ffsr::test::TempDir dir;
  const json j = ffsr::test::parse_json(cli({"detumble", "--run", "all", "--joint-torque-limit", "20",
                                             "--quiet", "--json", "-", "--csv", "series.csv"},
                                            dir.str()));
  const std::string text = ffsr::test::read_file(dir.str() + "/series.csv");
  // the runs one after the other: split on the run column (the first), keep the numbers
  std::map<std::string, std::string> per_run;
  std::istringstream in(text);
  std::string header, line;
  std::getline(in, header);
  while (std::getline(in, line)) {
    const auto comma = line.find(',');
    per_run[line.substr(0, comma)] += line.substr(comma + 1) + "\n";
  }
  REQUIRE(per_run.size() == 3);
  const std::string columns = header.substr(header.find(',') + 1) + "\n";
  for (const json& r : j.at("runs")) {
    const std::string name = r.at("run");
    INFO(name);
    const auto c = read_csv(columns + per_run.at(name));
    const auto pose = [&c](const std::string& p, size_t i) {
      const Eigen::Quaterniond q(c.at(p + "_qw")[i], c.at(p + "_qx")[i], c.at(p + "_qy")[i],
                                 c.at(p + "_qz")[i]);
      return std::make_pair(Eigen::Vector3d(c.at(p + "_x")[i], c.at(p + "_y")[i], c.at(p + "_z")[i]), q);
    };
    const auto q0 = r.at("joints_deg").get<std::vector<double>>();
    const auto& t = c.at("t");
    const auto [pt0, qt0] = pose("target", 0);
    const auto [pb0, qb0] = pose("body3", 0);
    const Eigen::Vector3d held = qb0.conjugate() * (pt0 - pb0);  // the target in the gripper's body
    const Eigen::Quaterniond turn = qb0.conjugate() * qt0;
    const auto [base0p, base0] = pose("base", 0);
    for (size_t i = 0; i < t.size(); ++i) {
      for (const char* p : {"base", "target", "body1", "body2", "body3"})
        CHECK(pose(p, i).second.norm() == Approx(1.0).margin(1e-10));
      // held rigidly by the gripper's body
      const auto [pt, qt] = pose("target", i);
      const auto [pb, qb] = pose("body3", i);
      CHECK((qb.conjugate() * (pt - pb) - held).norm() < 1e-9);
      CHECK(std::abs((qb.conjugate() * qt).dot(turn)) == Approx(1.0).margin(1e-10));
      // the base's rotation since the grasp, from its attitude column
      CHECK(base0.angularDistance(pose("base", i).second) == Approx(c.at("base_attitude")[i]).margin(1e-9));
      // the joint angles advance with the joint rates (trapezoid over a 0.01 s tick)
      for (size_t k = 1; k <= q0.size(); ++k) {
        const auto& th = c.at("theta_" + std::to_string(k));
        const auto& rate = c.at("theta_dot_" + std::to_string(k));
        if (i == 0) CHECK(th[0] == Approx(q0[k - 1] * M_PI / 180).margin(1e-10));
        if (i > 0)
          CHECK(th[i] - th[i - 1] == Approx(0.5 * (rate[i] + rate[i - 1]) * (t[i] - t[i - 1])).margin(1e-7));
      }
    }
    const auto a = r.at("grasp").at("attachment");
    CHECK(a.at("frame") == "ee");
    CHECK(a.at("mass").get<double>() > 0);
  }
}

TEST_CASE("main job: each run's post-capture phase when a Detumble key is given, the CSV unchanged",
          "[cli]") {
  ffsr::test::TempDir dir;
  const Args run{"--global", "false", "--quiet", "--json", "-"};
  Args plain = run, post = run;
  plain.insert(plain.end(), {"--csv", "plain.csv"});
  post.insert(post.end(), {"--csv", "post.csv", "--joint-torque-limit", "2"});
  const json a = ffsr::test::parse_json(cli(plain, dir.str()));
  const json b = ffsr::test::parse_json(cli(post, dir.str()));
  for (const char* name : {"baseline", "optimized"}) {
    INFO(name);
    CHECK_FALSE(a.at(name).contains("post_capture"));  // no Detumble key: the runs stop at the impact
    const json& p = b.at(name).at("post_capture");
    CHECK(p.at("parameters").at("joint_torque_limit") == json({2.0, 2.0, 2.0}));
    CHECK(p.at("at_rest").get<bool>());
    CHECK(p.at("peak_joint_torque").get<double>() <= 2.0 * (1 + 1e-12));
    CHECK(p.at("momentum_drift").get<double>() < 1e-8);
    // the grasp starts from the run's capture configuration
    const auto q = p.at("joints_deg").get<std::vector<double>>();
    const auto qm = b.at(name).at("capture_configuration_deg").get<std::vector<double>>();
    REQUIRE(q.size() == qm.size());
    for (size_t k = 0; k < q.size(); ++k) CHECK(q[k] == Approx(qm[k]).margin(1e-9));
    CHECK_FALSE(p.contains("version"));
    // the capture itself does not change
    CHECK(a.at(name).at("integrated_effective_mass") == b.at(name).at("integrated_effective_mass"));
  }
  CHECK(b.at("scenario").at("joint-torque-limit") == json({2.0}));
  // the CSV holds the approach's series only (detumble --csv holds the post-capture series)
  CHECK(ffsr::test::read_existing_file(dir.str() + "/plain.csv") ==
        ffsr::test::read_existing_file(dir.str() + "/post.csv"));
}

TEST_CASE("main job: an error of the post-capture phase names the key and the run and writes nothing",
          "[cli]") {
  ffsr::test::TempDir dir;
  const std::string old = "{\"earlier\": true}\n";
  std::ofstream(dir.str() + "/out.json") << old;
  struct Case {
    Args args;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases = {
      {{"--joint-torque-limit", "20", "--detumble-horizon", "0.1"},
       {"--detumble-horizon", "not at rest after 0.1 s", "baseline run"}},
      {{"--joint-torque-limit", "20", "--stop-stack-spin", "true"}, {"--stop-stack-spin", "baseline run"}},
      {{"--joint-torque-limit", "20", "--base-actuator", "reaction-wheels", "--wheel-torque", "0.2",
        "--wheel-momentum", "1", "--stop-stack-spin", "true"},
       {"--wheel-momentum", "cannot store", "baseline run"}},
      {{"--rest-rate-deg", "0.1"}, {"--joint-torque-limit", "<limit effort>", "baseline run"}}};
  for (const Case& c : cases) {
    Args a{"--global", "false", "--quiet", "--json", "out.json", "--csv", "out.csv"};
    a.insert(a.end(), c.args.begin(), c.args.end());
    const auto r = cli(a, dir.str());
    INFO(r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.out.empty());
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    for (const std::string& part : c.says) CHECK(r.err.find(part) != std::string::npos);
    CHECK(ffsr::test::read_file(dir.str() + "/out.json") == old);  // the earlier file survives
    CHECK_FALSE(std::ifstream(dir.str() + "/out.csv").good());
  }
  // a key of the file is named where the file gives it
  std::string toml =
      std::regex_replace(ffsr::test::read_file(kDetumbleToml), std::regex("base-actuator = \"none\""),
                         "base-actuator = \"none\"\nstop-stack-spin = true");
  toml = std::regex_replace(toml, std::regex("urdf = \"paper_7dof.urdf\""),
                            "urdf = \"" + ffsr::test::kUrdf7 + "\"");
  std::ofstream(dir.str() + "/spin.toml") << toml;
  const auto r =
      cli({"--config", "spin.toml", "--global", "false", "--quiet", "--json", "out.json"}, dir.str());
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(std::regex_search(r.err, std::regex("spin\\.toml:\\d+: stop-stack-spin: .*conserved.*baseline run")));
  CHECK(ffsr::test::read_file(dir.str() + "/out.json") == old);
}

#if defined(FFSR_HAVE_PLAN)
TEST_CASE("detumble --plan: the time-optimal plan beside the law, its re-run in the CSV within every limit",
          "[cli]") {
  ffsr::test::TempDir dir;
  const auto r = cli({"detumble", "--config", kDetumbleToml, "--quiet", "--plan", "--json", "-", "--csv", "series.csv"},
                     dir.str());
  const json j = ffsr::test::parse_json(r);
  const json& p = j.at("plan");
  // the free plan's intervals are shorter than the 0.01 s tick: solved again on the tick's grid, whose
  // least-effort solve may end at IPOPT's acceptable level (its constraints still within 1e-8)
  CHECK((p.at("solver_status") == "Solve_Succeeded" || p.at("solver_status") == "Solved_To_Acceptable_Level"));
  CHECK(p.at("constraint_violation").get<double>() <= 1e-8);
  const double T = p.at("time_to_rest").get<double>();
  const double tick = j.at("parameters").at("tick").get<double>();
  CHECK(p.at("free_intervals_time_to_rest").get<double>() <= T);
  CHECK(T / p.at("intervals").get<int>() == Approx(tick).epsilon(1e-12));
  CHECK(T < j.at("time_to_rest").get<double>());  // the law's
  CHECK(T <= 0.5 * 5.05);                         // the fixed-gain law of the earlier releases
  CHECK(p.at("initial_guess_time_to_rest").get<double>() == Approx(j.at("time_to_rest").get<double>()).margin(0.02));
  const json& rr = p.at("rerun");
  CHECK(rr.at("at_rest").get<bool>());
  CHECK(rr.at("dwell_at_rest").get<bool>());
  CHECK(rr.at("worst_bound_excess").get<double>() <= 1e-9);
  CHECK(rr.at("momentum_drift").get<double>() <= 1e-8);  // free-floating: the plan on the 0.01 s grid
  const auto limits = j.at("parameters").at("joint_torque_limit").get<std::vector<double>>();
  REQUIRE(p.at("controls").size() == size_t(p.at("intervals").get<int>()));
  REQUIRE(p.at("nodes").size() == p.at("controls").size() + 1);
  for (const json& c : p.at("controls")) {
    const auto tau = c.at("tau").get<std::vector<double>>();
    for (size_t k = 0; k < limits.size(); ++k) CHECK(std::abs(tau[k]) <= limits[k]);
    CHECK(c.at("base_force").get<std::vector<double>>() == std::vector<double>{0, 0, 0});  // free-floating
  }
  CHECK(p.at("nodes").back().at("t").get<double>() == Approx(T).epsilon(1e-12));
  // the CSV: the law's rows ("law") then the plan's re-run ("plan"), each torque within its limit
  std::istringstream csv(ffsr::test::read_file(dir.str() + "/series.csv"));
  std::string line;
  std::getline(csv, line);
  REQUIRE(line.rfind("run,t,", 0) == 0);
  std::map<std::string, int> rows;
  double last_plan_t = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::istringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
    ++rows[cells.at(0)];
    if (cells[0] == "plan") last_plan_t = std::stod(cells.at(1));
  }
  CHECK(rows.size() == 2);
  CHECK(rows["law"] == j.at("ticks").get<long>() + 1);
  CHECK(rows["plan"] > 0);
  CHECK(last_plan_t == Approx(T + 5).margin(0.011));  // the plan, then the 5 s hold
}

TEST_CASE("detumble --plan on robots/vyas2022_planar.toml: the plan agrees with the C++ setup's to the solver's local optimum",
          "[cli]") {
  const PublishedPlanar pb;
  const ffsr::DetumblePlan plan =
      ffsr::plan_detumble(pb.stack, pb.ee, pb.body, pb.start, pb.limits, pb.options, pb.run.horizon);
  const auto r = cli({"detumble", "--config", kVyasToml, "--quiet", "--plan", "--json", "-"});
  const json j = ffsr::test::parse_json(r);
  const json& p = j.at("plan");
  INFO("command " << p.at("time_to_rest").get<double>() << " s (" << p.at("iterations") << " iterations), C++ "
                  << plan.duration << " s (" << plan.iterations << " iterations)");
  for (const std::string& status : {p.at("solver_status").get<std::string>(), plan.status})
    CHECK((status == "Solve_Succeeded" || status == "Solved_To_Acceptable_Level"));
  // the same problem to rounding (the attachment from the file's inertial pose differs from 0.35 m
  // along z by about 1e-16), and the interior point's path in this non-convex problem changes with
  // rounding: the two local optima measured 3.41186 s and 3.41154 s
  CHECK(std::abs(p.at("time_to_rest").get<double>() - plan.duration) <= 1e-3);
  CHECK(plan.duration <= 3.5);  // published 4.095 s
  CHECK(p.at("time_to_rest").get<double>() <= 3.5);
  CHECK(p.at("rerun").at("at_rest").get<bool>());
  CHECK(p.at("rerun").at("worst_bound_excess").get<double>() <= 1e-9);
}
#else
TEST_CASE("detumble --plan without IPOPT: refused naming the flag and what to install", "[cli]") {
  const auto r = cli({"detumble", "--config", kDetumbleToml, "--plan"});
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("--plan") != std::string::npos);
  CHECK(r.err.find("coinor-libipopt-dev") != std::string::npos);
}
#endif
