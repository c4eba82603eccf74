// ffsr/control/detail/detumble_planner.hxx -- body of ffsr/control/detumble_planner.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#if defined(__unix__) || defined(__APPLE__)
#include <dlfcn.h>
#endif

namespace ffsr {

namespace detail {

inline void check_detumble_plan_options(const DetumblePlanOptions& po, double horizon) {
  constexpr const char* w = "plan_detumble";
  if (po.intervals < 2 || po.intervals > 2000)
    throw InputError(str(w, ": the intervals must be in [2, 2000], got ", po.intervals));
  if (po.substeps < 1 || po.substeps > 50)
    throw InputError(str(w, ": the substeps must be in [1, 50], got ", po.substeps));
  if (!std::isfinite(po.effort_weight) || po.effort_weight < 0)
    throw InputError(str(w, ": the effort weight must be >= 0 and finite, got ", po.effort_weight));
  if (!std::isfinite(po.tolerance) || !(po.tolerance > 0))
    throw InputError(str(w, ": the tolerance must be positive and finite, got ", po.tolerance));
  if (!std::isfinite(po.optimality) || !(po.optimality > 0))
    throw InputError(str(w, ": the optimality tolerance must be positive and finite, got ", po.optimality));
  if (std::isnan(po.max_joint_rate) || !(po.max_joint_rate > 0))
    throw InputError(str(w, ": the largest joint rate must be positive (infinity: none), got ", po.max_joint_rate));
  if (po.max_iterations < 1) throw InputError(str(w, ": max_iterations must be >= 1, got ", po.max_iterations));
  if (!std::isfinite(po.tick) || po.tick < 0)
    throw InputError(str(w, ": the tick must be >= 0 and finite (0: none), got ", po.tick));
  if (!std::isfinite(horizon) || !(horizon > 0))
    throw InputError(str(w, ": the horizon must be positive and finite, got ", horizon));
}

/// The fraction of the gripper's limits the initial guess's law keeps within.
inline constexpr double kDetumbleGuessGripperFraction = 0.9;

/// The initial guess from the detumbling law's run on the planner's own integrator (RK4 over each
/// tick, the command held in the inertial frame as the onboard law holds it), sampled at the nodes:
/// the states interpolated, each interval's controls the mean of the law's commands over it (base frame,
/// scaled by the bounds, within [-1, 1]). Returns the law's time to rest (the horizon if never).
inline double detumble_law_guess(DetumblePlanNlp& nlp, const Model& stack, int gripper, const AttachedBody& body,
                                 const DetumbleState& start, const DetumbleLimits& limits,
                                 const DetumbleOptions& options, double horizon, int N, Eigen::VectorXd& x) {
  const int n = stack.n(), ny = nlp.ny(), nu = nlp.nu();
  const double tick = std::min(0.01, 0.5 * detumble_longest_tick(stack, gripper, start));
  // the law within nine tenths of the gripper's limits: a guess strictly inside the gripper's rows (the
  // law's run sits on a limit that binds, where the interior point starts badly)
  DetumbleLimits inside = limits;
  inside.gripper_force *= kDetumbleGuessGripperFraction;
  inside.gripper_moment *= kDetumbleGuessGripperFraction;
  DetumbleController ctrl(stack, gripper, body, inside, options, tick);
  DetumbleCommand cmd = ctrl.make_command();
  auto& w = nlp.work0();
  w.y = nlp.start();
  std::vector<Eigen::VectorXd> ys{w.y}, us;
  const bool thrusters = limits.actuator == BaseActuator::Thrusters;
  const bool wheels = limits.actuator == BaseActuator::ReactionWheels;
  const auto ticks = static_cast<long>(std::ceil(horizon / tick));
  double T = horizon;
  for (long k = 0; k < ticks; ++k) {
    ctrl.step(w.sys.unpack(w.y), cmd);
    if (cmd.status == DetumbleStatus::Fault) break;
    const bool slow = !(thrusters && options.stop_stack_spin) || w.y.segment<3>(7 + n).norm() < options.rest_rate;
    if (cmd.status == DetumbleStatus::AtRest && slow) {
      T = std::max(static_cast<double>(k) * tick, 2 * tick);
      break;
    }
    const Matrix3 R = Quaternion(w.y(6), w.y(3), w.y(4), w.y(5)).normalized().toRotationMatrix();
    Eigen::VectorXd u(nu);
    u.head(n) = cmd.tau;
    if (thrusters) u.tail(6) << R.transpose() * cmd.base_wrench.head<3>(), R.transpose() * cmd.base_wrench.tail<3>();
    if (wheels) u.tail(3) = R.transpose() * cmd.base_wrench.tail<3>();
    us.push_back(u.cwiseQuotient(nlp.scale()).cwiseMax(-1.0).cwiseMin(1.0));
    nlp.step_held(w, cmd, tick, 2);
    ys.push_back(w.y);
  }
  if (us.empty()) us.push_back(Eigen::VectorXd::Zero(nu));
  x.resize(nlp.num_vars());
  x(0) = T;
  const double h = T / N;
  const auto at = [&](double t) {  // the state at t, linear between ticks
    const double s = std::min(t / tick, static_cast<double>(ys.size() - 1));
    const auto i = static_cast<size_t>(std::floor(s));
    const size_t j = std::min(i + 1, ys.size() - 1);
    Eigen::VectorXd y = ys[i] + (s - static_cast<double>(i)) * (ys[j] - ys[i]);
    y.segment<4>(3).normalize();
    return y;
  };
  for (int k = 0; k <= N; ++k) x.segment(nlp.oy(k), ny) = k == 0 ? nlp.start() : at(k * h);
  for (int k = 0; k < N; ++k) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(nu);
    int c = 0;
    for (auto i = static_cast<size_t>(k * h / tick); i < us.size() && static_cast<double>(i) * tick < (k + 1) * h; ++i, ++c)
      u += us[i];
    if (c == 0) u = us[std::min(static_cast<size_t>(k * h / tick), us.size() - 1)];
    else u /= c;
    x.segment(nlp.ou(k), nu) = u;
  }
  return T;
}

/// The initial guess from a previous plan: T, and the nodes and controls resampled to N intervals.
inline void detumble_plan_guess(DetumblePlanNlp& nlp, const DetumblePlan& p, int N, Eigen::VectorXd& x) {
  x.resize(nlp.num_vars());
  x(0) = p.duration;
  const DetumbleSystem& sys = nlp.work0().sys;
  const int M = p.intervals();
  for (int k = 0; k <= N; ++k) {
    const double s = static_cast<double>(k) * M / N;
    const int i = std::min(static_cast<int>(std::floor(s)), M);
    const int j = std::min(i + 1, M);
    Eigen::VectorXd y = sys.pack(p.nodes[static_cast<size_t>(i)]);
    y += (s - i) * (sys.pack(p.nodes[static_cast<size_t>(j)]) - y);
    y.segment<4>(3).normalize();
    x.segment(nlp.oy(k), nlp.ny()) = k == 0 ? nlp.start() : y;
  }
  const int n = static_cast<int>(p.tau.front().size()), nu = nlp.nu();
  for (int k = 0; k < N; ++k) {
    const auto i = static_cast<size_t>(std::min(M - 1, static_cast<int>((k + 0.5) * M / N)));
    Eigen::VectorXd u(nu);
    u.head(n) = p.tau[i];
    if (nu - n == 6) u.tail(6) = p.base_wrench[i];
    if (nu - n == 3) u.tail(3) = p.base_wrench[i].tail<3>();
    x.segment(nlp.ou(k), nu) = u.cwiseQuotient(nlp.scale()).cwiseMax(-1.0).cwiseMin(1.0);
  }
}

/// OpenBLAS, when it is the BLAS that IPOPT's MUMPS calls, on one thread for the solve (the previous
/// count restored after): its threaded kernels sum in an order that depends on the thread count, and the
/// interior point's path, so the plan's last digits, with it (measured: 0.1285903 s on two threads,
/// 0.1285940 s on one). Another BLAS: nothing to do.
class OneBlasThread {
 public:
  OneBlasThread() {
#if defined(__unix__) || defined(__APPLE__)
    get_ = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
    set_ = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (get_ && set_) {
      saved_ = get_();
      set_(1);
    }
#endif
  }
  ~OneBlasThread() {
    if (saved_ > 0) set_(saved_);
  }
  OneBlasThread(const OneBlasThread&) = delete;
  OneBlasThread& operator=(const OneBlasThread&) = delete;

