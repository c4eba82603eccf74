// The command-line conventions over every subcommand (docs/command.md, "Conventions"): each key of
// the library's key table that a subcommand accepts changes its result or is refused; --quiet,
// --json FILE and --json - everywhere (standard output then holds one JSON document and nothing
// else); a bad value in a scenario file names the file, the key and its line; an unknown key names
// the nearest known one; --config with --urdf keeps the file's other keys in every subcommand.
#include "support/command.hpp"

#include "ffsr/scenario/scenario.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

// Small runs only (the built-in 3-DOF scenario, a few samples, coarse grids): the cases run in CI.

namespace test_conventions {

using ffsr::test::Args;
using ffsr::test::cli;
using ffsr::test::CommandResult;
using ffsr::test::kSource;
using ffsr::test::kUrdf3;
using nlohmann::json;

/// A subcommand ("" for the main job) and the arguments of a small run of it.
struct Sub {
  std::string name;
  Args base;
};

/// Files the cases use, written once into a scratch folder that lives for the test run.
struct Files {
  ffsr::test::TempDir dir;
  std::string heavy_urdf, bad_inertia_urdf, uncertain_toml, post_capture_toml;
  Files() {
    const std::string urdf = ffsr::test::read_file(kUrdf3);
    // the same robot with a heavier first link: another URDF for the urdf key
    heavy_urdf = dir.str() + "/heavy.urdf";
    std::ofstream(heavy_urdf) << std::regex_replace(urdf, std::regex("<mass value=\"5\"/>"),
                                                    "<mass value=\"10\"/>");
    // link1's moments break the triangle inequality (0.01 + 0.82 < 1.0): the inertia-repair key's case
    bad_inertia_urdf = dir.str() + "/bad_inertia.urdf";
    std::ofstream(bad_inertia_urdf) << std::regex_replace(
        urdf, std::regex("ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.82\" iyz=\"0\" izz=\"0.82\""),
        "ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.82\" iyz=\"0\" izz=\"1.0\"");
    // the built-in scenario with an [uncertainty] table: robust's input
    std::string toml = ffsr::test::read_file(kSource + "/robots/paper_3dof.toml");
    toml = std::regex_replace(toml, std::regex("urdf = \"paper_3dof.urdf\""), "urdf = \"" + kUrdf3 + "\"");
    // the built-in scenario with joint torque limits: the post-capture constraints' input
    post_capture_toml = dir.str() + "/post_capture.toml";
    std::ofstream(post_capture_toml) << toml << "\njoint-torque-limit = 20\n";
    uncertain_toml = dir.str() + "/uncertain.toml";
    std::ofstream(uncertain_toml) << toml
                                  << "\n[uncertainty]\nsamples = 8\nseed = 3\n"
                                     "target-mass = { law = \"uniform\", relative = 0.1 }\n";
  }
};

const Files& files() {
  static const Files f;
  return f;
}

const std::string kPosition7 = kSource + "/robots/paper_7dof_position.toml";
const std::string kUncertain7 = kSource + "/robots/paper_7dof_position_uncertain.toml";
const std::string kDetumble7 = kSource + "/robots/paper_7dof_detumble.toml";

/// Every subcommand with a small run of it: on the built-in 3-DOF scenario, or (`seven_dof`) on the
/// paper's 7-DOF position scenario, whose plain run tracks the pose.
std::vector<Sub> subcommands(bool seven_dof = false) {
  if (seven_dof)
    return {{"", {"--config", kPosition7, "--global", "false"}},
            {"inspect", {"--config", kPosition7}},
            {"contact", {"--config", kPosition7}},
            {"xi", {"--config", kPosition7, "--points", "3"}},
            {"map", {"--config", kPosition7, "--vary", "1", "--step-deg", "90", "--csv", "map.csv"}},
            {"robust", {"--config", kUncertain7, "--global", "false", "--samples", "4"}},
            {"pareto", {"--config", kPosition7, "--levels", "2", "--starts", "2", "--global-starts", "2"}},
            {"closed-loop", {"--config", kPosition7, "--control-rate", "5", "--estimate-rate", "1"}},
            {"detumble", {"--config", kDetumble7}}};
  return {{"", {"--global", "false"}},
          {"inspect", {}},
          {"contact", {}},
          {"xi", {"--points", "3"}},
          {"map", {"--vary", "1", "--step-deg", "90", "--csv", "map.csv"}},
          {"robust", {"--config", files().uncertain_toml, "--global", "false"}},
          {"pareto", {"--levels", "2", "--starts", "2", "--global-starts", "2"}},
          {"closed-loop", {"--control-rate", "5", "--estimate-rate", "1"}},
          {"detumble", {"--joint-torque-limit", "20"}}};
}

/// The arguments that set a key to another value (`alt`, with the other keys it needs) and what the
/// base run needs for the key to matter (`context`: global keys need the global run, shape keys a
/// shape, and so on). Built-in 3-DOF scenario.
struct KeyCase {
  Args alt;
  Args context;
  bool seven_dof = false;  ///< on the 7-DOF position scenario (tasks, orientations)
  bool limit = false;      ///< a tolerance: the alternative value makes the run fail, which is its effect
  /// subcommands whose run ends with a verdict of the problem (exit 3) under the alternative value:
  /// that verdict is the key's effect there
  std::set<std::string> verdict_in = {};
  /// subcommands that report the optimum only, where the alternative leads the search to the same
  /// optimum (more starts or another seed of a converged search; F_max, whose minimum is M_ie's on a
  /// single body): the main job, which reports the search and its objective, must show the change,
  /// and its global run must end on the same configuration under both values, or the subcommand's
  /// unchanged result means that it ignored the key
  std::set<std::string> same_optimum_in = {};
};

/// The end-effector's attitude of the 7-DOF scenario's start, turned by 2 deg about z: a final
/// orientation of the pose task the arm can reach.
std::string turned_final_rpy() {
  const json j = ffsr::test::parse_json(cli({"inspect", "--config", kPosition7, "--json", "-"}));
  const std::vector<double> rpy = j.at("end_effector_rpy_deg").get<std::vector<double>>();
  return std::to_string(rpy[0]) + "," + std::to_string(rpy[1]) + "," + std::to_string(rpy[2] + 2.0);
}

const std::map<std::string, KeyCase>& key_cases() {
  const Args bus{"--bus-mass", "500", "--bus-inertia", "200,200,200"};
  // closed-loop flies the global run's plan with --plan global (the other subcommands do not take it)
  const Args global{"--global", "true", "--global-starts", "2", "--plan", "global"};
  const Args sphere{"--target-shape", "sphere", "--target-size", "0.29154759474226504"};
  // the post-capture phase: the main job runs it for each run when a Detumble key is given; the built-in
  // robot's URDF gives no <limit effort>, so every case names the joint torque limit
  const Args torque{"--joint-torque-limit", "20"};
  const Args wheels{"--joint-torque-limit", "20",  "--base-actuator",  "reaction-wheels",
                    "--wheel-torque",       "0.2", "--wheel-momentum", "25",
                    "--stop-stack-spin",    "true"};
  const Args thrusters{"--joint-torque-limit", "20",   "--base-actuator",   "thrusters",
                       "--thruster-force",     "2",    "--thruster-torque", "0.2",
                       "--stop-stack-spin",    "true", "--target-velocity", "0.001,0,0"};
  const Args wheels_kept{"--joint-torque-limit", "20",  "--base-actuator",  "reaction-wheels",
                         "--wheel-torque",       "0.2", "--wheel-momentum", "25"};
  const Args held{"--joint-torque-limit", "20", "--grasp-after", "held"};
  Args post_capture{"--config", files().post_capture_toml};
  post_capture.insert(post_capture.end(), global.begin(), global.end());
  static const std::map<std::string, KeyCase> cases = {
      {"urdf", {{"--urdf", files().heavy_urdf, "--joints-deg", "0,150,-100"}, {}}},
      {"end-effector", {{"--end-effector", "link3"}, {}}},
      {"bus-mass", {bus, {}}},
      {"bus-inertia", {{"--bus-inertia", "300,300,300"}, bus}},
      {"bus-com", {{"--bus-com", "0.1,0,0"}, bus}},
      {"mount-xyz", {{"--mount-xyz", "0.1,0,0"}, bus}},
      {"mount-rpy-deg", {{"--mount-rpy-deg", "0,0,5"}, bus}},
      // with two joints left the M_ie optimum also has the least base rate: pareto says so (exit 3)
      {"lock-joints",
       {{"--lock-joints", "joint3=-1.7453292519943295", "--joints-deg", "0,150"},
        {"--gain", "0"},
        false,
        false,
        {"pareto"}}},
      {"inertia-repair",
       {{"--inertia-repair", "balance"}, {"--urdf", files().bad_inertia_urdf, "--joints-deg", "0,150,-100"}}},
      // link3 has 4 kg and moments (0, 0.09, 0.09) kg m^2: raised to these floors
      {"min-mass", {{"--min-mass", "4.5"}, {}}},
      {"min-inertia", {{"--min-inertia", "0.1"}, {}}},
      {"end-effector-offset", {{"--end-effector-offset", "0.05,0,0"}, {}}},
      {"joints-deg", {{"--joints-deg", "0,140,-100"}, {}}},
      {"base-position", {{"--base-position", "0.05,0,0"}, {}}},
      {"base-rpy-deg", {{"--base-rpy-deg", "0,0,3"}, {}}},
      {"target-mass", {{"--target-mass", "150"}, {}}},
      // r_tp x u = (0, 0, -0.15): only the moment about z enters M_ie (Eq. 14)
      {"target-inertia", {{"--target-inertia", "100,100,50"}, {}}},
      {"target-position", {{"--target-position", "2.7,1.45,0"}, sphere}},
      {"target-rpy-deg", {{"--target-rpy-deg", "0,0,3"}, {}}},
      {"target-angular-velocity-deg", {{"--target-angular-velocity-deg", "0,0,3"}, {}}},
      {"target-velocity", {{"--target-velocity", "0.001,0,0"}, {}}},
      {"contact-offset", {{"--contact-offset", "-0.25,0.1,0"}, {}}},
      {"normal", {{"--normal", "1,0.1,0"}, {}}},
      // the contact law acts on detumble with grasp-after = contact only (refused there without it)
      {"model", {{"--model", "hunt-crossley"}, {"--grasp-after", "contact"}}},
      {"stiffness", {{"--stiffness", "2e9"}, {"--grasp-after", "contact"}}},
      {"exponent", {{"--exponent", "1.2"}, {"--grasp-after", "contact"}}},
      {"restitution", {{"--restitution", "0.5"}, {"--grasp-after", "contact"}}},
      {"approach-speed", {{"--approach-speed", "0.3"}, {}}},
      {"task", {{"--task", "pose"}, {}, true}},
      // three rows on three joints: no null space, so the gain must be 0
      {"task-axes", {{"--task-axes", "xyz"}, {"--gain", "0"}}},
      {"baseline-task", {{"--baseline-task", "position"}, {}, true}},
      {"final-rpy-deg", {{"--final-rpy-deg", turned_final_rpy()}, {}, true}},
      {"duration", {{"--duration", "170"}, {}}},
      {"step", {{"--step", "0.2"}, {}}},
      {"gain", {{"--gain", "-0.02"}, {}}},
      {"feedback", {{"--feedback", "2"}, {}}},
      {"tolerance", {{"--tolerance", "1e-15"}, {}, false, true}},
      {"orientation-tolerance-deg", {{"--orientation-tolerance-deg", "1e-14"}, {}, true, true}},
      {"objective", {{"--objective", "exact-force"}, global, false, false, {}, {"closed-loop"}}},
      {"base-attitude", {{"--base-attitude", "hold", "--task-axes", "x"}, {"--task-axes", "x"}}},
      {"global", {{"--global", "true", "--global-starts", "2"}, {"--global", "false"}}},
      {"seed", {{"--seed", "7"}, global, false, false, {}, {"closed-loop"}}},
      {"max-joint-rate-deg", {{"--max-joint-rate-deg", "5"}, global}},
      {"global-starts",
       {{"--global-starts", "1"}, global, false, false, {}, {"robust", "pareto", "closed-loop"}}},
      {"max-base-rate-deg", {{"--max-base-rate-deg", "0.01"}, global}},
      {"reconfigure", {{"--reconfigure", "always"}, global}},
      {"reconfigure-duration",
       {{"--reconfigure-duration", "30"},
        {"--global", "true", "--global-starts", "2", "--plan", "global", "--reconfigure", "always"}}},
      {"contact-joints", {{"--contact-joints", "locked"}, {}}},
      {"armature", {{"--armature", "0.5"}, {"--contact-joints", "armature"}}},
      {"joint-stiffness", {{"--joint-stiffness", "1000"}, {}}},
      {"joint-damping", {{"--joint-damping", "100"}, {}}},
      {"target-shape", {sphere, {}}},
      // a box whose face x = -0.25 holds the contact point, made wider towards the arm
      {"target-size",
       {{"--target-size", "0.5,2,0.4"}, {"--target-shape", "box", "--target-size", "0.5,0.4,0.4"}}},
      // the sphere's centre moved so that the contact point stays on its surface
      {"target-shape-offset", {{"--target-shape-offset", "-0.5,0,0"}, sphere}},
      {"link-radius", {{"--link-radius", "0.08"}, sphere}},
      {"bus-box", {{"--bus-box", "1,1,1"}, sphere}},
      {"clearance", {{"--clearance", "0.09"}, sphere}},
      {"contact-exemption", {{"--contact-exemption", "0.5"}, sphere}},
      // the post-capture phase (detumble; the main job's post_capture): on the built-in robot the
      // braking needs about 3 N m
      {"joint-torque-limit", {{"--joint-torque-limit", "1"}, torque}},
      {"base-actuator",
       {{"--base-actuator", "thrusters", "--thruster-force", "2", "--thruster-torque", "0.2"},
        {"--joint-torque-limit", "20", "--stop-stack-spin", "true"}}},
      {"wheel-torque", {{"--wheel-torque", "0.5"}, wheels}},
      // the stack's angular momentum, 3.49 N m s, does not fit in wheels of 2 N m s per axis
      {"wheel-momentum", {{"--wheel-momentum", "2"}, wheels}},
      // the stack's linear momentum (a moving target, 0.2 N s) is what the thrusters' force removes
      {"thruster-force", {{"--thruster-force", "0.001"}, thrusters}},
      {"thruster-torque", {{"--thruster-torque", "0.5"}, thrusters}},
      {"rest-rate-deg", {{"--rest-rate-deg", "0.1"}, torque}},
      {"detumble-horizon", {{"--detumble-horizon", "0.1"}, torque, false, true}},
      {"detumble-tick", {{"--detumble-tick", "0.02"}, torque}},
      // the gripper's load bound by the controller (about 20 N and 30 N m at the 20 N m joints' braking)
      {"gripper-force-limit", {{"--gripper-force-limit", "5"}, torque}},
      {"gripper-moment-limit", {{"--gripper-moment-limit", "5"}, torque}},
      {"detumble-dwell", {{"--detumble-dwell", "1"}, torque}},
      {"detumble-max-decay", {{"--detumble-max-decay", "2"}, torque}},
      {"detumble-max-base-decay", {{"--detumble-max-base-decay", "0.5"}, thrusters}},
      {"stop-stack-spin", {{"--stop-stack-spin", "true"}, wheels_kept}},
      // the grasp after the Hertz contact run: another lock impulse and start state
      {"grasp-after", {{"--grasp-after", "contact"}, torque}},
      // the stack that holds its target from the start (the built-in target welded where it is): its
      // start rates
      {"start-joint-rates-deg", {{"--start-joint-rates-deg", "1,-2,3"}, held}},
      {"start-base-velocity", {{"--start-base-velocity", "0.01,0,0"}, held}},
      {"start-base-angular-velocity-deg", {{"--start-base-angular-velocity-deg", "0,0,0.5"}, held}},
      // the global search's post-capture constraints (20 N m joints): the impact-best capture needs
      // 3.59 N m and 1.57 N (another capture is chosen); no candidate rests within 3.3 s or holds the
      // gripper's moment within 1 N m (refused, naming the key, with the least each candidate reached)
      {"max-time-to-rest", {{"--max-time-to-rest", "3.3"}, post_capture}},
      {"max-peak-joint-torque", {{"--max-peak-joint-torque", "3"}, post_capture}},
      {"max-gripper-force", {{"--max-gripper-force", "1.55"}, post_capture}},
      {"max-gripper-moment", {{"--max-gripper-moment", "1"}, post_capture}},
  };
  return cases;
}

/// The flags `sub` lists in its --help.
std::set<std::string> accepted_flags(const std::string& sub) {
  const CommandResult r = sub.empty() ? cli({"--help"}) : cli({sub, "--help"});
  REQUIRE(r.exit_code == 0);
  std::set<std::string> flags;
  const std::regex flag("(--[a-z][a-z0-9-]*)");
  for (std::sregex_iterator it(r.out.begin(), r.out.end(), flag), end; it != end; ++it)
    flags.insert((*it)[1]);
  return flags;
}

/// `args` without the flags `sub` does not accept (each flag takes one value here).
Args only_accepted(const Args& args, const std::set<std::string>& accepted) {
  Args out;
  for (size_t i = 0; i + 1 < args.size(); i += 2)
    if (accepted.count(args[i])) {
      out.push_back(args[i]);
      out.push_back(args[i + 1]);
    }
  return out;
}

/// The command line of `sub` with `args` and --json - --quiet. A flag of `args` replaces the same
/// flag of the subcommand's base arguments, and a later flag of `args` an earlier one (each flag
/// takes one value here): the command refuses a flag given twice.
Args command_line(const Sub& sub, const Args& args) {
  std::vector<std::pair<std::string, std::string>> flags;
  auto set = [&flags](const Args& from) {
    for (size_t i = 0; i + 1 < from.size(); i += 2) {
      auto it = std::find_if(flags.begin(), flags.end(), [&](const auto& f) { return f.first == from[i]; });
      if (it != flags.end())
        it->second = from[i + 1];
      else
        flags.emplace_back(from[i], from[i + 1]);
    }
  };
  set(sub.base);
  set(args);
  Args a;
  if (!sub.name.empty()) a.push_back(sub.name);
  for (const auto& [flag, value] : flags) {
    a.push_back(flag);
    a.push_back(value);
  }
  a.insert(a.end(), {"--json", "-", "--quiet"});
  return a;
}

/// Runs every command line of `results` (the keys), two at a time, each in a scratch folder.
void run_all(std::map<Args, CommandResult>& results) {
  std::vector<std::pair<const Args*, CommandResult*>> jobs;
  for (auto& [args, r] : results) jobs.emplace_back(&args, &r);
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < jobs.size(); i = next++) *jobs[i].second = cli(*jobs[i].first);
  };
  std::thread other(worker);
  worker();
  other.join();
}

