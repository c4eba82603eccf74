// Replays every input the fuzz targets of fuzz/ ever failed on (tests/data/fuzz_regressions/<target>/)
// and their seed corpus (fuzz/corpus/<target>/) through the same checks as the targets, with the
// normal compiler and without libFuzzer, so a fixed finding stays fixed in the ordinary test suite.
#include "../fuzz/numeric_check.hpp"
#include "../fuzz/scenario_check.hpp"
#include "../fuzz/urdf_check.hpp"
#include "support/run_command.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

//   fuzz_urdf, fuzz_numeric: the checks of fuzz/urdf_check.hpp and fuzz/numeric_check.hpp, in-process;
//   fuzz_scenario: the built ffsr-optimize is run on the scenario with the harness's arguments and
//   its exit code and outputs are checked (fuzz/scenario_check.hpp).
// A broken contract shows as an ffsr_fuzz::Finding naming what was wrong.

namespace test_fuzz_regressions {

namespace {

namespace fs = std::filesystem;

/// The files of tests/data/fuzz_regressions/<target> and fuzz/corpus/<target>, sorted.
std::vector<std::string> inputs(const std::string& target) {
  std::vector<std::string> files;
  for (const std::string& dir : {std::string(FFSR_SOURCE_DIR) + "/tests/data/fuzz_regressions/" + target,
                                 std::string(FFSR_SOURCE_DIR) + "/fuzz/corpus/" + target}) {
    if (!fs::is_directory(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string bytes_of(const std::string& path) { return ffsr_fuzz::read_text(path); }

const uint8_t* data_of(const std::string& s) { return reinterpret_cast<const uint8_t*>(s.data()); }

/// Every regression and seed input of `target` through `check` (the target's contract): none throws.
template <class Check>
void replay(const std::string& target, Check check) {
  const auto files = inputs(target);
  REQUIRE(files.size() >= 2);
  for (const auto& f : files) {
    INFO(f);
    const std::string b = bytes_of(f);
    CHECK_NOTHROW(check(data_of(b), b.size()));
  }
}

}  // namespace

TEST_CASE("fuzz_urdf: every regression and seed input keeps the contract", "[fuzz]") {
  replay("fuzz_urdf", [](const uint8_t* data, size_t size) { ffsr_fuzz::check_urdf_input(data, size); });
}

TEST_CASE("fuzz_numeric: every regression and seed input keeps the contract", "[fuzz]") {
  replay("fuzz_numeric", [](const uint8_t* data, size_t size) { ffsr_fuzz::check_numeric_input(data, size); });
}

TEST_CASE("fuzz_scenario: ffsr-optimize on every regression and seed scenario keeps the contract", "[fuzz]") {
  const auto files = inputs("fuzz_scenario");
  REQUIRE(files.size() >= 2);
  for (const auto& f : files) {
    INFO(f);
    ffsr::test::TempDir tmp;
    ffsr_fuzz::prepare_scenario_dir(tmp.str());
    fs::copy_file(f, tmp / "scenario.toml");
    std::vector<std::string> args{FFSR_CLI};
    for (const auto& a : ffsr_fuzz::scenario_arguments(tmp.str())) args.push_back(a);
    const ffsr::test::CommandResult r = ffsr::test::run_command(args, tmp.str(), 120.0);
    INFO("exit " << r.exit_code << "\nstdout: " << r.out << "\nstderr: " << r.err);
    CHECK_FALSE(r.timed_out);
    CHECK_FALSE(r.signaled);
    CHECK_NOTHROW(ffsr_fuzz::check_scenario_outputs(tmp.str(), r.exit_code, r.out));
  }
}

}  // namespace test_fuzz_regressions