 private:
  int (*get_)() = nullptr;
  void (*set_)(int) = nullptr;
  int saved_ = -1;
};

/// IPOPT's settings for the plan (see the top of detumble_planner.hpp); `warm`: near the solution, a
/// small barrier and the start kept near its bounds.
inline void set_ipopt_options(Ipopt::OptionsList& opt, const DetumblePlanOptions& po, bool warm) {
  opt.SetStringValue("sb", "yes");
  opt.SetIntegerValue("print_level", po.print_level);
  opt.SetStringValue("hessian_approximation", "limited-memory");
  opt.SetNumericValue("tol", po.optimality);
  opt.SetNumericValue("constr_viol_tol", po.tolerance);
  opt.SetNumericValue("acceptable_constr_viol_tol", po.tolerance);
  opt.SetNumericValue("bound_relax_factor", 0);
  opt.SetIntegerValue("max_iter", po.max_iterations);
  opt.SetStringValue("mu_strategy", po.adaptive_mu ? "adaptive" : "monotone");
  opt.SetIntegerValue("limited_memory_max_history", po.history);
  opt.SetStringValue("limited_memory_update_type", po.sr1 ? "sr1" : "bfgs");
  opt.SetNumericValue("acceptable_tol", 100 * po.optimality);
  opt.SetIntegerValue("acceptable_iter", 10);
  if (warm) {
    opt.SetNumericValue("mu_init", 1e-5);
    opt.SetNumericValue("bound_push", 1e-6);
    opt.SetNumericValue("bound_frac", 1e-6);
  }
}

/// The plan of the NLP's solution x.
inline void plan_from_solution(const DetumblePlanNlp& nlp, const Eigen::VectorXd& x, int n, int N, DetumblePlan& plan) {
  plan.duration = x(0);
  const DetumbleSystem sys(nlp.stack());
  const int ny = nlp.ny(), nu = nlp.nu();
  for (int k = 0; k <= N; ++k) plan.nodes.push_back(sys.unpack(x.segment(nlp.oy(k), ny)));
  for (int k = 0; k < N; ++k) {
    const Eigen::VectorXd u = x.segment(nlp.ou(k), nu).cwiseProduct(nlp.scale());
    plan.tau.push_back(u.head(n));
    Vector6 b = Vector6::Zero();
    if (nu - n == 6) b = u.tail(6);
    if (nu - n == 3) b.tail<3>() = u.tail(3);
    plan.base_wrench.push_back(b);
  }
}

/// Solves `nlp` from the guess x0: the plan, or DetumblePlanError naming `w` with IPOPT's status and
/// the residual it reached.
inline DetumblePlan solve_detumble_plan(const Ipopt::SmartPtr<DetumblePlanNlp>& nlp, const Eigen::VectorXd& x0,
                                        const DetumblePlanOptions& po, bool warm, int n, const char* w) {
  nlp->set_guess(x0);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  set_ipopt_options(*app->Options(), po, warm);
  if (app->Initialize() != Ipopt::Solve_Succeeded) throw NumericalError(str(w, ": IPOPT could not be initialised"));
  Ipopt::ApplicationReturnStatus st;
  {
    const OneBlasThread one;
    st = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(nlp)));
  }
  DetumblePlan plan;
  plan.status = ipopt_status_name(st);
  plan.iterations = IsValid(app->Statistics()) ? app->Statistics()->IterationCount() : 0;
  const Eigen::VectorXd& x = nlp->solution();
  const double viol = x.size() == nlp->num_vars() ? nlp->violation(x) : std::numeric_limits<double>::infinity();
  plan.constraint_violation = viol;
  const bool ok = (st == Ipopt::Solve_Succeeded || st == Ipopt::Solved_To_Acceptable_Level) && viol <= po.tolerance;
  if (!ok)
    throw DetumblePlanError(str(w, ": IPOPT did not converge (", plan.status, " after ", plan.iterations,
                                " iterations; the constraints' residual reached ", viol, ", asked ", po.tolerance, ")"),
                            plan.status, viol);
  plan_from_solution(*nlp, x, n, po.intervals, plan);
  plan.substeps = nlp->substeps();
  return plan;
}

