// src/onboard/core_check.cpp -- the onboard headers that the C interface does not call, compiled into the
// core with its flags on every target, so that they stay free of exceptions and RTTI as well: the
// plan-tracking controller (control/detumble_tracker.hpp), its constructor and its step. scripts/onboard.sh
// checks the core's objects for exception and RTTI symbols and runs clang-tidy and cppcheck on this file.
#include "ffsr/control/detumble_tracker.hpp"

namespace ffsr::onboard_check {

/// The tracker built and stepped: what a C++ flight program following a plan compiles.
DetumblePlanTracker make_tracker(const Model& stack, int gripper, const AttachedBody& body, const DetumblePlan& plan,
                                 const DetumbleLimits& limits, const DetumbleOptions& options, double tick) {
  return DetumblePlanTracker(stack, gripper, body, plan, limits, options, tick);
}

void step_tracker(DetumblePlanTracker& tracker, const DetumbleState& s, double t, DetumbleCommand& out) noexcept {
  tracker.step(s, t, out);
}

}  // namespace ffsr::onboard_check
