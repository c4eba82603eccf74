// End-to-end tests of `ffsr-optimize robust` on robots/paper_7dof_position_uncertain.toml:
// shards merged reproduce the unsharded summary exactly, sample i does not depend on the sample
// count, the 95th percentile of 1e3 samples against 2e4, the CSV, flags over the file, and the bad
// inputs (one error line naming the key, exit 2, no output file).
#include "support/command.hpp"

#include <catch2/catch.hpp>
#include "ffsr/uncertainty/sampling.hpp"
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

// To stay fast, the runs evaluate one given capture configuration (--capture-joints-deg) with the
// exact single-body F_max instead of planning.

namespace test_robust {

using namespace ffsr::test;
using nlohmann::json;

namespace {

const std::string kScenario = kSource + "/robots/paper_7dof_position_uncertain.toml";
const Args kGiven{"--capture-joints-deg", "5,80,95,-85,92,88,3", "--quiet"};

CommandResult robust(const Args& args, const std::string& cwd) { return cli_sub("robust", args, cwd); }

/// Merges shard0..3.json of `dir` with shard 1 replaced by `shard1` (written to dir/name).
CommandResult merge_with_shard1(const TempDir& dir, const std::string& name, const json& shard1) {
  std::ofstream(dir / name) << shard1.dump();
  return robust({"--merge", dir / "shard0.json", dir / name, dir / "shard2.json", dir / "shard3.json"}, dir.str());
}

/// The example scenario with its URDF path made absolute and without its [uncertainty] table.
std::string scenario_without_uncertainty() {
  std::ifstream in(kScenario);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  s = s.substr(0, s.find("\n[uncertainty]") + 1);
  const std::string key = "urdf = \"paper_7dof.urdf\"";
  s.replace(s.find(key), key.size(), "urdf = \"" + kSource + "/robots/paper_7dof.urdf\"");
  return s;
}

/// The example scenario with its URDF path made absolute and its [uncertainty] table replaced.
std::string scenario_with(const std::string& uncertainty) {
  return scenario_without_uncertainty() + "[uncertainty]\n" + uncertainty + "\n";
}

std::string write(const TempDir& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir / name) << text;
  return dir / name;
}

double nearest_rank95(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[(95 * v.size() + 99) / 100 - 1];
}

}  // namespace

TEST_CASE("robust: 4 shards merged equal the unsharded run to the last digit", "[robust]") {
  TempDir dir;
  Args base{"--config", kScenario, "--samples", "4003", "--seed", "17"};
  base.insert(base.end(), kGiven.begin(), kGiven.end());
  Args whole = base;
  whole.insert(whole.end(), {"--json", dir / "whole.json", "--threads", "2"});
  const CommandResult w = robust(whole, dir.str());
  INFO(w.err);
  REQUIRE(w.exit_code == 0);
  Args merge{"--merge"};
  for (int k = 0; k < 4; ++k) {
    Args a = base;
    const std::string shard = std::to_string(k) + "/4", out = dir / ("shard" + std::to_string(k) + ".json");
    a.insert(a.end(), {"--shard", shard, "--json", out, "--threads", k % 2 ? "1" : "2"});
    const CommandResult r = robust(a, dir.str());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    merge.push_back(out);
  }
  std::reverse(merge.begin() + 1, merge.end());  // the order of the files does not matter
  merge.insert(merge.end(), {"--json", dir / "merged.json"});
  const CommandResult m = robust(merge, dir.str());
  INFO(m.err);
  REQUIRE(m.exit_code == 0);
  const json a = read_json_file(dir / "whole.json"), b = read_json_file(dir / "merged.json");
  REQUIRE(a["configurations"].size() == 1);
  const json& ca = a["configurations"][0];
  const json& cb = b["configurations"][0];
  CHECK(ca["summary"] == cb["summary"]);  // every double bit for bit
  CHECK(ca["summary"]["estimator"] == "stiffness-conditional");
  CHECK(a["stiffness"] == b["stiffness"]);
  CHECK(a["exponent"] == b["exponent"]);
  CHECK(ca["f_max"] == cb["f_max"]);
  CHECK(ca["tail"] == cb["tail"]);
  CHECK(cb["summary"]["n"] == 4003);
  // the printed tables agree line for line after the header
  auto table = [](const std::string& out) { return out.substr(out.find("configuration")); };
  CHECK(table(w.out) == table(m.out));
  // a gap between shards is refused
  const CommandResult gap = robust({"--merge", dir / "shard0.json", dir / "shard2.json"}, dir.str());
  CHECK(gap.exit_code == 2);
  CHECK(gap.err.find("--merge") != std::string::npos);
  // a shard of another estimator (multibody: order statistics) is refused by name
  json other = read_json_file(dir / "shard1.json");
  other["estimator"] = "order-statistics";
  other.erase("stiffness");
  other.erase("exponent");
  other.erase("stiffness_nominal");
  const CommandResult mixed = merge_with_shard1(dir, "other1.json", other);
  CHECK(mixed.exit_code == 2);
  CHECK(mixed.err.find("differ in 'estimator'") != std::string::npos);
  // a shard whose per-sample stiffness list lost a value
  json cut = read_json_file(dir / "shard1.json");
  cut["stiffness"].erase(cut["stiffness"].size() - 1);
  const CommandResult lost = merge_with_shard1(dir, "cut1.json", cut);
  CHECK(lost.exit_code == 2);
  CHECK(lost.err.find("'stiffness' lists do not hold one value per sample") != std::string::npos);
  CHECK(std::count(lost.err.begin(), lost.err.end(), '\n') == 1);
}