/// Whether the plan's controls, held as planned and re-run by CVODE (replay_detumble_plan, without the
/// dwell), bring the stack to rest at T: the plan is the dynamics', not the integrator's.
inline bool plan_rests(const Model& stack, int gripper, const AttachedBody& body, const DetumblePlan& plan,
                       const DetumbleLimits& limits, const DetumbleOptions& options) {
  DetumbleRunOptions r;
  r.tick = plan.interval();
  r.horizon = 2 * plan.duration;
  r.dwell = 0;
  r.record_every = 0;
  return replay_detumble_plan(stack, gripper, body, plan, limits, options, r).at_rest;
}

/// The plan `free` solved again on intervals no shorter than `po.tick` (DetumblePlanOptions::tick):
/// N = ceil(free T / tick) intervals and T >= N tick, from `free` resampled; N + 1 when N fails. T
/// within 1e-3 of N tick (the bound active, but for the barrier's margin) is then fixed to it, from that
/// solution, with the controls of least effort: the tick's grid (that plan kept if this solve fails).
/// The free plan when neither N solves.
inline DetumblePlan plan_on_tick_grid(const Model& stack, int gripper, const AttachedBody& body,
                                      const DetumbleState& start, const DetumbleLimits& limits,
                                      const DetumbleOptions& options, double horizon, const DetumblePlanOptions& po,
                                      const DetumblePlan& free) {
  constexpr const char* w = "plan_detumble";
  DetumblePlanOptions g = po;
  g.substeps = std::max(po.substeps, free.substeps);
  g.max_iterations = std::min(po.max_iterations, 500);  // from the free plan: a few tens when it solves
  const int first = std::max(2, static_cast<int>(std::ceil(free.duration / po.tick - 1e-9)));
  for (int N = first; N <= std::min(2000, first + 1) && N * po.tick <= horizon; ++N) {
    g.intervals = N;
    Ipopt::SmartPtr<DetumblePlanNlp> nlp = new DetumblePlanNlp(stack, gripper, body, start, limits, options, horizon, g);
    nlp->set_min_duration(N * po.tick);
    Eigen::VectorXd x0;
    detumble_plan_guess(*nlp, free, N, x0);
    x0(0) = N * po.tick;
    try {
      DetumblePlan p = solve_detumble_plan(nlp, x0, g, true, stack.n(), w);
      if (p.duration <= N * po.tick * (1 + 1e-3)) {  // the bound active, to the barrier's margin: T fixed on it
        DetumblePlanOptions e = g;  // with T fixed, the controls of least effort (the weight 1 when zero)
        if (!(e.effort_weight > 0)) e.effort_weight = 1;
        nlp = new DetumblePlanNlp(stack, gripper, body, start, limits, options, horizon, e);
        nlp->set_fixed_duration(N * po.tick);
        detumble_plan_guess(*nlp, p, N, x0);
        x0(0) = N * po.tick;
        try {
          const int it = p.iterations;
          p = solve_detumble_plan(nlp, x0, e, true, stack.n(), w);
          p.iterations += it;
        } catch (const DetumblePlanError&) {
          // keep the plan on intervals a little longer than the tick (the tracker follows it)
        }
      }
      p.iterations += free.iterations;
      p.warm_start_duration = free.warm_start_duration;
      p.free_duration = free.duration;
      return p;
    } catch (const DetumblePlanError&) {
      // the next N, then the free plan
    }
  }
  return free;
}

}  // namespace detail

