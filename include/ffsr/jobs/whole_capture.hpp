// ffsr/jobs/whole_capture.hpp -- the whole capture: the main job (jobs/scenario_run.hpp), then, when the
// scenario gives a key of the Detumble group, the post-capture phase of each of its runs (the job
// detumble, jobs/detumble.hpp, from each run's capture). It sits above both jobs: the main job knows
// nothing of the detumble job, which plans the main job's runs for its --run. Component
// ffsr::scenario. Never prints.
#pragma once

#include "ffsr/jobs/detumble.hpp"
#include "ffsr/jobs/scenario_run.hpp"

#include <string>
#include <utility>
#include <vector>

namespace ffsr {

/// The post-capture phase of each run of `r` that holds a result (a failed row has no capture), in the
/// order baseline, optimized, global: the grasp at the run's capture, the target at T, the stack brought
/// to rest under the Detumble keys. InputError naming the key and the run.
inline std::vector<DetumbleJobResult> post_capture_runs(const Scenario& sc, const ScenarioResult& r) {
  std::vector<std::pair<std::string, const CaptureResult*>> runs;
  if (r.plain_ok()) runs.emplace_back("baseline", &r.plain);
  if (r.optimized_ok()) runs.emplace_back("optimized", &r.optimized);
  if (r.global) runs.emplace_back("global", &r.global->result.run);
  return detail::detumble_each_run(sc, runs);
}

/// The command's main job and Scenario.run: run_scenario, then with a Detumble key given
/// (scenario_has_post_capture) each run's post-capture phase into ScenarioResult::post_capture (an
/// error of that phase, an actuator too small or not at rest by the horizon, is an InputError naming
/// the key and the run; grasp-after = held is refused before the runs: it starts from no capture).
/// Without one the runs stop at the impact.
inline ScenarioResult run_whole_capture(const Scenario& sc, const ScenarioRunOptions& options = {}) {
  if (scenario_has_post_capture(sc.keys)) detail::refuse_held(sc, "the main job's post-capture phase");
  ScenarioResult r = run_scenario(sc, options);
  if (scenario_has_post_capture(sc.keys)) r.post_capture = post_capture_runs(sc, r);
  return r;
}

}  // namespace ffsr
