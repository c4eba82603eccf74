// The job layer from C++ (ffsr/jobs/): the robust job on a scenario, its summary read back from its
// JSON, and shards merged by the library alone -- what `ffsr-optimize robust --merge` prints is
// this. Small runs: the built-in-like 3-DOF scenario, a given configuration, a few dozen samples.
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/robust.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace test_jobs {

/// robots/paper_3dof.toml with an [uncertainty] table of `samples` samples.
ffsr::Scenario uncertain_3dof(int samples) {
  const std::string dir = std::string(FFSR_SOURCE_DIR) + "/robots/";
  std::ifstream in(dir + "paper_3dof.toml");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str() + "\n[uncertainty]\nsamples = " + std::to_string(samples) +
                           "\nseed = 11\ntarget-mass = { law = \"uniform\", relative = 0.1 }\n"
                           "stiffness = { law = \"log-normal\", sigma = 0.5 }\n";
  return ffsr::build_scenario(ffsr::read_scenario_text(text, "scenario test", dir + "paper_3dof.toml"));
}

/// The paper's plain capture configuration of the 3-DOF robot (Table 4), base at its start pose.
std::vector<ffsr::RobustConfiguration> given(const ffsr::Scenario& sc) {
  ffsr::RobustConfiguration c;
  c.name = "given";
  c.theta = Eigen::Vector3d(-2.48, 90.49, -86.17) * (M_PI / 180.0);
  c.base = sc.problem.base;
  return {c};
}

}  // namespace test_jobs

using namespace test_jobs;

TEST_CASE("jobs: robust shards merged by the library equal one run, bit for bit", "[jobs][robust]") {
  const ffsr::Scenario sc = uncertain_3dof(41);
  const ffsr::UncertaintySpec spec = ffsr::uncertainty_spec(sc.keys);
  ffsr::RobustJobOptions o;
  o.threads = 2;
  const ffsr::RobustSummary whole =
      ffsr::robust_summary(sc, ffsr::run_robust(sc, spec, given(sc), o), "test", "0");
  std::vector<ffsr::RobustSummary> shards;
  for (std::uint64_t k : {2u, 0u, 1u}) {  // any order
    o.shard_k = k;
    o.shard_n = 3;
    const ffsr::RobustSummary s = ffsr::robust_summary(sc, ffsr::run_robust(sc, spec, given(sc), o), "test", "0");
    shards.push_back(ffsr::RobustSummary::from_json(s.to_json(), "shard"));  // through the JSON, as --merge
  }
  const ffsr::RobustSummary merged = ffsr::merge_shards(shards);
  CHECK(whole.stiffness_conditional);
  CHECK(merged.end == 41);
  CHECK(merged.merged_from == std::optional<std::uint64_t>(3));
  nlohmann::json a = whole.to_json(), b = merged.to_json();
  a.erase("shard");
  b.erase("shard");
  CHECK(a == b);  // every F_max, the percentiles, the tail: the unsharded run's
  // the summary's percentiles are those of the library's estimator over the same F_max
  const ffsr::RobustConfigurationSummary& c = whole.configurations.front();
  REQUIRE(c.f_max.size() == 41);
  CHECK(c.summary.n == 41);
  CHECK(c.tail.size() == ffsr::kRobustTail);
  CHECK(c.tail.front().force.f_max == *std::max_element(c.f_max.begin(), c.f_max.end()));
  // the redraws of every shard add up (this scenario redraws none: counts set by hand)
  for (std::size_t i = 0; i < shards.size(); ++i) shards[i].redraws = 2 * i + 1;
  CHECK(ffsr::merge_shards(shards).redraws == 1 + 3 + 5);
}

TEST_CASE("jobs: merge_shards refuses a gap and shards of another run", "[jobs][robust]") {
  const ffsr::Scenario sc = uncertain_3dof(10);
  const ffsr::UncertaintySpec spec = ffsr::uncertainty_spec(sc.keys);
  ffsr::RobustJobOptions o;
  o.shard_n = 3;
  std::vector<ffsr::RobustSummary> parts;
  for (std::uint64_t k : {0u, 2u}) {
    o.shard_k = k;
    parts.push_back(ffsr::robust_summary(sc, ffsr::run_robust(sc, spec, given(sc), o), "test", "0"));
  }
  CHECK_THROWS_AS(ffsr::merge_shards(parts), ffsr::InputError);  // samples of shard 1 missing
  o.shard_k = 1;
  ffsr::RobustSummary other = ffsr::robust_summary(sc, ffsr::run_robust(sc, spec, given(sc), o), "test", "0");
  other.seed += 1;
  parts.push_back(other);
  try {
    ffsr::merge_shards(parts);
    FAIL("a shard of another seed was merged");
  } catch (const ffsr::InputError& e) {
    CHECK(std::string(e.what()).find("differ in 'seed'") != std::string::npos);
  }
}

TEST_CASE("jobs: check_robust_job refuses a shard that does not exist and multibody with a joint model",
          "[jobs][robust]") {
  ffsr::Scenario sc = uncertain_3dof(4);
  ffsr::RobustJobOptions o;
  CHECK_NOTHROW(ffsr::check_robust_job(sc, o));
  o.shard_k = 3;
  o.shard_n = 3;
  CHECK_THROWS_AS(ffsr::check_robust_job(sc, o), ffsr::InputError);
  o.shard_k = 0;
  o.force_model = ffsr::ForceModel::Multibody;
  CHECK_NOTHROW(ffsr::check_robust_job(sc, o));  // free joints: what the multibody run simulates
  sc.problem.joints.model = ffsr::JointModel::Locked;
  try {
    ffsr::check_robust_job(sc, o);
    FAIL("multibody with locked joints was accepted");
  } catch (const ffsr::InputError& e) {
    CHECK(std::string(e.what()).rfind("--contact-joints:", 0) == 0);
  }
  o.force_model = ffsr::ForceModel::Exact;  // the exact peak takes Lambda^-1 of the joint model
  CHECK_NOTHROW(ffsr::check_robust_job(sc, o));
}