inline DetumblePlan plan_detumble(const Model& stack, int gripper, const AttachedBody& body,
                                  const DetumbleState& start, const DetumbleLimits& limits,
                                  const DetumbleOptions& options, double horizon, const DetumblePlanOptions& po,
                                  const DetumblePlan* warm) {
  const auto t_start = std::chrono::steady_clock::now();
  constexpr const char* w = "plan_detumble";
  detail::check_detumble_plan_options(po, horizon);
  DetumbleRunOptions check;
  check.horizon = horizon;
  check.tick = horizon / 2;
  detail::check_detumble_run(stack, gripper, body, start, check);
  if (stack.nb() - 1 != stack.n()) throw InputError(detail::str(w, ": the model has mimic joints"));
  const bool none = limits.actuator == BaseActuator::None;
  if (none) check_detumble_feasible(stack, start, limits, options, horizon);
  detail::check_detumble(stack, limits, options, w);
  if (!none) check_detumble_feasible(stack, start, limits, options, horizon);
  if (warm) detail::check_detumble_plan(stack, *warm, w);

  const int N = po.intervals;
  Ipopt::SmartPtr<detail::DetumblePlanNlp> nlp =
      new detail::DetumblePlanNlp(stack, gripper, body, start, limits, options, horizon, po);
  Eigen::VectorXd x0;
  double guess_duration = 0;
  if (warm) {
    detail::detumble_plan_guess(*nlp, *warm, N, x0);
    guess_duration = warm->duration;
  } else {
    guess_duration = detail::detumble_law_guess(*nlp, stack, gripper, body, start, limits, options, horizon, N, x0);
  }
  DetumblePlan plan = detail::solve_detumble_plan(nlp, x0, po, warm != nullptr, stack.n(), w);
  // a plan whose re-run misses rest is the integrator's: solved again from it with twice the substeps
  for (int again = 0; again < 3 && nlp->substeps() < 50 &&
                      !detail::plan_rests(stack, gripper, body, plan, limits, options);
       ++again) {
    DetumblePlanOptions finer = po;
    finer.substeps = std::min(50, 2 * nlp->substeps());
    const int iterations = plan.iterations;
    nlp = new detail::DetumblePlanNlp(stack, gripper, body, start, limits, options, horizon, finer);
    detail::detumble_plan_guess(*nlp, plan, N, x0);
    plan = detail::solve_detumble_plan(nlp, x0, finer, true, stack.n(), w);
    plan.iterations += iterations;
  }
  plan.warm_start_duration = guess_duration;
  if (po.tick > 0 && plan.interval() < po.tick * (1 - 1e-9))
    plan = detail::plan_on_tick_grid(stack, gripper, body, start, limits, options, horizon, po, plan);
  plan.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return plan;
}

}  // namespace ffsr
