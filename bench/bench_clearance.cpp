// bench/bench_clearance.cpp -- ffsr-bench-clearance: the global plan with a clearance, as the main
// job makes it (run_global: the search with the distance constraints, the reaching runs checked
// along their paths, the later rounds), on the paper's clearance scenarios.
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/scenario_clearance.hpp"
#include "ffsr/jobs/scenario_run.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

//   ffsr-bench-clearance [DIR]
//
// Times (steady_clock, wall, one thread) run_global on robots/paper_7dof_position_clearance.toml and
// robots/paper_3dof_clearance.toml; the plain and the paper's runs are made first and not timed.
// Best of 3, with the search's evaluations and the reaching runs. Target for the 7-DOF scenario:
// < 5 s in Release. DIR holds the scenario files (default FFSR_SOURCE_DIR/robots).

namespace {

using clock_type = std::chrono::steady_clock;

void time_global(const std::string& dir, const char* file) {
  const ffsr::Scenario sc = ffsr::load_scenario(dir + "/" + file);
  const auto runs = ffsr::plan_plain_and_optimized(sc);
  double best = 1e300;
  ffsr::GlobalRun g;
  for (int rep = 0; rep < 3; ++rep) {
    const auto t0 = clock_type::now();
    g = ffsr::run_global(sc, runs.second, sc.objective, nullptr, false);
    best = std::min(best, std::chrono::duration<double>(clock_type::now() - t0).count());
  }
  const ffsr::ClearanceReport c = ffsr::run_clearance(sc, g.result.run);
  std::printf("%-36s %7.3f s  M_ie %.4f kg  smallest distance %.4f m (%s)  evaluations %ld  reaching runs %d\n",
              file, best, g.result.run.M_ie, c.overall.distance, c.overall.pair.c_str(),
              g.result.counters.evaluations, g.result.counters.shooting_iterations);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : std::string(FFSR_SOURCE_DIR) + "/robots";
  std::printf("global plan with a clearance (best of 3, one thread; target for the 7-DOF scenario < 5 s)\n");
  time_global(dir, "paper_7dof_position_clearance.toml");
  time_global(dir, "paper_3dof_clearance.toml");
  return 0;
}
