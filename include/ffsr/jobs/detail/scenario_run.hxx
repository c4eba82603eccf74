// ffsr/jobs/detail/scenario_run.hxx -- bodies of ffsr/jobs/scenario_run.hpp: the runs of the main job.
#pragma once

#include "ffsr/detail/parallel.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>

namespace ffsr {

namespace detail {

/// The options of the plain (`plain` true: gain 0, the baseline task) or the optimized run.
inline CaptureOptions row_options(const Scenario& sc, const ScenarioRunOptions& options, bool plain) {
  CaptureOptions opt = sc.capture;
  opt.record_series = opt.record_series || options.record_series || sc.geometry;  // distances along the path
  if (plain) {
    opt.gain = 0.0;
    opt.progress = options.plain_progress;
  } else {
    opt.hold_base_attitude = sc.hold_base_attitude;  // the optimized run only
    opt.progress = options.optimized_progress;
  }
  add_clearance_barrier(sc, opt);  // with a clearance: both runs keep it in their null space
  return opt;
}

/// The plain or the optimized run; a NumericalError names it ("plain run: ...").
inline CaptureResult plan_row(const Scenario& sc, const ScenarioRunOptions& options, bool plain) {
  if (sc.scope != ScenarioScope::Run)  // a programming error: the caller resolves the rest (resolve_run)
    throw std::invalid_argument("the main job's runs need a scenario of scope Run (resolve_run)");
  const CaptureOptions opt = row_options(sc, options, plain);
  try {
    return plan_capture(sc.problem, plain ? sc.baseline_task : sc.task, opt);
  } catch (const NumericalError& e) {
    throw NumericalError(str(plain ? "plain" : "optimized", " run: ", e.what()));
  }
}

}  // namespace detail

inline std::pair<CaptureResult, CaptureResult> plan_plain_and_optimized(const Scenario& sc,
                                                                        const ScenarioRunOptions& options) {
  CaptureResult base_run = detail::plan_row(sc, options, true);
  CaptureResult opt_run = detail::plan_row(sc, options, false);
  return {std::move(base_run), std::move(opt_run)};
}

inline std::shared_ptr<RobustForceObjective> scenario_robust_objective(const Scenario& sc,
                                                                       const UncertaintySpec& spec) {
  UncertainNominal nominal;
  nominal.target = propagate_target(sc.problem.target, sc.capture.duration);
  nominal.contact = sc.problem.contact;
  nominal.approach_speed = sc.problem.approach_speed;
  UncertaintySpec s = spec;
  s.seed = robust_objective_seed(spec);
  std::vector<UncertainSample> samples(s.samples);
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  detail::parallel_for(s.samples, threads, [&](std::uint64_t i) { samples[i] = draw_sample(s, nominal, i); });
  return std::make_shared<RobustForceObjective>(std::move(samples), sc.problem.law);
}

namespace detail {

/// The post-capture constraints (max-time-to-rest, ...) as the search's candidate constraint g.admit;
/// null without them.
inline std::shared_ptr<PostCaptureScreen> post_capture_screen(const Scenario& sc, const CaptureOptions& opt,
                                                              GlobalCaptureOptions& g) {
  if (!post_capture_constraints(sc.keys).any()) return nullptr;
  const Target at_capture = prepare_capture(sc.problem, sc.task, opt).capture.target;
  auto screen = std::make_shared<PostCaptureScreen>(sc, at_capture);
  g.admit = [screen](const BasePose& b, const std::vector<Eigen::VectorXd>& t) { return (*screen)(b, t); };
  return screen;
}

/// The figures at the capture reached (check_reached admitted it) and the screen's counts, into r.
inline void add_post_capture(const PostCaptureScreen& screen, GlobalRun& r) {
  r.post_capture = screen.figures(r.result.run.base, r.result.run.theta);
  r.post_capture_candidates = screen.evaluated();
  r.post_capture_admitted = screen.admitted();
}

/// The global search's options of the scenario (run_global): its seed, starts, objective, joint models,
/// the reaching tolerance, the paper's run as an extra start, the base-rate constraint.
inline GlobalCaptureOptions global_search_options(const Scenario& sc, const CaptureOptions& opt,
                                                  const CaptureResult* paper_run, GlobalObjective objective,
                                                  const std::shared_ptr<RobustForceObjective>& robust,
                                                  bool tight_reaching) {
  GlobalCaptureOptions g;
  g.search.seed = sc.seed;
  g.search.starts = sc.keys.global_starts;
  g.search.objective = objective;
  g.search.robust = robust;
  g.search.multibody.joint_stiffness = sc.joint_stiffness;  // joint models: the servoed multibody reference
  g.search.multibody.joint_damping = sc.joint_damping;
  g.search.multibody.armature = sc.problem.joints.armature;
  // robust-force scenarios: the reaching runs land within 0.01 % of the manifold optimum at the reached
  // base pose (the library's default, 1 %, is coarser than the difference between the robust and the
  // nominal optimum), the nominal global run beside the robust one too, so the two compare fairly
  // so do the runs with a base-rate limit: M_ie is flat at its constrained optimum while the rate is
  // not, and a run within 1 % of M_ie can sit where the rate is well above the limit
  if (tight_reaching || objective == GlobalObjective::RobustForce || sc.keys.max_base_rate_deg > 0) {
    g.gap_percent = 0.01;
    g.max_iterations = 16;
  }
  if (paper_run) g.extra_starts = {paper_run->theta};
  if (sc.keys.max_base_rate_deg > 0)  // the impact's base-rate jump as a constraint of every search
    g.search.inequalities = base_rate_inequality(sc.problem, prepare_capture(sc.problem, sc.task, opt),
                                                 sc.keys.max_base_rate_deg * M_PI / 180.0);
  return g;
}

/// run_global with the paper's-method run, or without it (null); `record_series`: keep the time
/// series (ScenarioRunOptions::record_series) beside the scenario's own setting.
inline GlobalRun run_global(const Scenario& sc, const CaptureResult* paper_run, GlobalObjective objective,
                            std::shared_ptr<RobustForceObjective> robust, bool tight_reaching,
                            bool record_series = false) {
  CaptureOptions opt = sc.capture;
  opt.gain = 0.0;
  opt.max_joint_rate = sc.keys.max_joint_rate_deg * M_PI / 180.0;
  opt.progress = nullptr;
  GlobalCaptureOptions g = global_search_options(sc, opt, paper_run, objective, robust, tight_reaching);
  const std::shared_ptr<PostCaptureScreen> screen = post_capture_screen(sc, opt, g);
  g.reconfigure.mode = reconfigure_mode_of(sc.keys.reconfigure, "--reconfigure");
  g.reconfigure.duration = sc.keys.reconfigure_duration;
  opt.record_series = opt.record_series || record_series || sc.geometry;
  GlobalRun r;
  try {
    r.result = plan_global_with_clearance(sc, opt, g);  // as plan_capture_global without a clearance
  } catch (const ReconfigurationRateError& e) {
    throw InputError(str("--reconfigure-duration: a reconfiguration in ", e.duration, " s: joint '", e.joint,
                         "' needs ", std::ceil(e.needed * 18000 / M_PI) / 100,
                         " deg/s, max-joint-rate-deg is ", e.limit * 180 / M_PI));
  } catch (const InfeasibleInequalitiesError& e) {
    if (!(sc.keys.max_base_rate_deg > 0)) throw InputError(str("global run: ", e.what()));
    throw InputError(
        str("--max-base-rate-deg: no capture configuration found keeps the impact's base-rate "
            "jump within ",
            std::setprecision(6), sc.keys.max_base_rate_deg, " deg/s",
            sc.geometry ? " and the clearance" : "", " (`ffsr-optimize pareto` shows the least)"));
  } catch (const NoAdmittedCandidateError&) {
    throw InputError(screen->shortfall());
  } catch (const JointRateLimitError& e) {
    throw InputError(str("--max-joint-rate-deg: ", e.what()));
  } catch (const InputError& e) {
    throw InputError(str("global run: ", e.what()));
  } catch (const NumericalError& e) {
    if (screen && screen->admitted() == 0) throw InputError(screen->shortfall());
    throw NumericalError(str(
        "global run: ", e.what(),
        screen ? str(" (", screen->admitted(), " of ", screen->evaluated(),
                     " candidate runs met the post-capture constraints ", screen->constraints().flags(), ")")
               : std::string()));
  }
  if (screen) add_post_capture(*screen, r);
  const CaptureSetup setup = prepare_capture(sc.problem, sc.task, opt);
  r.paper_objective = paper_run ? evaluate_capture(sc.problem, setup, paper_run->base, paper_run->theta,
                                                   objective, g.search.multibody, robust.get())
                                      .objective
                                : std::numeric_limits<double>::quiet_NaN();
  r.branches = capture_branches(sc.problem, sc.task, opt, setup, r.result.search, r.result.run.base, 6,
                                std::max(1u, std::thread::hardware_concurrency()));
  return r;
}

}  // namespace detail

inline GlobalRun run_global(const Scenario& sc, const CaptureResult& paper_run, GlobalObjective objective,
                            std::shared_ptr<RobustForceObjective> robust, bool tight_reaching) {
  return detail::run_global(sc, &paper_run, objective, std::move(robust), tight_reaching);
}

inline GlobalRun run_global(const Scenario& sc, GlobalObjective objective,
                            std::shared_ptr<RobustForceObjective> robust, bool tight_reaching) {
  return detail::run_global(sc, nullptr, objective, std::move(robust), tight_reaching);
}

namespace detail {

/// The robust-force sample set of the scenario (its [uncertainty] table).
inline UncertaintySpec robust_force_spec(const Scenario& sc) {
  try {
    return uncertainty_spec(sc.keys);
  } catch (const InputError&) {
    if (!sc.keys.document || !sc.keys.document->get("uncertainty"))
      throw InputError(str("--objective: robust-force needs an [uncertainty] table in ", sc.where));
    throw;
  }
}

}  // namespace detail

namespace detail {

/// The robust-force measure (CVaR_95 and p95 of the exact F_max over the sample set, the scenario's
/// joint model: the capture objective's) of each run that holds a configuration, into r.robust_rows.
inline void add_robust_rows(const Scenario& sc, ScenarioResult& r) {
  Data data(*sc.model);
  const CaptureSetup setup = prepare_capture(sc.problem, sc.task, sc.capture);
  const CaptureEvaluator objective(sc.problem, setup, GlobalObjective::RobustForce, nullptr, r.robust.get());
  const std::pair<const char*, const CaptureResult*> rows[] = {
      {"baseline", r.plain_ok() ? &r.plain : nullptr},
      {"optimized", r.optimized_ok() ? &r.optimized : nullptr},
      {"global", &r.global->result.run}};
  for (const auto& [name, run] : rows) {
    if (!run) continue;
    const auto v = objective.robust_value(data, run->base, run->theta);
    r.robust_rows.push_back({name, v.cvar95, v.p95});
  }
}

}  // namespace detail

namespace detail {

/// The runs of the main job, up to the impact.
inline ScenarioResult run_captures(const Scenario& sc, const ScenarioRunOptions& options) {
  ScenarioResult r;
  if (!options.keep_going || !sc.keys.global) {
    std::tie(r.plain, r.optimized) = plan_plain_and_optimized(sc, options);
  } else {  // a failed row is recorded; the global run decides
    for (const bool plain : {true, false}) try {
        (plain ? r.plain : r.optimized) = detail::plan_row(sc, options, plain);
      } catch (const NumericalError& e) {
        (plain ? r.plain_failure : r.optimized_failure) = e.what();
      }
  }
  if (sc.geometry) {
    if (r.plain_ok()) r.clearances.emplace_back("baseline", run_clearance(sc, r.plain));
    if (r.optimized_ok()) r.clearances.emplace_back("optimized", run_clearance(sc, r.optimized));
  }
  if (!sc.keys.global) return r;
  if (sc.objective == GlobalObjective::RobustForce) {
    r.robust_spec = detail::robust_force_spec(sc);
    r.robust = scenario_robust_objective(sc, r.robust_spec);
  }
  try {
    r.global =
        detail::run_global(sc, r.optimized_ok() ? &r.optimized : nullptr, sc.objective, r.robust, false,
                           options.record_series);
  } catch (const NumericalError& e) {
    if (r.plain_ok() && r.optimized_ok()) throw;
    throw NumericalError(detail::str(r.plain_ok() ? r.optimized_failure : r.plain_failure,
                                     "; the global run failed too: ", e.what()));
  }
  if (sc.geometry) r.clearances.emplace_back("global", run_clearance(sc, r.global->result.run));
  if (r.robust) detail::add_robust_rows(sc, r);
  return r;
}

}  // namespace detail

inline ScenarioResult run_scenario(const Scenario& sc, const ScenarioRunOptions& options) {
  return detail::run_captures(sc, options);
}

}  // namespace ffsr