/// The result of a run without what echoes the inputs (the resolved scenario, the parameters, the
/// version) or measures the machine (wall-clock seconds): what the key must change.
json result_of(const CommandResult& r) {
  json j = json::parse(r.out);
  for (const char* echo : {"version", "scenario", "parameters", "urdf", "joints_deg"}) j.erase(echo);
  std::function<void(json&)> strip = [&](json& x) {
    if (x.is_object()) {
      x.erase("seconds");
      for (auto& [k, v] : x.items()) strip(v);
    } else if (x.is_array()) {
      for (auto& v : x) strip(v);
    }
  };
  strip(j);
  return j;
}

/// Whether the global run of two main-job runs ended on different capture configurations (by more
/// than 1e-6 deg in a joint, or one of them failed): a subcommand that flies or starts from that
/// optimum must then report another result.
bool global_optimum_moved(const CommandResult& a, const CommandResult& b) {
  if (a.exit_code != 0 || b.exit_code != 0) return true;
  const auto qa = json::parse(a.out).at("global").at("capture_configuration_deg").get<std::vector<double>>();
  const auto qb = json::parse(b.out).at("global").at("capture_configuration_deg").get<std::vector<double>>();
  if (qa.size() != qb.size()) return true;
  for (size_t i = 0; i < qa.size(); ++i)
    if (std::abs(qa[i] - qb[i]) > 1e-6) return true;
  return false;
}

