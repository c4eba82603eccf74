// Scenarios through the library (ffsr/scenario/scenario.hpp, ffsr/jobs/scenario_run.hpp): a scenario file
// gives the same result as `ffsr-optimize --json`, every shipped scenario loads, bad keys are named.
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/closed_loop.hpp"
#include "ffsr/jobs/map.hpp"
#include "ffsr/jobs/pareto.hpp"
#include "ffsr/jobs/scenario_run.hpp"

#include "support/run_command.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace test_scenario {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const std::string kSource = FFSR_SOURCE_DIR;

/// Every number of `a` and `b` at the same place agrees within rtol 1e-9 (the same code runs in
/// both: only the last bits of a sum may differ), except wall-clock keys named `seconds`; every key
/// of one is a key of the other.
void check_same_numbers(const json& a, const json& b, const std::string& path) {
  INFO("at " << path);
  REQUIRE(a.is_number() ==
          b.is_number());  // an integer may be stored signed on one side, unsigned on the other
  if (!a.is_number()) REQUIRE(a.type() == b.type());
  if (a.is_object()) {
    REQUIRE(a.size() == b.size());
    for (const auto& [key, value] : a.items()) {
      REQUIRE(b.contains(key));
      if (key == "seconds") continue;
      check_same_numbers(value, b[key], path + "." + key);
    }
  } else if (a.is_array()) {
    REQUIRE(a.size() == b.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      check_same_numbers(a[i], b[i], path + "[" + std::to_string(i) + "]");
  } else if (a.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    CHECK(std::abs(x - y) <= 1e-9 * std::max(std::abs(x), std::abs(y)) + 1e-12);
  } else {
    CHECK(a == b);
  }
}

struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "ffsr_scenario_XXXXXX").string();
    path = mkdtemp(pattern.data());
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

