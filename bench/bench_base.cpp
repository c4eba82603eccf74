// bench/bench_base.cpp -- ffsr-bench-base: the spacecraft's side on robots/paper_7dof_position.toml.
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/pareto.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

//   ffsr-bench-base [SCENARIO] [--csv FILE]
//
// Runs the main job once (plain, optimized, global; not timed), then times (steady_clock, wall, one
// thread) the front of (M_ie, base angular rate jump) on the capture manifold at the global run's
// base pose (optimize/pareto.hpp, default options), and prints its size, ends, knee, hypervolume
// and evaluations, the ends against the global search's manifold optimum, and the optimized run
// with base-attitude = hold beside the free one. Target: the front in < 10 s on one core.

namespace {

int run(int argc, char** argv) {
  using namespace ffsr;
  std::string file = std::string(FFSR_SOURCE_DIR) + "/robots/paper_7dof_position.toml", csv;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--csv" && i + 1 < argc)
      csv = argv[++i];
    else
      file = a;
  }
  const double deg = 180.0 / M_PI;
  const Scenario sc = load_scenario(file);
  const ScenarioResult r = run_scenario(sc);
  if (!r.global) return std::fprintf(stderr, "the scenario has global = false\n"), 1;
  const CaptureResult& g = r.global->result.run;
  const CaptureSetup setup = prepare_capture(sc.problem, sc.task, sc.capture);
  const std::vector<Eigen::VectorXd> extra = {r.plain.theta, r.optimized.theta, g.theta};
  const auto t0 = std::chrono::steady_clock::now();
  const ParetoFront f = pareto_front(sc.problem, sc.task, setup, g.base, ParetoOptions{}, extra);
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("front: %zu non-dominated points in %.2f s (one thread), %ld evaluations\n", f.points.size(),
              sec, f.evaluations);
  std::printf("M_ie end  : %.4f kg, %.5f deg/s (global search's manifold optimum %.4f kg: %+.3f %%)\n",
              f.min_mass.M_ie, f.min_mass.base_rate * deg, r.global->result.manifold_optimum,
              100 * (f.min_mass.M_ie / r.global->result.manifold_optimum - 1));
  std::printf("rate end  : %.4f kg, %.5f deg/s\n", f.min_rate.M_ie, f.min_rate.base_rate * deg);
  const ParetoPoint& k = f.points[f.knee];
  std::printf("knee      : %.4f kg, %.5f deg/s (point %zu)\n", k.M_ie, k.base_rate * deg, f.knee);
  std::printf("hypervolume: %.6g kg deg/s up to the nadir (%.4f kg, %.5f deg/s); normalized %.4f\n",
              f.hypervolume * deg, f.min_rate.M_ie, f.min_mass.base_rate * deg, f.hypervolume_normalized);
  if (!csv.empty()) {
    std::ofstream out(csv);
    out << "M_ie_kg,base_rate_deg_s\n";
    for (const ParetoPoint& p : f.points) out << p.M_ie << "," << p.base_rate * deg << "\n";
  }
  // base-attitude = hold beside free (the optimized run)
  ScenarioKeys keys = sc.keys;
  override_scenario_key(keys, "base-attitude", "hold");
  const Scenario held_sc = build_scenario(std::move(keys));
  CaptureResult held;
  try {
    held = plan_plain_and_optimized(held_sc).second;
  } catch (const NumericalError& e) {  // the held approach may meet an algorithmic singularity
    std::printf("\nbase-attitude = hold: %s\n", e.what());
    return 0;
  }
  std::printf("\n%-28s %10s %14s %16s %14s\n", "optimized run", "M_ie (kg)", "attitude (deg)",
              "momentum (N s)", "tracking (m)");
  for (const auto& [name, x] :
       {std::pair<const char*, const CaptureResult*>{"base-attitude = free", &r.optimized},
        {"base-attitude = hold", &held},
        {"plain (no optimization)", &r.plain},
        {"global", &g}})
    std::printf("%-28s %10.4f %14.6f %16.3g %14.3g\n", name, x->M_ie, x->base_attitude_drift * deg,
                x->max_momentum, x->tracking_error);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ffsr-bench-base: error: %s\n", e.what());
    return 1;
  }
}