bool refused(const CommandResult& r, const std::string& flag) {
  return r.exit_code == 2 && r.err.find(flag) != std::string::npos &&
         std::count(r.err.begin(), r.err.end(), '\n') == 1;
}

}  // namespace test_conventions

using namespace test_conventions;

TEST_CASE("every key of the table has a case in this test", "[cli][conventions]") {
  for (const ffsr::ScenarioKey& key : ffsr::scenario_keys()) {
    INFO("key '" << key.name << "': add an alternative value to key_cases()");
    CHECK(key_cases().count(key.name) == 1);
  }
}

TEST_CASE("the main job takes every key of the post-capture phase (the walk below: each changes it)",
          "[cli][conventions]") {
  const std::set<std::string> flags = accepted_flags("");
  int keys = 0;
  for (const ffsr::ScenarioKey& key : ffsr::scenario_keys()) {
    if (key.group != ffsr::KeyGroup::Detumble) continue;
    INFO(key.name);
    CHECK(flags.count("--" + key.name) == 1);
    ++keys;
  }
  // grasp-after and the held stack's three start rates with the fifteen of the limits, the actuator,
  // the law and the run
  CHECK(keys == 19);
}

TEST_CASE("each key a subcommand accepts changes its result, or the subcommand refuses it",
          "[cli][conventions]") {
  // the runs first (two at a time, each distinct run once), then the verdicts
  struct Check {
    Sub sub;
    std::string where, flag;
    bool accepted, limit, verdict, same_optimum;
    Args before, after;
    /// same_optimum: the main job's runs with the same two settings, whose global optimum must not
    /// move where the subcommand's result does not change
    Args main_before, main_after;
  };
  std::vector<Check> checks;
  std::map<Args, CommandResult> results;
  for (const bool seven : {false, true})
    for (const Sub& sub : subcommands(seven)) {
      const std::set<std::string> accepted = accepted_flags(sub.name);
      for (const ffsr::ScenarioKey& key : ffsr::scenario_keys()) {
        const auto it = key_cases().find(key.name);
        if (it == key_cases().end() || it->second.seven_dof != seven) continue;
        const KeyCase& c = it->second;
        Check k{sub,
                (sub.name.empty() ? "main job" : sub.name) + " --" + key.name,
                "--" + key.name,
                accepted.count("--" + key.name) > 0,
                c.limit,
                c.verdict_in.count(sub.name) > 0,
                c.same_optimum_in.count(sub.name) > 0,
                {},
                {},
                {},
                {}};
        const Args context = k.accepted ? only_accepted(c.context, accepted) : Args{};
        k.before = command_line(sub, context);
        Args changed = context;
        // a key the subcommand does not take: its flag alone (the other flags of its case, which the
        // subcommand may refuse first, would hide whether this one is refused)
        const auto own_end = k.accepted ? c.alt.end()
                                        : std::find_if(c.alt.begin() + 1, c.alt.end(), [](const std::string& a) {
                                            return a.rfind("--", 0) == 0;
                                          });
        changed.insert(changed.end(), c.alt.begin(), own_end);
        k.after = command_line(sub, changed);
        if (k.accepted) results[k.before];
        results[k.after];
        if (k.accepted && k.same_optimum) {
          const Sub main_job = subcommands(seven).front();  // a copy: the list is a temporary
          const Args main_context = only_accepted(c.context, accepted_flags(main_job.name));
          Args main_changed = main_context;
          main_changed.insert(main_changed.end(), c.alt.begin(), c.alt.end());
          k.main_before = command_line(main_job, main_context);
          k.main_after = command_line(main_job, main_changed);
          results[k.main_before];
          results[k.main_after];
        }
        checks.push_back(std::move(k));
      }
    }
  run_all(results);
  // a context the subcommand refuses (the shapes without a clearance, say) cannot show the key's
  // effect there: such a key is checked again without the context
  std::map<Args, CommandResult> again;
  for (Check& k : checks) {
    if (!k.accepted) continue;
    const CommandResult& before = results.at(k.before);
    const CommandResult& after = results.at(k.after);
    if (before.exit_code != 2 || after.exit_code != 2 || refused(after, k.flag) ||
        k.before == command_line(k.sub, {}))
      continue;
    k.before = command_line(k.sub, {});
    k.after = command_line(k.sub, key_cases().at(k.flag.substr(2)).alt);
    again[k.before];
    again[k.after];
  }
  run_all(again);
  results.insert(again.begin(), again.end());
  std::string problems;
  for (const Check& k : checks) {
    const CommandResult& after = results.at(k.after);
    if (!k.accepted) {  // refused by the parser, naming the flag
      if (!refused(after, k.flag))
        problems += k.where + ": not accepted, but not refused either: " + after.err + "\n";
      continue;
    }
    const CommandResult& before = results.at(k.before);
    if (refused(after, k.flag)) continue;                         // refused by the library, naming the key
    if (before.exit_code != 0 && after.exit_code == 0) continue;  // the key makes the run work
    if (k.limit && before.exit_code == 0 && after.exit_code != 0) continue;    // a tolerance the run misses
    if (k.verdict && before.exit_code == 0 && after.exit_code == 3) continue;  // the problem's verdict
    if (before.exit_code != 0 || after.exit_code != 0)
      problems += k.where + ": exit " + std::to_string(before.exit_code) + " -> " +
                  std::to_string(after.exit_code) + ": " + before.err + " / " + after.err + "\n";
    else if (result_of(before) == result_of(after) &&
             (!k.same_optimum || global_optimum_moved(results.at(k.main_before), results.at(k.main_after))))
      problems += k.where + ": accepted and ignored\n";
  }
  INFO(problems);
  CHECK(problems.empty());
}