/// A scenario file written from `text` (paths in it relative to robots/).
std::string write_scenario(const TempDir& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir.path / name;
  std::ofstream(p) << text;
  return p.string();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ffsr::InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

TEST_CASE("scenario: robots/paper_7dof_position.toml through the library gives the command's --json numbers",
          "[scenario]") {
  const std::string file = kSource + "/robots/paper_7dof_position.toml";
  const ffsr::Scenario sc = ffsr::load_scenario(file);
  const ffsr::ScenarioResult result = ffsr::run_scenario(sc);
  json lib = ffsr::scenario_json(sc, result, "library");

  TempDir tmp;
  const std::string out = (tmp.path / "out.json").string();
  const auto r = ffsr::test::run_command({FFSR_CLI, "--config", file, "--quiet", "--json", out});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  json cmd = json::parse(read_text(out));
  // the version is the command's; everything else, the resolved scenario included, is the same
  lib.erase("version");
  cmd.erase("version");
  check_same_numbers(lib, cmd, "result");
  CHECK(lib["optimized"]["integrated_effective_mass"].get<double>() <
        lib["baseline"]["integrated_effective_mass"].get<double>());
}

TEST_CASE("scenario: map, pareto and closed-loop through the library give the command's --json numbers",
          "[scenario][jobs]") {
  // the three jobs in-process (under the sanitizers in the sanitizer stage of .ci/run, whose command is
  // the Release stage's) against the command, on the 3-DOF paper scenario with small settings
  const std::string file = kSource + "/robots/paper_3dof.toml";
  const ffsr::Scenario sc = ffsr::load_scenario(file);
  TempDir tmp;
  const auto command_json = [&](std::vector<std::string> args) {
    const std::string out = (tmp.path / "job.json").string();
    args.insert(args.begin(), FFSR_CLI);
    args.insert(args.end(), {"--config", file, "--quiet", "--json", out});
    const auto r = ffsr::test::run_command(args);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    json j = json::parse(read_text(out));
    j.erase("version");
    return j;
  };
  const auto library = [](json j) {
    j.erase("version");
    return j;
  };

  SECTION("map: joints 2 and 3 over the full turn in 20 deg steps, two threads") {
    ffsr::MapJobOptions o;
    o.vary = {2, 3};
    o.step_deg = {20};
    o.threads = 2;
    const ffsr::MapPlan plan = ffsr::plan_map(sc, o);
    REQUIRE(plan.count() == 18 * 18);
    double largest = 0;
    std::uint64_t seen = 0;
    bool in_order = true;  // checked here, not in the sink: commit runs on a worker thread
    ffsr::MapSink sink;
    sink.commit = [&](unsigned, const ffsr::MapBlock& b) {
      in_order = in_order && b.first == seen;  // in point order, every point once
      seen += b.count;
      for (std::uint64_t i = 0; i < b.count; ++i) largest = std::max(largest, b.M_ie[i]);
    };
    const ffsr::MapRun run = ffsr::evaluate_map(sc, plan, sink);
    CHECK(in_order);
    CHECK(seen == plan.count());
    const json lib = library(ffsr::map_json(sc, run, "library"));
    check_same_numbers(lib, command_json({"map", "--vary", "2,3", "--step-deg", "20", "--threads", "2",
                                          "--csv", (tmp.path / "map.csv").string()}),
                       "map");
    CHECK(lib["max"]["integrated_effective_mass"].get<double>() == largest);  // the blocks' own maximum
  }
  SECTION("pareto: 4 levels, 2 starts") {
    ffsr::ParetoJobOptions o;
    o.levels = 4;
    o.starts = 2;
    const json lib = library(ffsr::pareto_json(sc, ffsr::pareto(sc, o), "library"));
    check_same_numbers(lib, command_json({"pareto", "--levels", "4", "--starts", "2"}), "pareto");
  }
  SECTION("closed-loop: the paper's plan") {
    const json lib = library(ffsr::closed_loop_json(sc, ffsr::closed_loop(sc, {}), "library"));
    check_same_numbers(lib, command_json({"closed-loop"}), "closed-loop");
  }
}

TEST_CASE("scenario: every robots/*.toml loads through the library", "[scenario]") {
  int count = 0;
  for (const auto& e : fs::directory_iterator(kSource + "/robots")) {
    if (e.path().extension() != ".toml") continue;
    INFO(e.path().string());
#ifndef FFSR_HAVE_GEOMETRY  // a build without ffsr::geometry refuses scenarios with shapes
    if (ffsr::scenario_uses_geometry(ffsr::read_scenario_file(e.path().string()))) continue;
#endif
    ffsr::ScenarioKeys keys = ffsr::read_scenario_file(e.path().string());
    // a stack that holds its target without the main job's keys (vyas2022_planar.toml) is detumble's
    // scenario: built as the command's detumble builds it, and the main job asks for its keys
    const bool held_only = ffsr::holds_target(keys) && !keys.given.count("task");
    if (held_only)
      CHECK_THROWS_WITH(ffsr::load_scenario(e.path().string()), Catch::Contains("missing key"));
    const ffsr::Scenario sc =
        held_only ? ffsr::build_scenario(std::move(keys), nullptr, ffsr::ScenarioScope::Configuration)
                  : ffsr::load_scenario(e.path().string());
    CHECK(sc.model->n() > 0);
    CHECK(sc.problem.model == sc.model.get());
    CHECK(sc.where == "scenario " + e.path().string());
    ++count;
  }
  CHECK(count >= 5);
  // the uncertain scenario's [uncertainty] table is read by the same reader
  const auto keys = ffsr::read_scenario_file(kSource + "/robots/paper_7dof_position_uncertain.toml");
  CHECK(ffsr::uncertainty_spec(keys).samples >= 1);
}

TEST_CASE("scenario: a Configuration scenario resolved for the main job is the Run one, the robot loaded once",
          "[scenario]") {
  for (const char* name : {"paper_7dof_position.toml", "paper_3dof_clearance.toml"}) {
    const std::string file = kSource + "/robots/" + name;
    INFO(file);
#ifndef FFSR_HAVE_GEOMETRY  // a build without ffsr::geometry refuses scenarios with shapes
    if (ffsr::scenario_uses_geometry(ffsr::read_scenario_file(file))) continue;
#endif
    const ffsr::Scenario run = ffsr::load_scenario(file);
    ffsr::Scenario sc =
        ffsr::build_scenario(ffsr::read_scenario_file(file), nullptr, ffsr::ScenarioScope::Configuration);
    CHECK(sc.scope == ffsr::ScenarioScope::Configuration);
    CHECK_FALSE(sc.geometry);
    CHECK_THROWS_AS(ffsr::plan_plain_and_optimized(sc), std::invalid_argument);  // not the main job's yet
    const ffsr::Model* model = sc.model.get();
    ffsr::resolve_run(sc);
    CHECK(sc.scope == ffsr::ScenarioScope::Run);
    CHECK(sc.model.get() == model);  // not loaded again
    CHECK(sc.problem.model == model);
    CHECK(sc.keys.urdf == run.keys.urdf);
    CHECK(sc.problem.theta == run.problem.theta);
    CHECK(sc.problem.frame == run.problem.frame);
    CHECK(sc.problem.law == run.problem.law);
    CHECK(sc.problem.approach_speed == run.problem.approach_speed);
    CHECK(sc.problem.joints.model == run.problem.joints.model);
    CHECK(sc.task.rows() == run.task.rows());
    CHECK(sc.baseline_task.rows() == run.baseline_task.rows());
    CHECK(sc.capture.duration == run.capture.duration);
    CHECK(sc.capture.step == run.capture.step);
    CHECK(sc.capture.gain == run.capture.gain);
    CHECK(sc.seed == run.seed);
    CHECK(sc.hold_base_attitude == run.hold_base_attitude);
    CHECK(static_cast<bool>(sc.geometry) == static_cast<bool>(run.geometry));
  }
  // the keys only the main job needs: a file without them loads for the one-configuration jobs, and
  // resolve_run asks for them as build_scenario does
  TempDir tmp;
  std::string text = read_text(kSource + "/robots/paper_7dof_position.toml");
  for (const char* key : {"urdf =", "duration ="}) {
    const auto at = text.find(key);
    text.erase(at, text.find('\n', at) - at);
  }
  const std::string file =
      write_scenario(tmp, "s.toml", "urdf = \"" + kSource + "/robots/paper_7dof.urdf\"\n" + text);
  ffsr::Scenario sc =
      ffsr::build_scenario(ffsr::read_scenario_file(file), nullptr, ffsr::ScenarioScope::Configuration);
  CHECK(sc.model->n() == 7);
  try {
    ffsr::resolve_run(sc);
    FAIL("resolved without duration");
  } catch (const ffsr::InputError& e) {
    CHECK(std::string(e.what()) == "scenario " + file + ": missing key 'duration'");
  }
  CHECK_THROWS_WITH(ffsr::load_scenario(file), "scenario " + file + ": missing key 'duration'");
}

TEST_CASE("scenario: a variant built again from the resolved keys of a relative file finds the same URDF",
          "[scenario]") {
  // a scenario file named by a relative path: its urdf key is joined to the file's folder once
  const std::string rel =
      fs::relative(fs::path(kSource) / "robots" / "paper_7dof_position.toml", fs::current_path()).string();
  REQUIRE(rel.find('/') != std::string::npos);
  REQUIRE(rel.front() != '/');
  const ffsr::Scenario sc = ffsr::load_scenario(rel);
  CHECK(fs::equivalent(sc.keys.urdf, fs::path(kSource) / "robots" / "paper_7dof.urdf"));
  ffsr::ScenarioKeys keys = sc.keys;
  keys.base_attitude = "hold";
  const ffsr::Scenario held = ffsr::build_scenario(std::move(keys));
  CHECK(held.keys.urdf == sc.keys.urdf);
  CHECK(held.model->n() == sc.model->n());
}

TEST_CASE("scenario: bad keys and values name the file or the key", "[scenario]") {
  TempDir tmp;
  const std::string base = read_text(kSource + "/robots/paper_3dof.toml");
  const std::string urdf = kSource + "/robots/paper_3dof.urdf";
  auto with = [&](const std::string& extra) {
    return write_scenario(
        tmp, "s.toml", "urdf = \"" + urdf + "\"\n" + extra + "\n" + [&] {
          std::string s = base;  // the same file without its urdf line
          const auto at = s.find("urdf =");
          return s.erase(at, s.find('\n', at) - at);
        }());
  };
  CHECK(error_of([&] { ffsr::load_scenario(with("colour = \"red\"")); }).find("unknown key 'colour'") !=
        std::string::npos);
  CHECK(error_of([&] {
          ffsr::read_scenario_file(with("orientation-tolerance-deg = \"fast\""));
        }).find(":2: orientation-tolerance-deg: 'fast' is not a number") != std::string::npos);
  CHECK(error_of([&] {
          ffsr::read_scenario_file(with("global-starts = \"many\""));
        }).find(":2: global-starts: 'many' is not an integer") != std::string::npos);

  ffsr::ScenarioKeys keys = ffsr::read_scenario_file(with(""));
  ffsr::override_scenario_key(keys, "duration", "-1");
  CHECK(error_of([&] { ffsr::build_scenario(keys); }) == "--duration: must be positive, got -1");
  keys = ffsr::read_scenario_file(with(""));
  keys.given.erase("step");
  CHECK(error_of([&] { ffsr::build_scenario(keys); }) ==
        "scenario " + tmp.path.string() + "/s.toml: missing key 'step'");
  keys = ffsr::read_scenario_file(with(""));
  ffsr::override_scenario_key(keys, "joints-deg", "1,2");
  CHECK(error_of([&] { ffsr::build_scenario(keys); }).rfind("--joints-deg: got 2 angles", 0) == 0);
  CHECK(error_of([&] { ffsr::override_scenario_key(keys, "target-inertia", "1,abc,3"); }) ==
        "--target-inertia: 'abc' is not a number (in '1,abc,3')");
  CHECK(error_of([&] {
          ffsr::read_scenario_text("duration = [", "scenario x.toml");
        }).rfind("scenario x.toml:1: ", 0) == 0);
  // a value of the file found bad when the scenario is built: the key as the file writes it
  const std::string lock = with("base-attitude = \"lock\"");
  CHECK(error_of([&] { ffsr::load_scenario(lock); }) ==
        "scenario " + lock + ":2: base-attitude: unknown mode 'lock'; expected 'free' or 'hold'");
  // several keys, one of them a flag's: named as flags, not located at the line of another key
  keys = ffsr::read_scenario_file(with(""));
  ffsr::override_scenario_key(keys, "restitution", "0");
  CHECK(error_of([&] { ffsr::build_scenario(keys); }).rfind("--stiffness/--exponent/--restitution: ", 0) == 0);
}

TEST_CASE("scenario: the keys a row of the main job does not take", "[scenario]") {
  using ffsr::ScenarioRow;
  using V = std::vector<std::string>;
  // paper_7dof_position: the plain run tracks the pose, the optimized and the global run the position
  ffsr::ScenarioKeys k = ffsr::read_scenario_file(kSource + "/robots/paper_7dof_position.toml");
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Plain) == V{"max-joint-rate-deg"});
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Optimized) == V{"max-joint-rate-deg"});
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Global).empty());
  ffsr::override_scenario_key(k, "base-attitude", "free");  // the base of every run is free
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Global).empty());
  ffsr::override_scenario_key(k, "base-attitude", "hold");  // the optimized run's mode
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Plain) == V{"base-attitude", "max-joint-rate-deg"});
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Optimized) == V{"max-joint-rate-deg"});
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Global) == V{"base-attitude"});
  // the keys of a task act on the rows of that task
  ffsr::override_scenario_key(k, "task-axes", "xy");
  ffsr::override_scenario_key(k, "orientation-tolerance-deg", "1");
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Plain) ==
        V{"task-axes", "base-attitude", "max-joint-rate-deg"});
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Global) == V{"orientation-tolerance-deg", "base-attitude"});
  // multibody-force: the global run's objective; the paper's method descends M_ie
  ffsr::override_scenario_key(k, "objective", "multibody-force");
  ffsr::override_scenario_key(k, "joint-stiffness", "10");
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Optimized) ==
        V{"orientation-tolerance-deg", "objective", "max-joint-rate-deg", "joint-stiffness"});
  CHECK(ffsr::keys_not_applied(k, ScenarioRow::Global) == V{"orientation-tolerance-deg", "base-attitude"});
}

}  // namespace test_scenario