TEST_CASE("robust: sample i depends on (seed, i) only -- p95 of 1e3 against 2e4 samples -- no NaN",
          "[robust]") {
  TempDir dir;
  Args a{"--config", kScenario, "--samples", "20000", "--json", dir / "big.json", "--csv", dir / "big.csv"};
  a.insert(a.end(), kGiven.begin(), kGiven.end());
  const CommandResult big = robust(a, dir.str());
  INFO(big.err);
  REQUIRE(big.exit_code == 0);
  Args b{"--config", kScenario, "--json", dir / "small.json"};  // samples = 1000 from the file
  b.insert(b.end(), kGiven.begin(), kGiven.end());
  const CommandResult small = robust(b, dir.str());
  REQUIRE(small.exit_code == 0);
  const json jb = read_json_file(dir / "big.json"), js = read_json_file(dir / "small.json");
  const auto fb = jb["configurations"][0]["f_max"].get<std::vector<double>>();
  const auto fs = js["configurations"][0]["f_max"].get<std::vector<double>>();
  REQUIRE(fb.size() == 20000);
  REQUIRE(fs.size() == 1000);
  CHECK(std::equal(fs.begin(), fs.end(), fb.begin()));
  for (double f : fb) REQUIRE(std::isfinite(f));
  // our own nearest-rank percentile of the stored values equals the summary's order statistic
  const json sb = jb["configurations"][0]["summary"], ss = js["configurations"][0]["summary"];
  CHECK(nearest_rank95(fb) == sb["order_statistics"]["p95"].get<double>());
  CHECK(nearest_rank95(fs) == ss["order_statistics"]["p95"].get<double>());
  // the p95 of the law: stiffness-conditional (exact model, K log-normal); 1e3 against 2e4 within
  // 1 % (its scatter at 1e3 is about 0.1-0.3 % here; order statistics scatter by 1.6-1.8 %)
  REQUIRE(ss["estimator"] == "stiffness-conditional");
  const double p95_small = ss["p95"], p95_big = sb["p95"];
  CHECK(std::abs(p95_small / p95_big - 1) < 0.01);
  // the 1e3 run's delta-method interval holds the 2e4 estimate, and is narrower than the
  // distribution-free interval of the order statistics of the same samples
  const json cs = ss["p95_ci95"], cb = sb["p95_ci95"];
  CHECK(cs["method"] == "delta");
  CHECK(cs["lo"].get<double>() <= p95_big);
  CHECK(p95_big < cs["hi"].get<double>());
  CHECK(cb["hi"].get<double>() - cb["lo"].get<double>() < cs["hi"].get<double>() - cs["lo"].get<double>());
  const json os = ss["order_statistics"]["p95_ci95"];
  CHECK(os["method"] == "order-statistics");
  CHECK(cs["hi"].get<double>() - cs["lo"].get<double>() <
        0.5 * (os["hi"].get<double>() - os["lo"].get<double>()));
  // and the distribution-free interval of the order statistics holds the conditional estimate too
  CHECK(os["lo"].get<double>() <= p95_big);
  CHECK(p95_big < os["hi"].get<double>());
  std::vector<double> sorted = fs;
  std::sort(sorted.begin(), sorted.end());
  CHECK(os["lo"].get<double>() == sorted[os["lower_rank"].get<std::size_t>() - 1]);
  CHECK(os["hi"].get<double>() == sorted[os["upper_rank"].get<std::size_t>() - 1]);
  CHECK(small.out.find("percentiles conditional on the stiffness") != std::string::npos);
  CHECK(small.out.find("95 % confidence interval of the 95th percentile") != std::string::npos);
  // the CSV: a header and one row per sample, 31 columns, no NaN
  std::ifstream csv(dir / "big.csv");
  std::string line;
  std::getline(csv, line);
  CHECK(std::count(line.begin(), line.end(), ',') == 30);
  long rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    if (line.find("nan") != std::string::npos || line.find("inf") != std::string::npos)
      FAIL("non-finite value: " << line);
  }
  CHECK(rows == 20000);
  CHECK(big.out.find("nan") == std::string::npos);
}