TEST_CASE("a key of one kind of task is refused where no run has that task", "[cli][conventions]") {
  // the walk above gives the pose task's keys on the 7-DOF position scenario, whose plain run tracks
  // the pose; here the same keys where both runs track a position (the built-in 3-DOF scenario), and
  // the position task's axes where both track the pose
  const std::string pose7 = kSource + "/robots/paper_7dof_pose.toml";
  struct Where {
    std::vector<Sub> subs;
    Args alt;
    std::string says;
  };
  std::vector<Sub> on_pose;
  for (const Sub& sub : subcommands(true)) {
    Sub s = sub;
    for (std::string& a : s.base)
      if (a == kPosition7) a = pose7;
    if (std::find(s.base.begin(), s.base.end(), kUncertain7) == s.base.end()) on_pose.push_back(s);
  }
  const std::vector<Where> cases = {
      {subcommands(false), {"--final-rpy-deg", "0,0,10"}, "acts on the pose task only"},
      {subcommands(false), {"--orientation-tolerance-deg", "1"}, "acts on the pose task only"},
      {on_pose, {"--task-axes", "xy"}, "acts on the position task only"}};
  int refusals = 0;
  for (const Where& w : cases)
    for (const Sub& sub : w.subs) {
      if (!accepted_flags(sub.name).count(w.alt[0])) continue;  // the parser refuses it (the walk above)
      const CommandResult r = cli(command_line(sub, w.alt));
      INFO((sub.name.empty() ? "main job" : sub.name)
           << " " << w.alt[0] << ": exit " << r.exit_code << ": " << r.err);
      CHECK(refused(r, w.alt[0]));
      CHECK(r.err.find(w.says) != std::string::npos);
      CHECK(r.out.empty());
      ++refusals;
    }
  // the main job, map, robust and pareto take these keys at least
  CHECK(refusals >= 8);
}

