// The closed loop of the capture controller (control/closed_loop.hpp) over seeds: capture error
// and M_ie against the open-loop plan, the global plan's servo (its capture configuration read from
// the stored baseline tests/data/baselines/<scenario>.json) on a paper scenario.

#include "support/baselines.hpp"

#include "ffsr/control/capture_controller.hpp"
#include "ffsr/control/closed_loop.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

// Run (Release): build/bench/ffsr-bench-closed-loop [--scenario paper_7dof_position] [--seeds 20]
//   [--control-rate 1000] [--estimate-rate 5] [--position-noise 0.005] [--attitude-noise-deg 0.5]
//   [--spin-noise-deg 0] [--policy servo|gradient] [--bandwidth 50] [--torque-limit 100] [--window 1]
//   [--first-seed 1] [--no-exact] [--integrator rk|cvode] [--rtol 1e-9] [--atol 1e-12] [--reference]
// Prints the exact-target run, one line per seed, then the worst and the median. Seeds first-seed to
// first-seed + seeds - 1: split a long study into processes run side by side (e.g. GNU parallel).
// --reference runs the exact target a second time with CVODE restarted at every tick
// (ClosedLoopIntegrator::CvodeRestart) at the default rtol and atol (--rtol and --atol set the
// measured run's) and prints the differences of capture error, M_ie and largest
// torque and the ratio of the two wall times. Times are wall clock of the simulation alone (the plan
// and the controller's construction are outside).

namespace {

using namespace ffsr;
using ffsr::test::global_configuration;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Run {
  ClosedLoopResult r;
  double seconds;
};

template <class Make>
Run run_once(Make&& make, const ClosedLoopOptions& o) {
  auto ctrl = make();
  const auto a = std::chrono::steady_clock::now();
  ClosedLoopResult r = simulate_closed_loop(ctrl, o);
  return {std::move(r), std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count()};
}

double relative(double a, double b) { return std::abs(a - b) / std::abs(b); }

void print(const char* label, const Run& x, double M_open) {
  std::printf(
      "%-10s capture error %10.6f mm  M_ie %10.8f kg (%+7.3f %%)  F_max %7.1f N  max torque %9.6f N m  "
      "max lag %8.2e rad/s  base turn %6.3f deg  |h| max %8.1e  %6.2f s\n",
      label, 1e3 * x.r.capture_error, x.r.M_ie, 100 * (x.r.M_ie - M_open) / M_open, x.r.f_max_closed_form,
      x.r.max_torque, x.r.max_tracking_lag, x.r.base_attitude_change * 180 / M_PI, x.r.max_momentum,
      x.seconds);
}

}  // namespace

