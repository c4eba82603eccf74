// ffsr/jobs/detail/base_disturbance_json.hpp -- the impact disturbance of the base
// (algorithm/base_disturbance.hpp) of each run of the main job, as JSON.
#pragma once

#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/jobs/detail/json_values.hpp"

#include "ffsr/algorithm/base_disturbance.hpp"

namespace ffsr {
namespace detail {

/// The impact disturbance of a run's capture configuration: the target at T (its attitude gives
/// the normal), the scenario's law at the run's delta_dot^-, the scenario's joint model of the
/// contact. Runs crba. Writes data.
inline BaseDisturbance run_base_disturbance(const Scenario& sc, Data& data, const CaptureResult& run) {
  const Target at_capture = propagate_target(sc.problem.target, sc.capture.duration);
  const AnyContactLaw law = make_contact_law(sc.problem.law, sc.problem.contact, run.approach_velocity);
  return CaptureEvaluator(*sc.model, sc.problem.frame, at_capture, &law, sc.problem.joints)
      .disturbance(data, run.base, run.theta);
}

inline nlohmann::json base_disturbance_json(const BaseDisturbance& d) {
  return {{"impulse", d.impulse},
          {"restitution_single_body", d.restitution},
          {"angular_velocity_jump", vector_json(d.angular)},
          {"angular_rate_jump_deg_s", d.angular_rate() * 180.0 / M_PI},
          {"linear_velocity_jump", vector_json(d.linear)}};
}

/// Adds "base_disturbance" to the baseline, optimized and global rows of `j` that hold a run.
inline void add_base_disturbance_json(nlohmann::json& j, const Scenario& sc, const ScenarioResult& r) {
  Data data(*sc.model);
  if (r.plain_ok())
    j["baseline"]["base_disturbance"] = base_disturbance_json(run_base_disturbance(sc, data, r.plain));
  if (r.optimized_ok())
    j["optimized"]["base_disturbance"] = base_disturbance_json(run_base_disturbance(sc, data, r.optimized));
  if (r.global)
    j["global"]["base_disturbance"] =
        base_disturbance_json(run_base_disturbance(sc, data, r.global->result.run));
}

}  // namespace detail
}  // namespace ffsr