TEST_CASE("conventions: --quiet, --json FILE and --json - on every subcommand", "[cli][conventions]") {
  for (const Sub& sub : subcommands()) {
    INFO(sub.name);
    ffsr::test::TempDir tmp;
    Args a;
    if (!sub.name.empty()) a.push_back(sub.name);
    a.insert(a.end(), sub.base.begin(), sub.base.end());
    Args to_file = a, to_stdout = a;
    to_file.insert(to_file.end(), {"--quiet", "--json", "out.json"});
    to_stdout.insert(to_stdout.end(), {"--quiet", "--json", "-"});
    const CommandResult f = cli(to_file, tmp.str());
    INFO(f.err);
    REQUIRE(f.exit_code == 0);
    CHECK(f.err.empty());  // --quiet: nothing on standard error
    const json written = ffsr::test::read_json_file(tmp.str() + "/out.json");
    CHECK(written.is_object());
    const CommandResult s = cli(to_stdout, tmp.str());
    REQUIRE(s.exit_code == 0);
    CHECK(s.err.empty());  // --quiet: the table that would go to standard error is not written either
    json j;
    REQUIRE_NOTHROW(j = json::parse(s.out));  // one JSON document and nothing else
    CHECK(j.is_object());
    CHECK(j.contains("version"));
  }
}

TEST_CASE("conventions: --json - alone is the only thing on standard output of every subcommand",
          "[cli][conventions]") {
  // no other output (the map's --csv dropped) and no --quiet: the table and the progress go elsewhere
  std::vector<Sub> subs = subcommands();
  subs.push_back({"robust", {"--merge", "shard.json"}});  // a summary written by the robust run above
  for (const Sub& sub : subs) {
    INFO((sub.name.empty() ? "main job" : sub.name));
    ffsr::test::TempDir tmp;
    if (!sub.base.empty() && sub.base.front() == "--merge") {  // the shard to merge
      const Sub& run = subs[5];
      REQUIRE(run.name == "robust");
      Args a{"robust"};
      a.insert(a.end(), run.base.begin(), run.base.end());
      a.insert(a.end(), {"--quiet", "--json", "shard.json"});
      REQUIRE(cli(a, tmp.str()).exit_code == 0);
    }
    Args a;
    if (!sub.name.empty()) a.push_back(sub.name);
    for (size_t i = 0; i < sub.base.size(); ++i) {
      if (sub.base[i] == "--csv") {
        ++i;
        continue;
      }
      a.push_back(sub.base[i]);
    }
    a.insert(a.end(), {"--json", "-"});
    const CommandResult r = cli(a, tmp.str());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    json j;
    REQUIRE_NOTHROW(j = json::parse(r.out));  // one JSON document and nothing else
    CHECK(j.is_object());
    CHECK(j.contains("version"));
    CHECK_FALSE(r.err.empty());  // the table went to standard error
  }
}

