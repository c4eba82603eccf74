// The joint model of the contact through every subcommand: for free, locked and armature joints, each
// M_ie or F_max a subcommand reports in its JSON (or CSV) equals the library's capture objective
// (CaptureEvaluator, optimize/objective.hpp; its values are checked against independent computations
// in tests/unit/test_capture_objective.cpp) of that model at the configuration it reports, to 1e-10
// relative. Short runs: the paper's 3-DOF robot, small horizons, few samples and levels.
#include <catch2/catch.hpp>

#include "support/command.hpp"

#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/objective.hpp"

#include <fstream>
#include <sstream>

namespace test_objective_models {

using namespace ffsr;
using namespace ffsr::test;

namespace {

struct JointCase {
  std::string name;
  Args flags;                                             ///< the command's flags
  std::vector<std::pair<std::string, std::string>> keys;  ///< the same as scenario keys
};

std::vector<JointCase> joint_cases() {
  return {{"free", {}, {}},
          {"locked", {"--contact-joints", "locked"}, {{"contact-joints", "locked"}}},
          {"armature",
           {"--contact-joints", "armature", "--armature", "0.5"},
           {{"contact-joints", "armature"}, {"armature", "0.5"}}}};
}

Args with(Args a, const Args& more) {
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

/// The scenario of `file` with the case's keys (and `extra`), through the library.
Scenario scenario_of(const std::string& file, const JointCase& c,
                     const std::vector<std::pair<std::string, std::string>>& extra = {}) {
  ScenarioKeys k = read_scenario_file(file);
  for (const auto& [name, value] : c.keys) override_scenario_key(k, name, value);
  for (const auto& [name, value] : extra) override_scenario_key(k, name, value);
  return build_scenario(std::move(k));
}

Eigen::VectorXd radians(const nlohmann::json& deg) {
  Eigen::VectorXd q(static_cast<Eigen::Index>(deg.size()));
  for (Eigen::Index k = 0; k < q.size(); ++k) q(k) = deg[static_cast<size_t>(k)].get<double>() * M_PI / 180;
  return q;
}

BasePose pose(const nlohmann::json& position, const nlohmann::json& wxyz) {
  BasePose b;
  b.position = Vector3(position[0].get<double>(), position[1].get<double>(), position[2].get<double>());
  b.orientation =
      Quaternion(wxyz[0].get<double>(), wxyz[1].get<double>(), wxyz[2].get<double>(), wxyz[3].get<double>());
  return b;
}

void same(const nlohmann::json& reported, double library) {
  REQUIRE(reported.is_number());
  CHECK(reported.get<double>() == Approx(library).epsilon(1e-10));
}

const std::string kPaper3 = kSource + "/robots/paper_3dof.toml";

}  // namespace

TEST_CASE("Joint models through the main job: every row, branch and base jump is the model's",
          "[objective][cli]") {
  for (const JointCase& c : joint_cases()) {
    INFO(c.name);
    TempDir dir;
    const auto r = cli(with({"--config", kPaper3, "--json", dir / "r.json", "--quiet"}, c.flags), dir.str());
    REQUIRE(r.exit_code == 0);
    const nlohmann::json j = read_json_file(dir / "r.json");
    const Scenario sc = scenario_of(kPaper3, c);
    const CaptureSetup setup = prepare_capture(sc.problem, sc.task, sc.capture);
    const CaptureEvaluator f(sc.problem, setup);
    Data data(*sc.model);
    for (const char* row : {"baseline", "optimized", "global"}) {
      INFO(row);
      const nlohmann::json& x = j[row];
      const BasePose base = pose(x["base_position"], x["base_quaternion_wxyz"]);
      const double M = f.mass(data, base, radians(x["capture_configuration_deg"]));
      same(x["integrated_effective_mass"], M);
      same(x["f_max_closed_form"], f.f_max_closed_form(M));
      same(x["f_max_exact"], f.f_max_exact(M));
      same(x["base_disturbance"]["impulse"],
           f.disturbance(data, base, radians(x["capture_configuration_deg"])).impulse);
    }
    const nlohmann::json& g = j["global"];
    same(g["objective_value"], g["integrated_effective_mass"].get<double>());
    const BasePose gbase = pose(g["base_position"], g["base_quaternion_wxyz"]);
    REQUIRE(!g["branches"].empty());
    for (const nlohmann::json& b : g["branches"])
      same(b["integrated_effective_mass"], f.mass(data, gbase, radians(b["configuration_deg"])));
  }
}

TEST_CASE("Joint models through inspect and contact: M_ie and the peaks are the model's",
          "[objective][cli]") {
  for (const JointCase& c : joint_cases()) {
    INFO(c.name);
    const Scenario sc = scenario_of(kPaper3, c);
    const Model& model = *sc.model;
    Data data(model);
    const nlohmann::json ins =
        parse_json(cli_sub("inspect", with({"--config", kPaper3, "--json"}, c.flags), {}));
    CHECK(ins["contact_joints"] == c.name);
    const CaptureEvaluator at_start(model, sc.problem.frame, sc.problem.target, nullptr, sc.problem.joints);
    same(ins["integrated_effective_mass"], at_start.mass(data, sc.problem.base, radians(ins["joints_deg"])));

    const nlohmann::json con =
        parse_json(cli_sub("contact", with({"--config", kPaper3, "--json"}, c.flags), {}));
    const AnyContactLaw law =
        make_contact_law(sc.problem.law, sc.problem.contact, con["approach_velocity"].get<double>());
    const CaptureEvaluator f(model, sc.problem.frame, sc.problem.target, &law, sc.problem.joints);
    const double M = f.mass(data, sc.problem.base, sc.problem.theta);
    same(con["integrated_effective_mass"], M);
    same(con["f_max_closed_form"], f.f_max_closed_form(M));
    same(con["f_max_exact"], f.f_max_exact(M));
    same(con["base_disturbance"]["impulse"], f.disturbance(data, sc.problem.base, sc.problem.theta).impulse);
  }
}

TEST_CASE("Joint models through map: each row's M_ie and F_max are the model's", "[objective][cli]") {
  for (const JointCase& c : joint_cases()) {
    INFO(c.name);
    const auto r = cli_sub(
        "map",
        with({"--config", kPaper3, "--vary", "1,3", "--step-deg", "90", "--csv", "-", "--quiet"}, c.flags),
        {});
    REQUIRE(r.exit_code == 0);
    const Scenario sc = scenario_of(kPaper3, c);
    const Target& t = sc.problem.target;
    const Vector3 u = t.normal_world();
    const double v_in = approach_velocity(u, Vector3(sc.problem.approach_speed * u), t.velocity,
                                          t.angular_velocity_world(), t.offset_world());
    const AnyContactLaw law = make_contact_law(sc.problem.law, sc.problem.contact, v_in);
    const CaptureEvaluator f(*sc.model, sc.problem.frame, t, &law, sc.problem.joints);
    Data data(*sc.model);
    std::istringstream in(r.out);
    std::string line;
    std::getline(in, line);  // header
    int rows = 0;
    while (std::getline(in, line)) {
      double a1 = 0, a3 = 0, M = 0, F = 0;
      REQUIRE(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf", &a1, &a3, &M, &F) == 4);
      Eigen::VectorXd theta = sc.problem.theta;
      theta(0) = a1 * (M_PI / 180.0);
      theta(2) = a3 * (M_PI / 180.0);
      const double expected = f.mass(data, sc.problem.base, theta);
      CHECK(M == Approx(expected).epsilon(1e-10));
      CHECK(F == Approx(f.f_max_closed_form(expected)).epsilon(1e-10));
      ++rows;
    }
    CHECK(rows == 16);  // 4 x 4 angles: -180, -90, 0, 90
  }
}

TEST_CASE("Joint models through pareto and closed-loop: the front's and the loop's M_ie are the model's",
          "[objective][cli]") {
  for (const JointCase& c : joint_cases()) {
    INFO(c.name);
    TempDir dir;
    const Args common = with({"--config", kPaper3}, c.flags);
    const auto p = cli_sub(
        "pareto", with(common, {"--levels", "3", "--starts", "4", "--json", dir / "p.json"}), dir.str());
    INFO(p.err);
    REQUIRE(p.exit_code == 0);
    const nlohmann::json pj = read_json_file(dir / "p.json");
    const Scenario sc = scenario_of(kPaper3, c);
    const CaptureSetup setup = prepare_capture(sc.problem, sc.task, sc.capture);
    const CaptureEvaluator f(sc.problem, setup);
    Data data(*sc.model);
    const BasePose base = pose(pj["base_position"], pj["base_quaternion_wxyz"]);
    for (const nlohmann::json& x : pj["front"])
      same(x["integrated_effective_mass"], f.mass(data, base, radians(x["capture_configuration_deg"])));
    same(pj["knee"]["integrated_effective_mass"],
         f.mass(data, base, radians(pj["knee"]["capture_configuration_deg"])));

    const auto l = cli_sub(
        "closed-loop",
        with(common, {"--control-rate", "10", "--estimate-rate", "1", "--quiet", "--json", dir / "l.json"}),
        dir.str());
    INFO(l.err);
    REQUIRE(l.exit_code == 0);
    const nlohmann::json lj = read_json_file(dir / "l.json");
    for (const char* run : {"open_loop", "closed_loop"}) {
      INFO(run);
      const nlohmann::json& x = lj[run];
      const double M = f.mass(data, pose(x["base_position"], x["base_quaternion_wxyz"]),
                              radians(x["capture_configuration_deg"]));
      same(x["integrated_effective_mass"], M);
      same(x["f_max_closed_form"], f.f_max_closed_form(M));
    }
  }
}

TEST_CASE("Joint models through robust: the nominal and the tail samples' M_ie and F_max are the model's",
          "[objective][cli]") {
  TempDir dir;
  {
    std::ofstream toml(dir / "robust.toml");
    toml << read_existing_file(kPaper3) << "\n[uncertainty]\nsamples = 30\nseed = 7\n"
         << "target-mass = { law = \"uniform\", relative = 0.10 }\n"
         << "contact-point = { law = \"uniform\", half-width = 0.05 }\n"
         << "normal = { law = \"cone\", angle-deg = 5 }\n";
  }
  {  // the file's urdf is relative to the file: link the robot beside it
    std::ofstream urdf(dir / "paper_3dof.urdf");
    urdf << read_existing_file(kSource + "/robots/paper_3dof.urdf");
  }
  for (const JointCase& c : joint_cases()) {
    INFO(c.name);
    const auto r = cli_sub("robust",
                           with({"--config", dir / "robust.toml", "--capture-joints-deg", "10,80,-60",
                                 "--json", dir / "r.json", "--quiet"},
                                c.flags),
                           dir.str());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json j = read_json_file(dir / "r.json");
    const Scenario sc = scenario_of(dir / "robust.toml", c);
    const nlohmann::json& cj = j["configurations"][0];
    const BasePose base = pose(cj["base_position"], cj["base_quaternion_wxyz"]);
    const Eigen::VectorXd theta = radians(cj["joints_deg"]);
    UncertainNominal nominal;
    nominal.target = propagate_target(sc.problem.target, sc.capture.duration);
    nominal.contact = sc.problem.contact;
    nominal.approach_speed = sc.problem.approach_speed;
    Data data(*sc.model);
    const CaptureEvaluator f(*sc.model, sc.problem.frame, nominal.target, nullptr, sc.problem.joints);
    same(cj["nominal"]["M_ie"], f.mass(data, base, theta));
    const Matrix6 Linv = f.inverse_inertia(data, base, theta);
    const UncertaintySpec spec = uncertainty_spec(sc.keys);
    REQUIRE(!cj["tail"].empty());
    for (const nlohmann::json& t : cj["tail"]) {
      const SampleForce s = sample_force(Linv, draw_sample(spec, nominal, t["index"].get<std::uint64_t>()),
                                         sc.problem.law, ForceModel::Exact);
      same(t["M_ie"], s.M_ie);
      same(t["f_max"], s.f_max);
    }
  }
  // the multibody force model simulates the joints free: another joint model is refused in one line
  const auto bad = cli_sub("robust",
                           {"--config", dir / "robust.toml", "--capture-joints-deg", "10,80,-60",
                            "--force-model", "multibody", "--contact-joints", "locked", "--quiet"},
                           dir.str());
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.rfind(kErrorPrefix + " --contact-joints:", 0) == 0);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
}

}  // namespace test_objective_models
