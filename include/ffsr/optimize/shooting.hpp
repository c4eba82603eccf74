// ffsr/optimize/shooting.hpp -- the reaching planner of the global capture optimization
// (plan_capture_global): the capture configuration is chosen first on the capture manifold
// (manifold_search.hpp), then the approach is planned to reach it.
#pragma once

#include "ffsr/optimize/manifold_search.hpp"
#include "ffsr/optimize/reconfigure.hpp"

#include <functional>
#include <optional>
#include <string>
#include <vector>

// The same line reference and time law as the paper's method, the task first, and the null space
// servoing to the chosen configuration (ServoPolicy in null_space.hpp), with the joint-rate limit.
// The base pose at T depends on the path, so it shoots: search at the base pose reached, plan again
// to the new optimum, until the reached objective is within `gap_percent` of the manifold optimum at
// the reached base pose. Needs NLopt (ffsr::global).

namespace ffsr {

struct GlobalCaptureOptions {
  ManifoldSearchOptions search;
  int max_iterations = 8;    ///< shooting iterations per goal before the goal is given up
  int max_goals = 6;         ///< local optima tried as goals, best first
  double gap_percent = 1.0;  ///< required (reached - optimum) / optimum at the reached base pose, %
  std::vector<Eigen::VectorXd> extra_starts;  ///< e.g. the paper's method's capture configuration
  /// A reconfiguration before the approach (reconfigure.hpp): never (the default), auto (only when
  /// the best goal is not reached by the approach alone) or always; its duration.
  ReconfigureOptions reconfigure;
  /// Optional check of a reaching run (its series recorded) and the time its approach begins (0, or
  /// the end of its reconfiguration): a message rejects the run, whose goal is then given up (e.g.
  /// the clearance along the path, optimize/clearance.hpp).
  std::function<std::optional<std::string>(const CaptureResult&, double approach_begin)> check_run;
  /// Optional constraint on candidate capture configurations that the search cannot take as an
  /// inequality (not smooth: the post-capture phase, jobs/detail/post_capture.hpp): one flag per
  /// configuration at the base pose, true when it meets the constraint (batched, so that it may run
  /// them in parallel). The goals, each full search's optimum and the reached run must meet it.
  std::function<std::vector<char>(const BasePose&, const std::vector<Eigen::VectorXd>&)> admit;
};

/// No candidate capture configuration of the search meets GlobalCaptureOptions::admit.
struct NoAdmittedCandidateError : InputError {
  using InputError::InputError;
};

/// What plan_capture_global did over every goal it tried: its counters and the last messages of what
/// failed. A result holds them as of its return, whichever goal's run it reports.
struct GlobalSearchCounters {
  int shooting_iterations = 0;     ///< reaching runs over every goal tried
  int goals_tried = 0;
  int goals_out_of_limits = 0;     ///< goals given up because the way to them crosses a joint limit
  long evaluations = 0;            ///< over every search
  long objective_evaluations = 0;  ///< multibody simulations over every search
  double search_seconds = 0;       ///< over every search
  int goals_rejected = 0;          ///< reached goals whose run check_run rejected
  int goals_not_admitted = 0;      ///< reached goals whose configuration admit rejected
  std::string rejection;           ///< the last rejection's message
  /// Empty when the task alone (no null-space motion) followed the line and gave the first base pose
  /// at T; otherwise its error (possible only with a reconfiguration allowed): the first search was at
  /// the initial base pose.
  std::string task_alone_failure;
  /// The error of the last reaching run that failed and whose goal was given up for it (an approach
  /// after a reconfiguration, or alone where a reconfiguration may follow); empty if none.
  std::string run_failure;
};

struct GlobalCaptureResult {
  CaptureResult run;                  ///< the reaching run (its capture configuration and checks)
  ManifoldSearchResult search;        ///< the last search, at the reached base pose
  double objective = 0;               ///< objective at the reached capture configuration
  double manifold_optimum = 0;        ///< objective at the optimum of C(reached base pose)
  double optimality_gap_percent = 0;  ///< 100 (objective - manifold_optimum) / manifold_optimum
  /// false: no better optimum than the one reached could be reached (it lies on another component
  /// of the self-motion manifold: the servo ended elsewhere); the gap then exceeds gap_percent
  bool reached_manifold_optimum = true;
  /// The phases of `run`: the approach alone, or the reconfiguration then the approach.
  std::vector<RunPhase> phases;
  bool reconfigured = false;  ///< `run` begins with a reconfiguration
  /// With a clearance (scenario/geometry.hpp): the distance bound of the searches, m (the
  /// clearance plus the margin of the round that planned the run); manifold_optimum is the optimum
  /// under it. 0: no distance bound.
  double search_distance_bound = 0;
  GlobalSearchCounters counters;  ///< over every goal tried, whichever goal's run `run` is
};

namespace detail {

inline void check_global_options(const GlobalCaptureOptions& g, const char* where) {
  if (g.max_iterations < 1) throw InputError(str(where, ": max_iterations must be >= 1"));
  if (g.max_goals < 1) throw InputError(str(where, ": max_goals must be >= 1"));
  if (!(g.gap_percent > 0)) throw InputError(str(where, ": gap_percent must be positive"));
}

/// Adds a search's evaluation counts and time to the planner's counters.
inline void account(GlobalSearchCounters& c, const ManifoldSearchResult& sr) {
  c.evaluations += sr.evaluations;
  c.objective_evaluations += sr.objective_evaluations;
  c.search_seconds += sr.seconds;
}

/// Pose task: the angle between the end-effector's orientation at (base, theta) and the final one
/// (0 for a position task). Runs crba.
inline double goal_orientation_error(const CaptureProblem& pb, const CaptureTask& task, const CaptureSetup& s,
                                     const BasePose& base, const Eigen::VectorXd& theta) {
  if (task.kind != CaptureTask::Kind::Pose) return 0.0;
  Data data(*pb.model);
  crba(*pb.model, data, base, theta);
  return rotation_angle(s.capture.R_end * frame_pose(*pb.model, data, pb.frame).R.transpose());
}

/// Drops the local optima whose end-effector is not in the final orientation (a residual that
/// vanishes at a half turn too lets them through) and makes the best remaining one res.best. The
/// result keeps at least one point (the best, even if off). Runs crba per optimum.
inline void drop_turned_optima(const CaptureProblem& pb, const CaptureTask& task, const CaptureSetup& s,
                               const BasePose& base, const GlobalCaptureOptions& g,
                               ManifoldSearchResult& res) {
  if (task.kind != CaptureTask::Kind::Pose || g.search.objective == GlobalObjective::MultibodyForce) return;
  std::vector<ManifoldPoint> kept;
  for (const ManifoldPoint& p : res.local_optima)
    if (goal_orientation_error(pb, task, s, base, p.theta) < 1e-4) kept.push_back(p);
  if (kept.empty() || kept.size() == res.local_optima.size()) return;
  res.local_optima = std::move(kept);
  res.best = res.local_optima.front();
}

/// The points of `points` that meet g.admit at `base` (all of them without it), order kept.
inline void admitted_only(const GlobalCaptureOptions& g, const BasePose& base,
                          std::vector<ManifoldPoint>& points) {
  if (!g.admit || points.empty()) return;
  std::vector<Eigen::VectorXd> thetas;
  for (const ManifoldPoint& p : points) thetas.push_back(p.theta);
  const std::vector<char> ok = g.admit(base, thetas);
  std::vector<ManifoldPoint> kept;
  for (size_t i = 0; i < points.size(); ++i)
    if (i < ok.size() && ok[i]) kept.push_back(points[i]);
  points = std::move(kept);
}

/// The best local optimum of `full` (sorted by objective) that meets g.admit at `base` becomes
/// full.best; the local optima stay as found. Unchanged when none meets it.
inline void best_admitted(const GlobalCaptureOptions& g, const BasePose& base, ManifoldSearchResult& full) {
  if (!g.admit) return;
  std::vector<ManifoldPoint> kept = full.local_optima;
  admitted_only(g, base, kept);
  if (!kept.empty()) full.best = kept.front();
}

/// The goals of plan_capture_global at the base pose of the task-only run: the best max_goals local
/// optima of a search from `extra` and random starts (multibody-force: the ranked ones), and the
/// local optima next to each extra start (on the component of the self-motion manifold the arm is
/// on, so reachable when the better ones are not), sorted by objective. Counts into `counters`.
inline std::vector<ManifoldPoint> capture_goals(const CaptureProblem& pb, const CaptureTask& task,
                                                const CaptureSetup& setup, const BasePose& base,
                                                const GlobalCaptureOptions& g,
                                                const std::vector<Eigen::VectorXd>& extra,
                                                GlobalSearchCounters& counters) {
  ManifoldSearchResult first = search_capture_manifold(pb, task, setup, base, g.search, extra);
  account(counters, first);
  drop_turned_optima(pb, task, setup, base, g, first);
  std::vector<ManifoldPoint> goals;
  for (const ManifoldPoint& p : first.local_optima)
    if (p.objective > 0) goals.push_back(p);  // multibody-force: the ranked ones
  auto by_objective = [](const ManifoldPoint& a, const ManifoldPoint& b) {
    return a.objective < b.objective;
  };
  std::stable_sort(goals.begin(), goals.end(), by_objective);
  admitted_only(g, base, goals);
  if (goals.size() > static_cast<size_t>(g.max_goals)) goals.resize(static_cast<size_t>(g.max_goals));
  std::vector<ManifoldPoint> near_goals;
  for (const Eigen::VectorXd& x : extra) {
    try {
      const ManifoldSearchResult near = detail::search_manifold(pb, task, setup, base, g.search, {x}, 0);
      account(counters, near);
      near_goals.push_back(near.best);
    } catch (const InputError&) {
    }
  }
  admitted_only(g, base, near_goals);
  goals.insert(goals.end(), near_goals.begin(), near_goals.end());
  if (goals.empty() && g.admit)
    throw NoAdmittedCandidateError(
        "no local optimum of the search at the first base pose meets the candidate constraint");
  std::stable_sort(goals.begin(), goals.end(), by_objective);
  return goals;
}

/// The shooting loop for one goal: reaching runs with ServoPolicy, the goal re-optimized locally at
/// each reached base pose, until the reached objective is within gap_percent of that local optimum;
/// then a full search at the reached base pose gives the gap. Returns that result (its counters left
/// empty: with_counters gives them), or nothing when the goal is given up: a joint limit on the way
/// (goals_out_of_limits), the goal off the manifold at the reached base pose, the run ending on
/// another component (more than 0.5 rad from the goal on some joint), or max_iterations spent. Counts
/// into `counters`.
/// t_r > 0: each run reconfigures the arm to the goal in t_r seconds first (plan_reconfigured_capture),
/// and a better optimum of the full search (on another component, which the reconfiguration can
/// reach) becomes the next goal while iterations remain.
inline std::optional<GlobalCaptureResult> reach_goal(const CaptureProblem& pb, const CaptureTask& task,
                                                     const CaptureOptions& run_opt, const CaptureSetup& setup,
                                                     const GlobalCaptureOptions& g, Eigen::VectorXd goal,
                                                     GlobalSearchCounters& counters, const char* where,
                                                     double t_r = 0) {
  for (int it = 1; it <= g.max_iterations; ++it) {
    ServoPolicy servo;
    servo.theta_goal = goal;
    ++counters.shooting_iterations;
    CaptureResult run;
    std::vector<RunPhase> phases;
    try {
      if (t_r > 0) {
        ReconfiguredRun rr = plan_reconfigured_capture(pb, task, run_opt, setup, goal, t_r, servo, where);
        run = std::move(rr.run);
        phases = std::move(rr.phases);
      } else {
        run = integrate_capture(pb, task, run_opt, setup, servo, where);
        phases = approach_only_phases(run, run_opt.duration);
      }
    } catch (const JointLimitError&) {
      ++counters.goals_out_of_limits;
      return std::nullopt;
    } catch (const NumericalError& e) {
      // the approach fails (after a reconfiguration, or alone where one may follow): give the goal
      // up; the approach alone without a reconfiguration to fall back on: the run's error
      if (t_r > 0 || g.reconfigure.mode != ReconfigureMode::Never) {
        counters.run_failure = e.what();
        return std::nullopt;
      }
      throw;
    }
    const ManifoldPoint reached = evaluate_capture(pb, setup, run.base, run.theta, g.search.objective,
                                                   g.search.multibody, g.search.robust.get());
    if (g.search.objective == GlobalObjective::MultibodyForce) ++counters.objective_evaluations;
    ManifoldSearchResult local;  // the goal re-optimized locally at the reached base pose
    try {
      local = detail::search_manifold(pb, task, setup, run.base, g.search, {goal}, 0);
    } catch (const InputError&) {
      return std::nullopt;
    }
    account(counters, local);
    // the servo leaves ~e^-10 of the error; the rest is the move of the manifold with the base pose,
    // small against the distance between components
    if (detail::configuration_distance(*pb.model, run.theta, local.best.theta) > 0.5) return std::nullopt;
    if (detail::exceeds_reach_tolerance(g.search.inequalities.get(), run.base, run.theta)) {  // outside
      goal = local.best.theta;
      continue;
    }
    const double local_gap = 100.0 * (reached.objective - local.best.objective) / local.best.objective;
    if (!std::isfinite(local_gap)) throw NumericalError(str(where, ": the optimality gap is not finite"));
    if (local_gap > g.gap_percent) {
      goal = local.best.theta;
      continue;
    }
    std::vector<Eigen::VectorXd> ex = g.extra_starts;  // the goal is reached: the whole manifold
    ex.push_back(goal);
    ex.push_back(run.theta);
    ManifoldSearchResult full = search_capture_manifold(pb, task, setup, run.base, g.search, ex);
    account(counters, full);
    drop_turned_optima(pb, task, setup, run.base, g, full);
    best_admitted(g, run.base, full);
    const double gap = 100.0 * (reached.objective - full.best.objective) / full.best.objective;
    if (t_r > 0 && gap > g.gap_percent && it < g.max_iterations) {
      goal = full.best.theta;  // reachable too: the reconfiguration moves to its component
      continue;
    }
    GlobalCaptureResult r;
    r.run = std::move(run);
    r.search = std::move(full);
    r.objective = reached.objective;
    r.manifold_optimum = r.search.best.objective;
    r.optimality_gap_percent = gap;
    r.reached_manifold_optimum = gap <= g.gap_percent;
    r.phases = std::move(phases);
    r.reconfigured = t_r > 0;
    return r;
  }
  return std::nullopt;
}

/// InputError unless the reconfiguration duration is 0 (not set) or lies in (0, duration).
inline void check_reconfiguration_duration(double t_r, double duration, const char* where) {
  if (!std::isfinite(t_r) || t_r < 0 || (t_r > 0 && t_r >= duration))
    throw InputError(
        str(where, ": the reconfiguration duration must lie in (0, ", duration, ") s, got ", t_r));
}

/// A reached goal's result (reach_goal: without counters) with the counters of every goal tried.
inline GlobalCaptureResult with_counters(GlobalCaptureResult best, const GlobalSearchCounters& counters) {
  best.counters = counters;
  return best;
}

}  // namespace detail

namespace detail {

/// The task alone (no null-space motion) in plan_capture_global: its capture configuration joins
/// `extra` and its base pose at T is returned (the first search's); a rate limit below what it needs
/// is an InputError. With a reconfiguration allowed, a task the arm cannot follow from its start (a
/// grasp orientation far from the initial one, an algorithmic singularity on the way) is no error:
/// its failure goes into counters.task_alone_failure and the initial base pose is returned, and the
/// reconfiguration moves the arm to where the approach works.
inline BasePose task_alone_base(const CaptureProblem& pb, const CaptureTask& task,
                                const CaptureOptions& quiet, const CaptureSetup& setup,
                                const GlobalCaptureOptions& g, const char* where,
                                std::vector<Eigen::VectorXd>& extra, GlobalSearchCounters& counters) {
  ServoPolicy none;
  try {
    const CaptureResult plain = integrate_capture(pb, task, quiet, setup, none, where);
    if (quiet.max_joint_rate > 0 && plain.max_joint_rate > quiet.max_joint_rate)
      throw JointRateLimitError(str(where, ": max joint rate ", quiet.max_joint_rate * 180 / M_PI,
                                    " deg/s is below what the task alone needs (",
                                    plain.max_joint_rate * 180 / M_PI, " deg/s)"));
    extra.push_back(plain.theta);
    return plain.base;
  } catch (const NumericalError& e) {
    if (g.reconfigure.mode == ReconfigureMode::Never) throw;
    counters.task_alone_failure = e.what();
  }
  return pb.base;
}

/// The goal reached with a reconfiguration first: in the given duration, or the default one for
/// the goal (default_reconfiguration_duration). A default duration fits the first goal; a goal that
/// moved while shooting may need more: that goal is then not reached (nothing), the next is tried.
/// A given duration is the user's: its ReconfigurationRateError propagates.
inline std::optional<GlobalCaptureResult> reach_reconfigured(
    const CaptureProblem& pb, const CaptureTask& task, const CaptureOptions& run_opt,
    const CaptureSetup& setup, const GlobalCaptureOptions& g, const Eigen::VectorXd& goal,
    GlobalSearchCounters& counters, const char* where) {
  const double t_r = g.reconfigure.duration > 0
                         ? g.reconfigure.duration
                         : default_reconfiguration_duration(*pb.model, pb.theta, goal, run_opt);
  try {
    return reach_goal(pb, task, run_opt, setup, g, goal, counters, where, t_r);
  } catch (const ReconfigurationRateError&) {
    if (g.reconfigure.duration > 0) throw;
  }
  return std::nullopt;
}

/// Drops a reached goal's run that g.admit or g.check_run rejects (the clearance along the path), counted
/// with its message in `counters`.
inline void check_reached(const GlobalCaptureOptions& g, GlobalSearchCounters& counters,
                          std::optional<GlobalCaptureResult>& r) {
  if (r && g.admit && !g.admit(r->run.base, {r->run.theta}).at(0)) {
    ++counters.goals_not_admitted;
    counters.rejection = "the reached capture configuration does not meet the candidate constraint";
    r.reset();
  }
  if (!r || !g.check_run) return;
  if (std::optional<std::string> why = g.check_run(r->run, r->reconfigured ? r->phases.front().t_end : 0.0)) {
    ++counters.goals_rejected;
    counters.rejection = *why;
    r.reset();
  }
}

/// The error when no goal was reached, with what was tried and why the runs failed.
inline NumericalError no_goal_reached(const GlobalSearchCounters& c, const char* where) {
  return NumericalError(str(
      where, ": no capture configuration chosen by the search was reached (", c.goals_tried, " goals, ",
      c.goals_out_of_limits, " of them behind a joint limit, ", c.shooting_iterations, " reaching runs)",
      c.goals_rejected + c.goals_not_admitted ? str("; the last reached goal was rejected: ", c.rejection)
                                              : "",
      c.task_alone_failure.empty() ? "" : str("; the task alone failed: ", c.task_alone_failure),
      c.run_failure.empty() ? "" : str("; the last reaching run that failed: ", c.run_failure)));
}

}  // namespace detail

/// Global capture planning (see the notes after the includes). Goals are the local optima of the search at
/// the base pose of the task-only run, best first. For each goal: plan the reaching run, re-optimize
/// the goal locally at the reached base pose, repeat until the reached objective is within
/// gap_percent of that local optimum (the goal is then reached) or the run ends away from it (the
/// goal lies on another component of the self-motion manifold: next goal). A reached goal is checked
/// against a full search at the reached base pose: within gap_percent of its optimum, done.
/// Otherwise the best reached goal is returned with reached_manifold_optimum = false and the gap
/// as measured. opt.gain is not used; opt.max_joint_rate limits the joint rates (0: not limited).
/// Throws InputError for bad arguments (as plan_capture, plus a rate limit below what the task alone
/// needs), NumericalError when a run fails the checks of integrate_capture or no goal is reached.
/// A reaching run that would leave a joint's limits gives its goal up (goals_out_of_limits).
/// g.reconfigure (reconfigure.hpp): never, the approach alone; always, every goal reached with a
/// reconfiguration first; auto, each goal with the approach alone first, then, unless reached,
/// with a reconfiguration. A reconfiguration the joint-rate limit does not allow in its time throws
/// ReconfigurationRateError (an InputError). With a reconfiguration allowed (auto, always), a task
/// the arm cannot follow from its start is no error: the failure of the task alone goes into
/// task_alone_failure, the first search is at the initial base pose, and an approach alone that fails
/// gives its goal up to the reconfiguration.
inline GlobalCaptureResult plan_capture_global(const CaptureProblem& pb, const CaptureTask& task,
                                               const CaptureOptions& opt, const GlobalCaptureOptions& g) {
  using detail::str;
  const char* where = "plan_capture_global";
  CaptureOptions o = opt;
  o.gain = 0.0;
  o.progress = nullptr;
  const CaptureSetup setup = prepare_capture(pb, task, o, where);
  detail::check_global_options(g, where);
  detail::check_reconfiguration_duration(g.reconfigure.duration, o.duration, where);
  CaptureOptions quiet = o;
  quiet.record_series = false;

  GlobalSearchCounters counters;
  std::vector<Eigen::VectorXd> extra = g.extra_starts;
  const BasePose first_base = detail::task_alone_base(pb, task, quiet, setup, g, where, extra, counters);
  std::vector<ManifoldPoint> goals;
  try {
    goals = detail::capture_goals(pb, task, setup, first_base, g, extra, counters);
  } catch (const InputError& e) {  // e.g. a capture point out of reach: the task alone's error first
    if (counters.task_alone_failure.empty()) throw;
    throw NumericalError(
        str(counters.task_alone_failure, "; the search at the initial base pose: ", e.what()));
  }

  CaptureOptions run_opt = quiet;
  run_opt.record_series = opt.record_series || static_cast<bool>(g.check_run);
  std::optional<GlobalCaptureResult> fallback;
  const ReconfigureMode mode = g.reconfigure.mode;
  for (const ManifoldPoint& goal : goals) {
    ++counters.goals_tried;
    // the approach alone first (not for always), then (not for never) with a reconfiguration
    for (const bool reconfigure : {false, true}) {
      if (reconfigure ? mode == ReconfigureMode::Never : mode == ReconfigureMode::Always) continue;
      std::optional<GlobalCaptureResult> r =
          reconfigure ? detail::reach_reconfigured(pb, task, run_opt, setup, g, goal.theta, counters, where)
                      : detail::reach_goal(pb, task, run_opt, setup, g, goal.theta, counters, where);
      detail::check_reached(g, counters, r);
      if (r && r->reached_manifold_optimum) return detail::with_counters(std::move(*r), counters);
      if (r && (!fallback || r->objective < fallback->objective)) fallback = std::move(r);
    }
  }
  if (fallback) return detail::with_counters(std::move(*fallback), counters);
  throw detail::no_goal_reached(counters, where);
}

}  // namespace ffsr