TEST_CASE("conventions: map without --csv evaluates the grid for its summary", "[cli][conventions]") {
  ffsr::test::TempDir tmp;
  const Args grid{"map", "--vary", "1,2", "--step-deg", "30", "--quiet"};
  Args with_csv = grid, without = grid;
  with_csv.insert(with_csv.end(), {"--json", "a.json", "--csv", "map.csv"});
  without.insert(without.end(), {"--json", "b.json"});
  REQUIRE(cli(with_csv, tmp.str()).exit_code == 0);
  REQUIRE(cli(without, tmp.str()).exit_code == 0);
  json a = ffsr::test::read_json_file(tmp.str() + "/a.json"),
       b = ffsr::test::read_json_file(tmp.str() + "/b.json");
  a.erase("seconds");
  b.erase("seconds");
  CHECK(a == b);  // the same summary, with and without the map's file
  // the extremes against the CSV's rows: the summary is of the points evaluated, not of a file
  std::ifstream csv(tmp.str() + "/map.csv");
  std::string line;
  std::getline(csv, line);  // header
  double max_M = -1, min_M = 1e300;
  size_t rows = 0;
  while (std::getline(csv, line)) {
    const size_t c2 = line.find(',', line.find(',') + 1);
    const double M = std::stod(line.substr(c2 + 1, line.find(',', c2 + 1) - c2 - 1));
    max_M = std::max(max_M, M);
    min_M = std::min(min_M, M);
    ++rows;
  }
  CHECK(rows == 144);  // 12 x 12 points
  CHECK(b.at("max").at("integrated_effective_mass").get<double>() == max_M);
  CHECK(b.at("min").at("integrated_effective_mass").get<double>() == min_M);
  // no output at all: the summary is the table on standard output
  Args plain = grid;
  plain.pop_back();  // --quiet
  const CommandResult t = cli(plain, tmp.str());
  REQUIRE(t.exit_code == 0);
  CHECK(t.out.find("max M_ie") != std::string::npos);
  CHECK(t.out.find("wrote") == std::string::npos);
}

TEST_CASE("conventions: --csv - is the only thing on standard output, where a subcommand has series",
          "[cli][conventions]") {
  for (const Sub& sub : subcommands()) {
    if (sub.name == "inspect") continue;  // one configuration: no series
    INFO(sub.name);
    ffsr::test::TempDir tmp;
    Args a;
    if (!sub.name.empty()) a.push_back(sub.name);
    for (size_t i = 0; i < sub.base.size(); ++i) {  // the map's --csv replaced by '-'
      if (sub.base[i] == "--csv") {
        ++i;
        continue;
      }
      a.push_back(sub.base[i]);
    }
    a.insert(a.end(), {"--quiet", "--csv", "-", "--json", "out.json"});
    const CommandResult r = cli(a, tmp.str());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    REQUIRE_FALSE(r.out.empty());
    CHECK(r.out.find('{') == std::string::npos);  // no JSON, no table: the CSV's lines only
    CHECK(std::count(r.out.begin(), r.out.end(), ',') > 0);
  }
}

TEST_CASE("a bad value in a scenario file names the file, the key and its line", "[cli][conventions]") {
  ffsr::test::TempDir tmp;
  std::string toml = ffsr::test::read_file(kSource + "/robots/paper_3dof.toml");
  toml = std::regex_replace(toml, std::regex("urdf = \"paper_3dof.urdf\""), "urdf = \"" + kUrdf3 + "\"");
  const std::string file = tmp.str() + "/s.toml";
  SECTION("a value of the wrong type") {
    std::ofstream(file) << std::regex_replace(toml, std::regex("duration = 180"), "duration = \"long\"");
    const CommandResult r = cli({"--config", file, "--global", "false", "--quiet"});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("scenario " + file + ":27: duration: 'long' is not a number") != std::string::npos);
  }
  SECTION("a value out of range, found when the scenario is built") {
    std::ofstream(file) << std::regex_replace(toml, std::regex("duration = 180"), "duration = -5");
    for (const Args& a :
         {Args{"--config", file, "--global", "false", "--quiet"}, Args{"pareto", "--config", file}}) {
      const CommandResult r = cli(a);
      CHECK(r.exit_code == 2);
      CHECK(r.err.find("scenario " + file + ":27: duration: must be positive") != std::string::npos);
    }
  }
  SECTION("a flag's bad value names the flag only") {
    std::ofstream(file) << toml;
    const CommandResult r = cli({"--config", file, "--duration", "-5", "--global", "false", "--quiet"});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("error: --duration: must be positive") != std::string::npos);
  }
  SECTION("an unknown key names the nearest known one") {
    std::ofstream(file) << toml << "clearence = 0.1\n";
    const CommandResult r = cli({"--config", file, "--global", "false", "--quiet"});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("unknown key 'clearence' (did you mean 'clearance'?)") != std::string::npos);
    const CommandResult f = cli({"--clearence", "0.1"});
    CHECK(f.exit_code == 2);
    CHECK(f.err.find("did you mean --clearance?") != std::string::npos);
  }
}

TEST_CASE("conventions: --config with --urdf keeps the file's end-effector and joints in every subcommand",
          "[cli][conventions]") {
  // the file names end-effector = "ee" and its joints; --urdf gives the same robot under another
  // path: every subcommand evaluates the file's end-effector, as the main job does
  ffsr::test::TempDir tmp;
  const std::string copy = tmp.str() + "/copy.urdf";
  std::ofstream(copy) << ffsr::test::read_file(kUrdf3);
  const std::string scenario = kSource + "/robots/paper_3dof.toml";
  const json a = ffsr::test::parse_json(cli({"inspect", "--config", scenario, "--json"}));
  const json b = ffsr::test::parse_json(cli({"inspect", "--config", scenario, "--urdf", copy, "--json"}));
  CHECK(b.at("end_effector") == a.at("end_effector"));
  CHECK(b.at("integrated_effective_mass") == a.at("integrated_effective_mass"));
  const json c =
      ffsr::test::parse_json(cli({"contact", "--config", scenario, "--urdf", copy, "--json", "-"}));
  CHECK(c.at("integrated_effective_mass").get<double>() == a.at("integrated_effective_mass").get<double>());
  const json m = ffsr::test::parse_json(
      cli({"--config", scenario, "--urdf", copy, "--global", "false", "--quiet", "--json", "-"}));
  CHECK(m.at("scenario").at("end_effector") == a.at("end_effector"));
}

