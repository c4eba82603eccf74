// ffsr/scenario/detail/detumble_keys.hpp -- the entries of the key table (keys.hpp) for the post-capture
// phase: the Detumble keys (the hardware's bounds, the run's settings, the grasp it starts from) and the
// global search's post-capture constraints.
#pragma once

#include "ffsr/scenario/detail/key_entry.hpp"

namespace ffsr {
namespace detail {

/// A Detumble key of a positive number, checked and echoed when given; returns it for more settings.
inline ScenarioKey& add_positive_detumble_key(std::vector<ScenarioKey>& keys, ScenarioKey key, const char* name,
                                              double ScenarioKeys::*member) {
  keys.push_back(key.in(KeyGroup::Detumble)
                     .checked([name, member](const ScenarioKeys& k) { check_positive_if_given(k, name, k.*member); })
                     .echoed(echo_given(name, member)));
  return keys.back();
}

/// The post-capture phase (the detumble job): the hardware's bounds and the run's settings.
inline void add_detumble_keys(std::vector<ScenarioKey>& keys) {
  using G = KeyGroup;
  using K = ScenarioKeys;
  // the base's actuator acts only when the run stops the stack's spin (DetumbleOptions::stop_stack_spin)
  const auto with_actuator = [](const char* actuator) {
    return [actuator](const K& k) -> std::string {
      if (k.base_actuator != actuator)
        return str("acts with base-actuator = ", actuator, " only, and this run has ", k.base_actuator);
      if (!k.stop_stack_spin) return "acts only when the run stops the stack's spin (stop-stack-spin = true)";
      return "";
    };
  };
  keys.push_back(
      FFSR_KEY("joint-torque-limit", joint_torque_limit,
               "Detumble: joint torque limit, N m (N prismatic): one value or one per joint (default: the "
               "URDF's <limit effort>)")
          .in(G::Detumble)
          .checked([](const K& k) {
            for (double v : k.joint_torque_limit)  // the controller's own test of a limit
              if (!detumble_bound_ok(finite(v, "joint-torque-limit")))
                throw InputError(str("--joint-torque-limit: every limit must be positive, got ", v));
          })
          .echoed(echo_given("joint-torque-limit", &K::joint_torque_limit)));
  const std::string actuators = "Detumble: the base's actuator: " + base_actuator_names();
  keys.push_back(
      FFSR_KEY("base-actuator", base_actuator, actuators.c_str(), actuator_name(BaseActuator::None))
                     .in(G::Detumble)
                     .checked([](const K& k) {
                       if (!find_base_actuator(k.base_actuator))
                         throw InputError(str("--base-actuator: expected ", base_actuator_names(), ", got '",
                                              k.base_actuator, "'"));
                     })
                     .echoed(echo_given("base-actuator", &K::base_actuator))
                     .acting([](const K& k) -> std::string {
                       return k.stop_stack_spin || k.base_actuator == actuator_name(BaseActuator::None)
                                  ? ""
                                  : "acts only when the run stops the stack's spin (stop-stack-spin = true)";
                     }));
  // a bound of the base actuator: positive, acting with its actuator only
  const auto bound = [&](ScenarioKey key, const char* name, double K::*member, const char* actuator) {
    add_positive_detumble_key(keys, std::move(key), name, member).acting(with_actuator(actuator));
  };
  bound(FFSR_KEY("wheel-torque", wheel_torque, "Detumble: reaction wheels' torque per base axis, N m"),
        "wheel-torque", &K::wheel_torque, actuator_name(BaseActuator::ReactionWheels));
  bound(FFSR_KEY("wheel-momentum", wheel_momentum,
                 "Detumble: reaction wheels' stored momentum per base axis, N m s"),
        "wheel-momentum", &K::wheel_momentum, actuator_name(BaseActuator::ReactionWheels));
  bound(FFSR_KEY("thruster-force", thruster_force, "Detumble: thrusters' force per base axis, N"),
        "thruster-force", &K::thruster_force, actuator_name(BaseActuator::Thrusters));
  bound(FFSR_KEY("thruster-torque", thruster_torque, "Detumble: thrusters' torque per base axis, N m"),
        "thruster-torque", &K::thruster_torque, actuator_name(BaseActuator::Thrusters));
  add_positive_detumble_key(keys, FFSR_KEY("gripper-force-limit", gripper_force_limit,
                 "Detumble: the gripper's force on the target, N (the controller keeps the load within it; "
                 "> 0; default: not limited)"),
        "gripper-force-limit", &K::gripper_force_limit);
  add_positive_detumble_key(keys, FFSR_KEY("gripper-moment-limit", gripper_moment_limit,
                 "Detumble: the gripper's moment on the target about the contact point, N m (the controller "
                 "keeps the load within it; > 0; default: not limited)"),
        "gripper-moment-limit", &K::gripper_moment_limit);
}

/// Where a start rate of the held stack acts: with grasp-after = held only.
inline std::string on_the_held_stack(const ScenarioKeys& k) {
  if (k.grasp_after == "held") return "";
  return str("acts with grasp-after = held only (the stack's rates at the start), and this scenario has "
             "grasp-after = ",
             k.grasp_after);
}

/// A start rate of the held stack: given with grasp-after = held only (it serves no other job, so a
/// file's is refused too), finite values, `size` of them (0: any count; the conversion,
/// held_start_state, checks one per joint against the robot).
inline void check_start_rates(const ScenarioKeys& k, const char* name, const std::vector<double>& v,
                              size_t size) {
  if (!k.given.count(name)) return;
  const std::string why = on_the_held_stack(k);
  if (!why.empty()) throw InputError(str("--", name, ": ", why));
  if (size != 0 && v.size() != size)
    throw InputError(str("--", name, ": expected ", size, " numbers, got ", v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(str("--", name, ": values must be finite, got ", x));
}

/// The held stack's start rates (grasp-after = held): checked and echoed when given, acting with held
/// only.
inline void add_held_start_keys(std::vector<ScenarioKey>& keys) {
  using K = ScenarioKeys;
  const auto held_key = [&keys](ScenarioKey key, const char* name, std::vector<double> K::*member,
                                size_t size) {
    keys.push_back(key.in(KeyGroup::Detumble)
                       .checked([name, member, size](const K& k) {
                         check_start_rates(k, name, k.*member, size);
                       })
                       .echoed(echo_given(name, member))
                       .acting(on_the_held_stack));
  };
  held_key(FFSR_KEY("start-joint-rates-deg", start_joint_rates_deg,
                    "Detumble, grasp-after = held: the joint rates at the start, deg/s (one per joint; "
                    "default 0)"),
           "start-joint-rates-deg", &K::start_joint_rates_deg, 0);
  held_key(FFSR_KEY("start-base-velocity", start_base_velocity,
                    "Detumble, grasp-after = held: the velocity of the base frame's origin at the start, m/s "
                    "(inertial axes; default 0,0,0)"),
           "start-base-velocity", &K::start_base_velocity, 3);
  held_key(FFSR_KEY("start-base-angular-velocity-deg", start_base_angular_velocity_deg,
                    "Detumble, grasp-after = held: the base's angular velocity at the start, deg/s (inertial "
                    "axes; default 0,0,0)"),
           "start-base-angular-velocity-deg", &K::start_base_angular_velocity_deg, 3);
}

/// The post-capture run's settings (the detumble job): rest, horizon, tick, the stack's spin.
inline void add_detumble_run_keys(std::vector<ScenarioKey>& keys) {
  using G = KeyGroup;
  using K = ScenarioKeys;
  add_positive_detumble_key(keys, FFSR_KEY("rest-rate-deg", rest_rate_deg,
                 "Detumble: at rest when every joint rate and the gripper's rate relative to the base "
                 "(and the stack's, with stop-stack-spin) are below this, deg/s", "0.05"),
        "rest-rate-deg", &K::rest_rate_deg);
  add_positive_detumble_key(keys, FFSR_KEY("detumble-horizon", detumble_horizon,
                 "Detumble: longest time to rest, s", "120"),
        "detumble-horizon", &K::detumble_horizon);
  keys.push_back(FFSR_KEY("detumble-tick", detumble_tick,
                          "Detumble: the controller's period, s (< detumble-horizon)", "0.01")
                     .in(G::Detumble)
                     .checked([](const K& k) {
                       check_positive_if_given(k, "detumble-tick", k.detumble_tick);
                       if (!(k.detumble_tick < k.detumble_horizon))
                         throw InputError(str("--detumble-tick: must be shorter than detumble-horizon (",
                                              k.detumble_horizon, " s), got ", k.detumble_tick));
                       const double span = k.detumble_horizon + k.detumble_dwell;
                       if (span / k.detumble_tick > 1e7)  // run_detumble's bound
                         throw InputError(str("--detumble-tick: at most 1e7 ticks in detumble-horizon + "
                                              "detumble-dwell (", span, " s), got ", k.detumble_tick, " s (",
                                              span / k.detumble_tick, " ticks)"));
                     })
                     .echoed(echo_given("detumble-tick", &K::detumble_tick)));
  keys.push_back(
      FFSR_KEY("detumble-dwell", detumble_dwell,
               "Detumble: after the first tick at rest the controller holds the stack this long, s (>= 0)", "5")
          .in(G::Detumble)
          .checked([](const K& k) {
            if (!std::isfinite(k.detumble_dwell) || k.detumble_dwell < 0)
              throw InputError(str("--detumble-dwell: must be >= 0 and finite, got ", k.detumble_dwell));
          })
          .echoed(echo_given("detumble-dwell", &K::detumble_dwell)));
  add_positive_detumble_key(keys, FFSR_KEY("detumble-max-decay", detumble_max_decay,
                 "Detumble: the fastest decay the law asks of the joint rates, 1/s (its bandwidth; at most half "
                 "the tick's inverse is used)", "20"),
        "detumble-max-decay", &K::detumble_max_decay);
  add_positive_detumble_key(keys, FFSR_KEY("detumble-max-base-decay", detumble_max_base_decay,
                 "Detumble: the fastest decay of the stack's momentum the base actuator is asked, 1/s (at "
                 "most half the tick's inverse is used)", "2"),
        "detumble-max-base-decay", &K::detumble_max_base_decay)
      .acting([](const K& k) -> std::string {
        return k.stop_stack_spin ? "" : "acts only when the run stops the stack's spin (stop-stack-spin = true)";
      });
  keys.push_back(
      FFSR_KEY("grasp-after", grasp_after,
               "Detumble: the grasp locks at the end of the approach, or after the Hertz contact run (the "
               "contact law's keys) at the separation; or the stack holds its target from the start state "
               "(held: the target welded where it is, the start-* keys' rates): approach, contact or held",
               "approach")
          .in(G::Detumble)
          .checked([](const K& k) {
            if (k.grasp_after != "approach" && k.grasp_after != "contact" && k.grasp_after != "held")
              throw InputError(
                  str("--grasp-after: expected approach, contact or held, got '", k.grasp_after, "'"));
          })
          .echoed(echo_given("grasp-after", &K::grasp_after)));
  add_held_start_keys(keys);
  keys.push_back(FFSR_KEY("stop-stack-spin", stop_stack_spin,
                          "Detumble: also stop the stack's spin (needs a base actuator; true/false)", "false")
                     .in(G::Detumble)
                     .echoed(echo_given("stop-stack-spin", &K::stop_stack_spin)));
}

/// The global search's constraints on the post-capture phase (jobs/detail/post_capture.hpp): each a
/// bound on a figure of the detumble run at the candidate capture configurations.
inline void add_post_capture_keys(std::vector<ScenarioKey>& keys) {
  using K = ScenarioKeys;
  const auto bound = [&keys](ScenarioKey key, const char* name, double K::*member) {
    keys.push_back(key.in(KeyGroup::PostCapture)
                       .checked([name, member](const K& k) { check_positive_if_given(k, name, k.*member); })
                       .echoed(echo_given(name, member))
                       .acting(on_the_global_run)
                       .skipping(skips_but_global));
  };
  bound(FFSR_KEY("max-time-to-rest", max_time_to_rest,
                 "Global search: longest post-capture run to rest, s (a constraint on the capture "
                 "configuration, by the detumble run under the Detumble keys; > 0; default: not limited)"),
        "max-time-to-rest", &K::max_time_to_rest);
  bound(FFSR_KEY("max-peak-joint-torque", max_peak_joint_torque,
                 "Global search: largest joint torque of the post-capture run, N m (a constraint; > 0, "
                 "below the largest joint-torque-limit)"),
        "max-peak-joint-torque", &K::max_peak_joint_torque);
  bound(FFSR_KEY("max-gripper-force", max_gripper_force,
                 "Global search: largest force of the gripper on the target after the grasp, N (a "
                 "constraint; > 0)"),
        "max-gripper-force", &K::max_gripper_force);
  bound(FFSR_KEY("max-gripper-moment", max_gripper_moment,
                 "Global search: largest moment of the gripper on the target after the grasp, N m (a "
                 "constraint; > 0)"),
        "max-gripper-moment", &K::max_gripper_moment);
}

}  // namespace detail
}  // namespace ffsr
