// Timings of the time-optimal post-capture plan (control/detumble_planner.hpp) on the published planar
// problem (robots/vyas2022_planar.urdf; Vyas et al. 2022, published 4.095 s): the cold solve (from the
// detumbling law's run, the law's run included) and the warm solve (from the previous plan), wall time
// over `--repeat` solves each (median, min, max), on all cores (the Jacobian's intervals on threads) and on
// one; the plan's T, IPOPT's iterations, and the CVODE re-run's check (at rest, every bound).
// Run (Release): build/bench/ffsr-bench-plan [robots/] [--repeat N]. Exit status 1 when a plan fails or
// its re-run is not at rest within the bounds; no budget on time (the figures go to docs/performance.md).

#include "ffsr/control/detumble_planner.hpp"
#include "ffsr/parsers/urdf.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace ffsr;
using Clock = std::chrono::steady_clock;

struct Stats {
  double median, min, max;
};

Stats stats(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v.front(), v.back()};
}

}  // namespace

int main(int argc, char** argv) {
  std::string robots = std::string(FFSR_SOURCE_DIR) + "/robots/";
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else robots = a + "/";
  }
  const Model robot = model_from_urdf_file(robots + "vyas2022_planar.urdf", "ee");
  AttachedBody body;
  body.mass = 50;
  body.inertia = Matrix3::Identity() * 3;
  body.pose.p = Vector3(0, 0, 0.35);
  const Model stack = attach_body(robot, "ee", body);
  const int ee = stack.frame_index("ee");
  DetumbleState start;
  start.theta = Eigen::Vector3d(-0.72, 1.2, 0.72);
  start.v = Eigen::VectorXd(9);
  start.v << -0.0124, 0, -0.0052, 0, 0.0042, 0, 0.0635, -0.1353, 0.1669;
  DetumbleLimits limits;
  limits.joint_torque = Eigen::Vector3d::Constant(0.5);
  limits.actuator = BaseActuator::Thrusters;
  limits.thruster_force = 2;
  limits.thruster_torque = 2.5;
  DetumbleOptions options;
  options.stop_stack_spin = true;
  options.rest_rate = 1e-3;
  int status = 0;
  std::printf("published planar problem (published 4.095 s), %d intervals, %u hardware threads\n",
              DetumblePlanOptions{}.intervals, std::thread::hardware_concurrency());
  for (const unsigned threads : {0u, 1u}) {
    DetumblePlanOptions po;
    po.threads = threads;
    std::vector<double> cold, warm;
    DetumblePlan plan, again;
    for (int r = 0; r < repeat; ++r) {
      auto t0 = Clock::now();
      plan = plan_detumble(stack, ee, body, start, limits, options, 30, po);
      cold.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      t0 = Clock::now();
      again = plan_detumble(stack, ee, body, start, limits, options, 30, po, &plan);
      warm.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
    DetumbleRunOptions run;
    run.dwell = 2;
    const DetumblePlanRun check = replay_detumble_plan(stack, ee, body, plan, limits, options, run);
    const Stats c = stats(cold), w = stats(warm);
    std::printf("threads %-4s T %.4f s (law %.2f s)  cold %.3f s [%.3f, %.3f] %d it  warm %.3f s [%.3f, %.3f] %d it  "
                "re-run: at rest %s, end rates %.2e %.2e %.2e %.2e, bound excess %.1e\n",
                threads == 0 ? "all" : "1", plan.duration, plan.warm_start_duration, c.median, c.min, c.max,
                plan.iterations, w.median, w.min, w.max, again.iterations, check.at_rest ? "yes" : "NO",
                check.end_joint_rate, check.end_relative_rate, check.end_base_rate, check.end_base_speed,
                check.worst_bound_excess);
    if (!check.at_rest || check.worst_bound_excess > 1e-9 || !check.dwell_at_rest) status = 1;
  }
  return status;
}