TEST_CASE("conventions: a row of the main job says which keys of the scenario it does not take",
          "[cli][conventions]") {
  // base-attitude = hold is the optimized run's mode: the plain and the global row run as without it
  // (the global row turns the base by degrees), and say so; max-joint-rate-deg acts on the global row
  ffsr::test::TempDir tmp;
  auto run = [&](const Args& extra, const std::string& name) {
    Args a{"--config", kPosition7, "--json", name};
    a.insert(a.end(), extra.begin(), extra.end());
    const CommandResult r = cli(a, tmp.str());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    return std::make_pair(r.out, ffsr::test::read_json_file(tmp.str() + "/" + name));
  };
  const auto [table, held] = run({"--base-attitude", "hold"}, "held.json");
  const json free = run({}, "free.json").second;
  const json explicitly_free = run({"--base-attitude", "free"}, "free2.json").second;
  const json faster = run({"--max-joint-rate-deg", "5"}, "faster.json").second;
  using V = std::vector<std::string>;
  auto not_applied = [](const json& j, const char* row) { return j.at(row).at("keys_not_applied").get<V>(); };
  CHECK(not_applied(held, "baseline") == V{"base-attitude", "max-joint-rate-deg"});
  CHECK(not_applied(held, "optimized") == V{"max-joint-rate-deg"});
  CHECK(not_applied(held, "global") == V{"base-attitude"});
  for (const json* j : {&free, &explicitly_free}) {  // free is how every run is: it skips no row
    CHECK(not_applied(*j, "baseline") == V{"max-joint-rate-deg"});
    CHECK(not_applied(*j, "optimized") == V{"max-joint-rate-deg"});
    CHECK(not_applied(*j, "global").empty());
  }
  // what a row says is what its run does: a row that does not take a key is the same without it
  // (the global search also starts from the optimized run's configuration, which the held run does
  // not give here: its search has one start fewer, and ends on the same run)
  auto without_notes = [](json row) {
    for (const char* key : {"keys_not_applied", "search", "branches"}) row.erase(key);
    return row;
  };
  CHECK(without_notes(held.at("baseline")) == without_notes(free.at("baseline")));
  CHECK(without_notes(held.at("global")) == without_notes(free.at("global")));
  CHECK(held.at("global").at("base_attitude_drift_deg").get<double>() > 1.0);  // the base turns
  CHECK(held.at("optimized").contains("error"));  // the held run meets a singularity here (docs)
  CHECK(without_notes(faster.at("baseline")) == without_notes(free.at("baseline")));
  CHECK(without_notes(faster.at("optimized")) == without_notes(free.at("optimized")));
  // the global row takes it: limited to 3 deg/s by the file, it moves faster under 5
  CHECK(faster.at("global").at("max_joint_rate_deg").get<double>() >
        free.at("global").at("max_joint_rate_deg").get<double>() + 0.1);
  // the table says it on the rows
  std::istringstream lines(table);
  std::map<std::string, std::string> rows;
  for (std::string line; std::getline(lines, line);)
    for (const char* label : {"Without optimization", "With optimization", "Global"})
      if (line.rfind(label, 0) == 0) rows[label] = line;
  REQUIRE(rows.size() == 3);
  auto ends_with = [](const std::string& s, const std::string& end) {
    return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
  };
  CHECK(ends_with(rows["Without optimization"], "  not applied: base-attitude, max-joint-rate-deg"));
  CHECK(ends_with(rows["With optimization"], "  not applied: max-joint-rate-deg"));
  CHECK(ends_with(rows["Global"], "  not applied: base-attitude"));
  // pareto places the same three runs on its front, with the same notes
  const CommandResult p = cli({"pareto", "--config", kPosition7, "--levels", "2", "--starts", "2",
                               "--global-starts", "2", "--json", "-", "--quiet"});
  INFO(p.err);
  REQUIRE(p.exit_code == 0);
  const json front = json::parse(p.out);
  const V global_keys{"max-joint-rate-deg", "global-starts"};  // the file's, and the flag's
  CHECK(front.at("runs").at("baseline").at("keys_not_applied").get<V>() == global_keys);
  CHECK(front.at("runs").at("optimized").at("keys_not_applied").get<V>() == global_keys);
  CHECK(front.at("runs").at("global").at("keys_not_applied").get<V>().empty());
}

namespace test_conventions {

/// One error line (the command's prefix) that holds every string of `parts`; the refusal of `flag`.
void check_refusal(const CommandResult& r, const std::vector<std::string>& parts) {
  INFO("exit " << r.exit_code << "\nstdout: [" << r.out.substr(0, 200) << "]\nstderr: [" << r.err << "]");
  CHECK(r.exit_code == 2);
  CHECK(r.err.rfind("ffsr-optimize: error: ", 0) == 0);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.out.empty());
  for (const std::string& p : parts) {
    INFO("the error must say: " << p);
    CHECK(r.err.find(p) != std::string::npos);
  }
}

/// The built-in 3-DOF scenario as a file in `dir` (its URDF by absolute path), with `extra` appended;
/// `line`: the line number of the first appended line.
std::string scenario_with(const ffsr::test::TempDir& dir, const std::string& extra, long* line = nullptr) {
  std::string toml = ffsr::test::read_file(kSource + "/robots/paper_3dof.toml");
  toml = std::regex_replace(toml, std::regex("urdf = \"paper_3dof.urdf\""), "urdf = \"" + kUrdf3 + "\"");
  if (!toml.empty() && toml.back() != '\n') toml += "\n";
  if (line) *line = std::count(toml.begin(), toml.end(), '\n') + 1;
  const std::string file = dir.str() + "/s.toml";
  std::ofstream(file) << toml << extra;
  return file;
}

}  // namespace test_conventions