TEST_CASE("robust: the 95th percentile from 1e3 and from 1e5 samples within 1 % (exact model)",
          "[robust]") {
  TempDir dir;
  Args a{"--config", kScenario, "--samples", "100000", "--json", dir / "big.json"};
  a.insert(a.end(), kGiven.begin(), kGiven.end());
  const CommandResult big = robust(a, dir.str());
  INFO(big.err);
  REQUIRE(big.exit_code == 0);
  const json jb = read_json_file(dir / "big.json");
  const json sb = jb["configurations"][0]["summary"];
  REQUIRE(sb["n"] == 100000);
  // the first 1000 samples of the 1e5 run are the 1e3 run's (sample i depends on (seed, i) only);
  // every block of 1000 of them estimates the p95 within 1 % of the 1e5 estimate
  const auto f = jb["configurations"][0]["f_max"].get<std::vector<double>>();
  const auto K = jb["stiffness"].get<std::vector<double>>(),
             alpha = jb["exponent"].get<std::vector<double>>();
  ffsr::Spread law;
  law.law = ffsr::Spread::Law::LogNormal;
  law.scale = 0.587;  // the example's K: log-normal, sigma 0.587 about 1e9
  REQUIRE(jb["uncertainty"]["stiffness"]["scale"] == 0.587);
  int within = 0;
  double worst = 0;
  for (std::size_t b = 0; b < 20; ++b) {
    const auto cut = [b](const std::vector<double>& v) {
      return std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(1000 * b),
                                 v.begin() + static_cast<std::ptrdiff_t>(1000 * (b + 1)));
    };
    const double p95 = ffsr::summarize_stiffness_conditional(cut(f), cut(K), cut(alpha), law, 1e9).p95;
    const double e = std::abs(p95 / sb["p95"].get<double>() - 1);
    worst = std::max(worst, e);
    within += e < 0.01;
  }
  INFO("largest difference of a 1e3 block: " << worst);
  CHECK(within == 20);
  Args s{"--config", kScenario, "--json", dir / "small.json"};  // samples = 1000 from the file
  s.insert(s.end(), kGiven.begin(), kGiven.end());
  REQUIRE(robust(s, dir.str()).exit_code == 0);
  const json ss = read_json_file(dir / "small.json")["configurations"][0]["summary"];
  CHECK(std::abs(ss["p95"].get<double>() / sb["p95"].get<double>() - 1) < 0.01);
  // the conditional and the order-statistics estimates of the same law agree: the 1e5 conditional p95
  // lies within the distribution-free interval of the 1e5 order statistics
  const json os = sb["order_statistics"]["p95_ci95"];
  CHECK(os["lo"].get<double>() <= sb["p95"].get<double>());
  CHECK(sb["p95"].get<double>() < os["hi"].get<double>());
}