int main(int argc, char** argv) {
  std::string name = "paper_7dof_position", policy = "servo";
  int seeds = 20, first_seed = 1;
  bool exact_run = true, reference = false;
  ControllerOptions copt;
  ClosedLoopOptions o;
  o.noise.position = 0.005;
  o.noise.attitude = 0.5 * M_PI / 180;
  for (int i = 1; i < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--no-exact" || a == "--reference") {  // flags without a value
      if (a == "--no-exact") exact_run = false;
      if (a == "--reference") reference = true;
      --i;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "bench_closed_loop: %s needs a value\n", a.c_str());
      return 2;
    }
    const double v = std::atof(argv[i + 1]);
    if (a == "--scenario")
      name = argv[i + 1];
    else if (a == "--policy")
      policy = argv[i + 1];
    else if (a == "--seeds")
      seeds = static_cast<int>(v);
    else if (a == "--first-seed")
      first_seed = static_cast<int>(v);
    else if (a == "--control-rate")
      o.control_rate = v;
    else if (a == "--estimate-rate")
      o.estimate_rate = v;
    else if (a == "--position-noise")
      o.noise.position = v;
    else if (a == "--attitude-noise-deg")
      o.noise.attitude = v * M_PI / 180;
    else if (a == "--spin-noise-deg")
      o.noise.angular_velocity = v * M_PI / 180;
    else if (a == "--bandwidth")
      o.loop.bandwidth = v;
    else if (a == "--window")
      copt.prediction_window = static_cast<int>(v);
    else if (a == "--torque-limit")
      o.loop.torque_limit = v;
    else if (a == "--rtol")
      o.rtol = v;
    else if (a == "--atol")
      o.atol = v;
    else if (a == "--integrator") {
      const std::string x = argv[i + 1];
      if (x != "rk" && x != "cvode") {
        std::fprintf(stderr, "bench_closed_loop: --integrator: expected rk or cvode, got %s\n", x.c_str());
        return 2;
      }
      o.integrator = x == "rk" ? ClosedLoopIntegrator::RungeKutta : ClosedLoopIntegrator::CvodeRestart;
    } else {
      std::fprintf(stderr, "bench_closed_loop: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  const Scenario sc = load_scenario(std::string(FFSR_SOURCE_DIR) + "/robots/" + name + ".toml");
  CaptureOptions g = sc.capture;
  Eigen::VectorXd goal;
  double M_open = 0;
  if (policy == "servo") {
    g.gain = 0.0;
    g.max_joint_rate = sc.keys.max_joint_rate_deg * M_PI / 180.0;
    goal = global_configuration(name);
    const CaptureSetup setup = prepare_capture(sc.problem, sc.task, g);
    ServoPolicy servo;
    servo.theta_goal = goal;
    M_open = integrate_capture(sc.problem, sc.task, g, setup, servo).M_ie;
  } else {
    M_open = plan_capture(sc.problem, sc.task, g).M_ie;
  }
  std::printf(
      "%s, %s plan: open-loop M_ie %.4f kg; control %.0f Hz, estimates %.1f Hz; rate loops %.0f rad/s, "
      "|tau| <= %.0f N m\n",
      name.c_str(), policy.c_str(), M_open, o.control_rate, o.estimate_rate, o.loop.bandwidth,
      o.loop.torque_limit);
  auto run = [&](const ClosedLoopOptions& opt) {
    if (policy == "servo")
      return run_once([&] { return make_servo_controller(sc.problem, sc.task, g, goal, 0.0, copt); }, opt);
    return run_once([&] { return make_gradient_controller(sc.problem, sc.task, g, copt); }, opt);
  };
  if (exact_run) {
    ClosedLoopOptions exact = o;
    exact.noise = {};
    const Run ex = run(exact);
    print("exact", ex, M_open);
    std::printf(
        "exact: %ld ticks, %ld %s steps (%ld refused), %ld saturated ticks, %ld damped, %ld rate-limited, "
        "max |p_e - x_d| %.2e m\n",
        ex.r.ticks, ex.r.integrator_steps,
        o.integrator == ClosedLoopIntegrator::RungeKutta ? "Runge-Kutta" : "CVODE", ex.r.rejected_steps,
        ex.r.saturated_ticks, ex.r.damped_ticks, ex.r.rate_limited_ticks, ex.r.max_reference_error);
    if (reference) {
      exact.integrator = o.integrator == ClosedLoopIntegrator::RungeKutta ? ClosedLoopIntegrator::CvodeRestart
                                                                          : ClosedLoopIntegrator::RungeKutta;
      exact.rtol = ClosedLoopOptions{}.rtol;  // the reference at the default tolerances
      exact.atol = ClosedLoopOptions{}.atol;
      const Run other = run(exact);
      print(exact.integrator == ClosedLoopIntegrator::CvodeRestart ? "CVODE" : "RK", other, M_open);
      std::printf(
          "against the other integrator: capture error %.3e m, M_ie %.3e relative, largest torque %.3e "
          "relative, |theta(T) difference| %.3e rad; wall time %.2f s / %.2f s = %.1fx\n",
          std::abs(ex.r.capture_error - other.r.capture_error), relative(ex.r.M_ie, other.r.M_ie),
          relative(ex.r.max_torque, other.r.max_torque), (ex.r.theta - other.r.theta).cwiseAbs().maxCoeff(),
          ex.seconds, other.seconds, other.seconds / ex.seconds);
    }
  }
  if (seeds <= 0) return 0;
  std::printf(
      "noise: position %.4f m, attitude %.3f deg, spin %.4f deg/s (1 sigma, per axis); prediction window "
      "%d\n",
      o.noise.position, o.noise.attitude * 180 / M_PI, o.noise.angular_velocity * 180 / M_PI,
      copt.prediction_window);
  std::vector<double> err, dM;
  for (int s = first_seed; s < first_seed + seeds; ++s) {
    o.seed = static_cast<std::uint64_t>(s);
    const Run x = run(o);
    char label[32];
    std::snprintf(label, sizeof label, "seed %d", s);
    print(label, x, M_open);
    err.push_back(1e3 * x.r.capture_error);
    dM.push_back(100 * std::abs(x.r.M_ie - M_open) / M_open);
  }
  std::printf(
      "over %d seeds: capture error worst %.3f mm, median %.3f mm; |M_ie - open loop| worst %.3f %%, median "
      "%.3f %%\n",
      seeds, *std::max_element(err.begin(), err.end()), median(err), *std::max_element(dM.begin(), dM.end()),
      median(dM));
  return 0;
}