TEST_CASE("conventions: a boolean is true or false, nothing else, as a flag or in a file",
          "[cli][conventions]") {
  ffsr::test::TempDir tmp;
  for (const std::string bad : {"yes", "on", "y", "TRUE", "1", "t", "no", "0", "False"}) {
    INFO(bad);
    // the flags of boolean keys, on the subcommands that take them; nothing is written
    const Args flag{"detumble", "--joint-torque-limit", "20", "--stop-stack-spin", bad, "--json", "d.json"};
    check_refusal(cli(flag, tmp.str()),
                  {"--stop-stack-spin: expected true or false, got '" + bad + "'"});
    check_refusal(cli({"--global", bad, "--json", "r.json"}, tmp.str()),
                  {"--global: expected true or false, got '" + bad + "'"});
    check_refusal(cli({"inspect", "--quiet=" + bad, "--json", "i.json"}, tmp.str()),
                  {"--quiet", "expected true or false, got '" + bad + "'"});
    CHECK(tmp.entries().empty());
  }
  // the words themselves work: true and false, and --quiet alone
  for (const std::string quiet : {"--quiet=true", "--quiet=false", "--quiet"}) {
    const Args a{"inspect", quiet, "--json", "-"};
    const CommandResult r = cli(a);
    INFO(r.err);
    CHECK(r.exit_code == 0);
  }
  // in a file: TOML's true and false only (not 1, not the text "yes" or "true")
  for (const std::string bad : {"1", "\"yes\"", "\"true\"", "0"}) {
    long line = 0;
    const std::string file = scenario_with(tmp, "stop-stack-spin = " + bad + "\n", &line);
    INFO(bad);
    const std::string where = "scenario " + file + ":" + std::to_string(line);
    check_refusal(cli({"detumble", "--config", file, "--joint-torque-limit", "20"}),
                  {where + ": stop-stack-spin: expected true or false"});
    if (bad == "\"true\"") continue;  // a command key of the file (quiet) is read as text, "true" is true
    const std::string quiet = scenario_with(tmp, "quiet = " + bad + "\n", &line);
    // quiet is a key of the main job's file (a command key, read as text)
    check_refusal(cli({"--config", quiet, "--global", "false"}), {"quiet", "expected true or false"});
  }
  // the word itself (true needs a base actuator: false runs without one)
  const std::string good = scenario_with(tmp, "stop-stack-spin = false\nglobal = false\n");
  const CommandResult r =
      cli({"detumble", "--config", good, "--joint-torque-limit", "20", "--json", "-", "--quiet"});
  INFO(r.err);
  CHECK(r.exit_code == 0);
}

TEST_CASE("conventions: a scenario key's flag on a subcommand that does not take it is refused saying why",
          "[cli][conventions]") {
  // every subcommand knows every key's flag: where it does not take one, one line names the flag, the
  // subcommand and the jobs that take it (not the parser's "arguments were not expected")
  int refusals = 0;
  for (const Sub& sub : subcommands()) {
    if (sub.name.empty()) continue;  // the main job takes every key
    const std::set<std::string> accepted = accepted_flags(sub.name);
    for (const ffsr::ScenarioKey& key : ffsr::scenario_keys()) {
      const std::string flag = "--" + key.name;
      if (accepted.count(flag)) continue;
      if (key.name != "joint-torque-limit" && key.name != "base-position" && key.name != "stiffness" &&
          key.name != "global" && key.name != "target-shape")
        continue;  // a few keys of several groups (the walk above runs them all)
      Args a{sub.name, flag, key.kind == ffsr::KeyKind::Boolean ? "true" : "1"};
      const CommandResult r = cli(a);
      INFO(sub.name << " " << flag);
      check_refusal(r, {flag + ": ", "(the subcommand " + sub.name + " does not take it; ", "the main job"});
      CHECK(r.err.find("not expected") == std::string::npos);
      ++refusals;
    }
  }
  CHECK(refusals >= 10);
  // the reason of a key a subcommand leaves out of a group it takes
  check_refusal(cli({"map", "--vary", "1", "--base-position", "1,0,0"}),
                {"--base-position: M_ie and F_max do not depend on where the base is (the subcommand map"});
  check_refusal(cli({"inspect", "--joint-torque-limit", "20"}),
                {"--joint-torque-limit: a key of the post-capture phase, which inspect does not evaluate",
                 "detumble"});
}

TEST_CASE("conventions: the approach speed is positive in every subcommand, named as the flag or the key",
          "[cli][conventions]") {
  ffsr::test::TempDir tmp;
  for (const std::string bad : {"-0.2", "0"}) {
    for (const Args& a : {Args{"detumble", "--joint-torque-limit", "20"},
                          Args{"detumble", "--joint-torque-limit", "20", "--grasp-after", "contact"},
                          Args{"inspect"}, Args{"contact"}, Args{"map", "--vary", "1", "--step-deg", "90"},
                          Args{"--global", "false"}}) {
      Args args = a;
      args.insert(args.end(), {"--approach-speed=" + bad, "--json", "out.json"});
      const CommandResult r = cli(args, tmp.str());
      INFO(args[0] << " " << bad);
      check_refusal(r, {"--approach-speed: must be positive, got " + (bad == "0" ? std::string("0") : bad)});
      CHECK(r.err.find("--grasp-after") == std::string::npos);
      CHECK(tmp.entries().empty());
    }
  }
  std::string toml = ffsr::test::read_file(kSource + "/robots/paper_3dof.toml");
  toml = std::regex_replace(toml, std::regex("urdf = \"paper_3dof.urdf\""), "urdf = \"" + kUrdf3 + "\"");
  toml = std::regex_replace(toml, std::regex("approach-speed = 0.2"), "approach-speed = -0.2");
  const std::string file = tmp.str() + "/neg.toml";
  std::ofstream(file) << toml;
  const long line = 23;  // approach-speed's line in robots/paper_3dof.toml
  for (const Args& a :
       {Args{"detumble", "--config", file, "--joint-torque-limit", "20", "--grasp-after", "contact"},
        Args{"inspect", "--config", file}})
    check_refusal(cli(a), {"scenario " + file + ":" + std::to_string(line) +
                           ": approach-speed: must be positive"});
}

TEST_CASE("conventions: a flag at fault is named as the flag, not located at the line of another key",
          "[cli][conventions]") {
  // target-mass comes from the file, the flag gives a non-physical inertia (1 + 1 < 5): the error is
  // the flag's, not "scenario FILE:10: target-mass"
  ffsr::test::TempDir tmp;
  const std::string file = scenario_with(tmp, "");
  for (const Args& a : {Args{"--config", file, "--global", "false", "--target-inertia", "1,1,5"},
                        Args{"inspect", "--config", file, "--target-inertia", "1,1,5"}}) {
    const CommandResult r = cli(a);
    check_refusal(r, {"error: --target-mass/--target-inertia: "});
    CHECK(r.err.find(file + ":") == std::string::npos);
  }
  // the same inertia in the file: located at the file's line of target-mass (10), the keys named as
  // written there
  std::string toml = ffsr::test::read_file(file);
  toml = std::regex_replace(toml, std::regex("target-inertia = \\[100, 100, 100\\]"),
                            "target-inertia = [1, 1, 5]");
  const std::string bad = tmp.str() + "/bad.toml";
  std::ofstream(bad) << toml;
  const CommandResult r = cli({"inspect", "--config", bad});
  check_refusal(r, {"scenario " + bad + ":10: target-mass/target-inertia: "});
}