TEST_CASE("robust: bad inputs give one error line naming the key, exit 2, no output", "[robust]") {
  TempDir dir;
  struct Case {
    std::string uncertainty;
    Args flags;
    std::string expected;
  };
  const std::vector<Case> cases{
      {"target-mass = { law = \"normal\", relative-std = -0.1 }",
       {},
       "uncertainty.target-mass.relative-std: a spread must be non-negative, got -0.1"},
      {"spin = { law = \"normal\", std = -0.2 }",
       {},
       "uncertainty.spin.std: a spread must be non-negative, got -0.2"},
      {"restitution = { law = \"uniform\", min = 0.95, max = 0.6 }",
       {},
       "uncertainty.restitution: min (0.95) is greater than max (0.6)"},
      {"normal = { law = \"cone\", angle-deg = 95 }",
       {},
       "uncertainty.normal: the cone half-angle must be at most 90 deg"},
      {"colour = { law = \"normal\", std = 1 }", {}, "uncertainty.colour: unknown uncertain quantity"},
      {"samples = 0", {}, "uncertainty.samples: must be at least 1"},
      {"seed = 1.5", {}, "uncertainty.seed: must be an integer"},
      {"seed = \"abc\"", {}, "uncertainty.seed: must be an integer"},
      {"stiffness = { law = \"log-normal\", sigma = 0.5, scale = 2 }",
       {},
       "uncertainty.stiffness.scale: unknown parameter"},
      {"stiffness = { law = \"gamma\", sigma = 0.5 }", {}, "uncertainty.stiffness.law: unknown law 'gamma'"},
      {"spin = { law = \"normal\", relative-std = 0.1 }",
       {},
       "uncertainty.spin: a vector takes an absolute spread"},
      {"contact-point = { law = \"uniform\", half-width = -0.02 }",
       {},
       "uncertainty.contact-point.half-width: a spread must be non-negative, got -0.02"},
      {"contact-point = { law = \"log-normal\", sigma = 0.1 }",
       {},
       "uncertainty.contact-point: a vector takes a 'normal' or 'uniform' law"},
      {"contact-point = 0.02", {}, "uncertainty.contact-point: expected a table"},
      {"samples = 10", {"--samples", "0"}, "--samples: must be at least 1"},
      {"samples = 10", {"--seed", "-3"}, "--seed: expected a non-negative integer, got '-3'"},
      {"samples = 10", {"--seed", "1e3"}, "--seed: expected a non-negative integer"},
      {"samples = 10", {"--shard", "4/4"}, "--shard: K must be less than N"},
      {"samples = 10", {"--force-model", "fem"}, "--force-model: unknown model 'fem'"},
  };
  for (const auto& c : cases) {
    const std::string text = scenario_with(c.uncertainty);
    const std::string path = write(dir, "bad.toml", text);
    // an entry of the table is named as written, after the file and the entry's line; a flag by itself
    const std::string expected =
        c.flags.empty() ? "scenario " + path + ":" +
                              std::to_string(std::count(text.begin(), text.end(), '\n')) + ": " + c.expected
                        : c.expected;
    Args a{"--config", path, "--json", dir / "out.json"};
    a.insert(a.end(), kGiven.begin(), kGiven.end());
    a.insert(a.end(), c.flags.begin(), c.flags.end());
    const CommandResult r = robust(a, dir.str());
    INFO(c.uncertainty << " " << (c.flags.empty() ? "" : c.flags[0]) << "\nstderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("ffsr-optimize: error: " + expected) == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.out.empty());
    CHECK_FALSE(std::ifstream(dir / "out.json").good());
  }
  // an unknown top-level key stays an error; a flag overrides a key of the file
  const std::string extra = write(dir, "extra.toml", "colour = 3\n" + scenario_with("samples = 10"));
  Args e{"--config", extra};
  e.insert(e.end(), kGiven.begin(), kGiven.end());
  const CommandResult re = robust(e, dir.str());
  CHECK(re.exit_code == 2);
  CHECK(re.err.find("unknown key 'colour'") != std::string::npos);
  const std::string ok = write(dir, "ok.toml", scenario_with("samples = 10\nseed = 4"));
  Args f{"--config", ok, "--samples", "7", "--json", dir / "ok.json", "--stiffness", "2e9"};
  f.insert(f.end(), kGiven.begin(), kGiven.end());
  const CommandResult rf = robust(f, dir.str());
  INFO(rf.err);
  REQUIRE(rf.exit_code == 0);
  const json j = read_json_file(dir / "ok.json");
  CHECK(j["samples"] == 7);
  CHECK(j["seed"] == 4);
  CHECK(j["configurations"][0]["tail"][0]["parameters"]["stiffness"] == 2e9);  // no spread: the flag's value
}

TEST_CASE(
    "robust-force: the main job's global run minimizes CVaR_95 -- robust shows it beside the nominal global "
    "run",
    "[robust][global]") {
#if defined(FFSR_SANITIZED) && !defined(__OPTIMIZE__)
  // three 7-DOF plans and three global searches at -O0 with ASan take about as long as ctest's per-test
  // limit: skipped there (.ci/run builds its sanitizer stage with -O1, where it runs); the robust
  // objective itself (value, gradient, scaling) runs under the sanitizers in test_uncertainty at any level
  WARN("skipped in an unoptimized sanitizer build (runs at -O1 and in Release)");
  return;
#endif
  TempDir dir;
  // the main job: the example scenario asks for objective = "robust-force"
  const CommandResult m =
      run_command({kCli, "--config", kScenario, "--json", dir / "main.json", "--quiet"}, dir.str());
  INFO(m.err);
  REQUIRE(m.exit_code == 0);
  const json j = read_json_file(dir / "main.json");
  CHECK(j["global"]["objective"] == "robust-force");
  const json& r = j["robust"];
  CHECK(r["samples"] == 1000);
  CHECK(r["seed"] == 2023);  // the table's seed + 1: independent of the evaluation samples of `robust`
  for (const char* row : {"baseline", "optimized", "global"}) {
    INFO(row);
    CHECK(r[row]["cvar95"].get<double>() >= r[row]["p95"].get<double>());
    CHECK(std::isfinite(r[row]["cvar95"].get<double>()));
  }
  // the search lowered the measure it minimizes, below the paper's method's configuration
  CHECK(r["global"]["cvar95"].get<double>() < r["optimized"]["cvar95"].get<double>());
  CHECK(j["global"]["objective_value"].get<double>() ==
        Approx(r["global"]["cvar95"].get<double>()).epsilon(1e-12));
  // the nominal values of the robust configuration are its row: M_ie and F_max
  CHECK(j["global"]["integrated_effective_mass"].get<double>() > 0);

  // robust: plain, optimized, the nominal global run (mass) and the robust one, on common samples
  const CommandResult rb = robust(
      {"--config", kScenario, "--samples", "10000", "--json", dir / "robust.json", "--quiet"}, dir.str());
  INFO(rb.err);
  REQUIRE(rb.exit_code == 0);
  const json k = read_json_file(dir / "robust.json");
  std::vector<std::string> names;
  for (const auto& c : k["configurations"]) names.push_back(c["name"]);
  CHECK(names == std::vector<std::string>{"plain", "optimized", "global", "robust"});
  // the robust row is the main job's global row
  const auto& rc = k["configurations"][3];
  CHECK(rc["nominal"]["M_ie"].get<double>() ==
        Approx(j["global"]["integrated_effective_mass"].get<double>()).epsilon(1e-12));
  // on the example (the contact point known to +-5 cm) the robust configuration's 95th
  // percentile is below the nominal global configuration's on the evaluation samples (seed 2022, not
  // the search's 2023), the whole paired 95 % interval of the ratio below 1, and it pays for it with
  // a higher nominal M_ie: the price of robustness
  const auto& gc = k["configurations"][2];
  const json& cmp = k["robust_vs_global"];
  INFO("p95 global " << gc["summary"]["p95"] << ", robust " << rc["summary"]["p95"] << "; ratio " << cmp);
  CHECK(rc["summary"]["p95"].get<double>() < gc["summary"]["p95"].get<double>());
  CHECK(cmp["p95_ratio"].get<double>() ==
        Approx(rc["summary"]["p95"].get<double>() / gc["summary"]["p95"].get<double>()));
  CHECK(cmp["p95_ratio_ci95"]["hi"].get<double>() < 1.0);
  CHECK(rc["nominal"]["M_ie"].get<double>() > gc["nominal"]["M_ie"].get<double>());
  CHECK(rb.out.find("robust against global on the same samples: p95 -") != std::string::npos);
  CHECK(rb.out.find("robust ") != std::string::npos);

  // robust-force needs the [uncertainty] table
  const std::string no_table = write(dir, "no_table.toml", scenario_without_uncertainty());
  const CommandResult e = run_command({kCli, "--config", no_table, "--quiet"}, dir.str());
  CHECK(e.exit_code == 2);
  CHECK(e.err.find("robust-force needs an [uncertainty] table") != std::string::npos);
  CHECK(std::count(e.err.begin(), e.err.end(), '\n') == 1);
}

TEST_CASE("robust --json -: the JSON alone on standard output, the table on standard error", "[robust]") {
  TempDir dir;
  Args a{"--config", kScenario, "--samples", "50", "--json", "-"};
  a.insert(a.end(), kGiven.begin(), kGiven.end() - 1);  // without --quiet: the table on standard error
  const CommandResult r = robust(a, dir.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json j = json::parse(r.out);  // throws if the table were mixed in
  CHECK(j["configurations"][0]["summary"]["n"] == 50);
  // 50 samples are too few for an upper bound of the distribution-free p95 interval: left out, not
  // null; the delta-method interval of the conditional estimate exists (asymptotic)
  const json ci = j["configurations"][0]["summary"]["order_statistics"]["p95_ci95"];
  CHECK(ci["upper_rank"] == 0);
  CHECK_FALSE(ci.contains("hi"));
  CHECK(ci["lo"].is_number());
  CHECK(j["configurations"][0]["summary"]["p95_ci95"]["hi"].is_number());
  // with the stiffness known the percentiles are order statistics, and the table says the bound is missing
  const std::string known_k = write(dir, "known_k.toml",
                                    scenario_with("samples = 50\nseed = 3\n"
                                                  "target-mass = { law = \"uniform\", relative = 0.1 }"));
  Args k{"--config", known_k, "--json", dir / "known_k.json"};
  k.insert(k.end(), kGiven.begin(), kGiven.end());
  const CommandResult rk = robust(k, dir.str());
  INFO(rk.err);
  REQUIRE(rk.exit_code == 0);
  const json jk = read_json_file(dir / "known_k.json");
  CHECK(jk["estimator"] == "order-statistics");
  CHECK_FALSE(jk.contains("stiffness"));
  const json sk = jk["configurations"][0]["summary"];
  CHECK(sk["p95"] == sk["order_statistics"]["p95"]);
  CHECK(sk["p95_ci95"] == sk["order_statistics"]["p95_ci95"]);
  CHECK(rk.out.find("none: too few samples") != std::string::npos);
  CHECK(rk.out.find("percentiles conditional") == std::string::npos);
  std::remove((dir / "known_k.json").c_str());
  std::remove(known_k.c_str());
  CHECK(r.err.find("configuration") != std::string::npos);
  // two outputs on standard output: refused before any work
  Args b{"--config", kScenario, "--json", "-", "--csv", "-"};
  b.insert(b.end(), kGiven.begin(), kGiven.end());
  const CommandResult two = robust(b, dir.str());
  CHECK(two.exit_code == 2);
  CHECK(two.out.empty());
  CHECK(std::count(two.err.begin(), two.err.end(), '\n') == 1);
  CHECK(dir.entries().empty());
}

TEST_CASE("robust --plot: the CDF and histogram per configuration, from a run and from merged shards",
          "[robust][plot]") {
  TempDir dir;
  Args a{"--config", kScenario, "--samples", "400", "--plot", dir.str(), "--json", dir / "r.json"};
  a.insert(a.end(), kGiven.begin(), kGiven.end());
  const CommandResult r = robust(a, dir.str());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("wrote " + (dir / "robust.png")) != std::string::npos);
  std::ifstream png(dir / "robust.png", std::ios::binary);
  std::string head(8, '\0');
  png.read(&head[0], 8);
  CHECK(head == "\x89PNG\r\n\x1a\n");
  // from a merged summary, as SVG
  TempDir svg;
  const CommandResult m =
      robust({"--merge", dir / "r.json", "--plot", svg.str(), "--plot-format", "svg"}, dir.str());
  INFO(m.err);
  REQUIRE(m.exit_code == 0);
  std::ifstream in(svg / "robust.svg");
  std::stringstream ss;
  ss << in.rdbuf();
  CHECK(ss.str().find("<svg") != std::string::npos);
  CHECK(ss.str().find("</svg>") != std::string::npos);
  // a missing folder: one line, before any work, no output file
  TempDir empty;
  Args b{"--config", kScenario, "--plot", "no_such_folder", "--json", "r.json"};
  b.insert(b.end(), kGiven.begin(), kGiven.end());
  const CommandResult bad = robust(b, empty.str());
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("--plot: folder 'no_such_folder' does not exist") != std::string::npos);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
  CHECK(empty.entries().empty());
}

}  // namespace test_robust
