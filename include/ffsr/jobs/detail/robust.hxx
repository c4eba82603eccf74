// ffsr/jobs/detail/robust.hxx -- bodies of ffsr/jobs/robust.hpp.
#pragma once

#include "ffsr/detail/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>

namespace ffsr {

inline std::vector<RobustConfiguration> planned_robust_configurations(const Scenario& sc,
                                                                      const ScenarioRunOptions& run) {
  std::vector<RobustConfiguration> configs;
  auto add = [&](const char* name, const CaptureResult& r) { configs.push_back({name, r.theta, r.base}); };
  const auto [plain, optimized] = plan_plain_and_optimized(sc, run);
  add("plain", plain);
  add("optimized", optimized);
  if (!sc.keys.global) return configs;
  if (sc.objective == GlobalObjective::RobustForce) {
    add("global", run_global(sc, optimized, GlobalObjective::Mass, nullptr, true).result.run);
    const auto set = scenario_robust_objective(sc, uncertainty_spec(sc.keys));
    add("robust", run_global(sc, optimized, sc.objective, set).result.run);
  } else {
    add("global", run_global(sc, optimized, sc.objective).result.run);
  }
  return configs;
}

inline ForceModel robust_force_model(const std::string& name) {
  if (name == "closed") return ForceModel::Closed;
  if (name == "exact") return ForceModel::Exact;
  if (name == "multibody") return ForceModel::Multibody;
  throw InputError(
      detail::str("--force-model: unknown model '", name, "'; expected closed, exact or multibody"));
}

inline const char* robust_force_model_name(ForceModel model) {
  return model == ForceModel::Closed ? "closed" : model == ForceModel::Exact ? "exact" : "multibody";
}

inline void check_robust_job(const Scenario& sc, const RobustJobOptions& options) {
  using detail::str;
  if (options.shard_n < 1 || options.shard_k >= options.shard_n)
    throw InputError(str("run_robust: shard ", options.shard_k, " of ", options.shard_n, " does not exist"));
  if (options.threads < 1) throw InputError(str("run_robust: threads must be >= 1, got ", options.threads));
  if (options.force_model == ForceModel::Multibody && sc.problem.joints.model != JointModel::Free)
    throw InputError(
        str("--contact-joints: the multibody force model simulates the joints free; use '",
            joint_model_name(sc.problem.joints.model), "' with --force-model exact or closed"));
}

inline RobustRun run_robust(const Scenario& sc, const UncertaintySpec& spec,
                            std::vector<RobustConfiguration> configs, const RobustJobOptions& options) {
  check_robust_job(sc, options);
  RobustRun run;
  run.spec = spec;
  run.options = options;
  run.first = spec.samples * options.shard_k / options.shard_n;
  run.end = spec.samples * (options.shard_k + 1) / options.shard_n;
  const Model& model = *sc.model;
  const CaptureProblem& pb = sc.problem;
  run.nominal.target = propagate_target(pb.target, sc.capture.duration);
  run.nominal.contact = pb.contact;
  run.nominal.approach_speed = pb.approach_speed;
  const std::uint64_t count = run.end - run.first;
  run.samples.resize(count);
  const std::uint64_t total_work = count * (1 + configs.size());
  std::atomic<std::uint64_t> work_done{0};
  detail::ParallelOptions each_options;  // one index per chunk: the first error by index is rethrown
  if (options.progress)
    each_options.progress = [&](std::uint64_t) { options.progress(work_done.load(), total_work); };
  const unsigned threads = static_cast<unsigned>(std::max(1, options.threads));
  auto each = [&](const std::function<void(std::uint64_t)>& f) {
    detail::parallel_for(
        count, threads,
        [&](std::uint64_t i) {
          f(i);
          work_done.fetch_add(1);
        },
        each_options);
  };
  each([&](std::uint64_t i) { run.samples[i] = draw_sample(spec, run.nominal, run.first + i); });
  Data data(model);
  UncertaintySpec fixed;  // the nominal sample: no spread
  fixed.seed = spec.seed;
  const UncertainSample nominal_sample = draw_sample(fixed, run.nominal, 0);
  for (RobustConfiguration& c : configs) {
    RobustRun::Evaluated e;
    e.configuration = std::move(c);
    e.forces.resize(count);
    const RobustConfiguration& k = e.configuration;
    if (options.force_model == ForceModel::Multibody) {
      auto force = [&](const UncertainSample& s) {
        return sample_force_multibody(model, k.base, k.theta, pb.frame, s, pb.law);
      };
      e.nominal = force(nominal_sample);
      each([&](std::uint64_t i) { e.forces[i] = force(run.samples[i]); });
    } else {
      // Lambda^-1 of the scenario's joint model (the capture objective's); each sample its own target and law
      const Matrix6 G = CaptureEvaluator(model, pb.frame, run.nominal.target, nullptr, pb.joints)
                            .inverse_inertia(data, k.base, k.theta);
      e.nominal = sample_force(G, nominal_sample, pb.law, options.force_model);
      each([&](std::uint64_t i) { e.forces[i] = sample_force(G, run.samples[i], pb.law, options.force_model); });
    }
    run.configurations.push_back(std::move(e));
  }
  if (options.progress) options.progress(total_work, total_work);
  for (const auto& smp : run.samples) run.redraws += static_cast<std::uint64_t>(smp.redraws);
  return run;
}

namespace detail {

/// The summary JSON's names of Spread::Law, in the enum's order.
constexpr const char* kRobustLawNames[] = {"fixed", "normal", "uniform", "log-normal", "cone"};

/// The parameters of a sample by name (the CSV's columns), SI units, spin in deg/s.
inline nlohmann::json sample_parameters_json(const UncertainSample& s) {
  auto v3 = [](const Vector3& v) { return std::vector<double>{v(0), v(1), v(2)}; };
  const Matrix3& I = s.target.inertia;
  return {{"target_mass", s.target.mass},
          {"target_inertia", {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)}},
          {"contact_offset", v3(s.target.contact_offset)},
          {"normal", v3(s.target.normal)},
          {"spin_deg", v3(s.target.angular_velocity * (180.0 / M_PI))},
          {"target_velocity", v3(s.target.velocity)},
          {"approach_speed", s.approach_speed},
          {"stiffness", s.contact.K},
          {"exponent", s.contact.alpha},
          {"restitution", s.contact.c_r},
          {"robot_contact_offset", v3(s.robot_offset)}};
}

/// The three most extreme uncertain quantities of a sample: [{quantity, score}].
inline nlohmann::json sample_extremes_json(const UncertainSample& s, const UncertaintySpec& spec) {
  std::vector<std::size_t> idx;
  for (std::size_t q = 0; q < kNumQuantities; ++q)
    if (spec.spread[q].law != Spread::Law::Fixed) idx.push_back(q);
  std::stable_sort(idx.begin(), idx.end(),
                   [&](std::size_t a, std::size_t b) { return std::abs(s.score[a]) > std::abs(s.score[b]); });
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < std::min<std::size_t>(3, idx.size()); ++k)
    out.push_back({{"quantity", std::string(kQuantityNames[idx[k]])}, {"score", s.score[idx[k]]}});
  return out;
}

/// The [uncertainty] table as drawn (an absent bound is left out: the JSON has no null).
inline nlohmann::json uncertainty_table_json(const UncertaintySpec& spec) {
  nlohmann::json u = nlohmann::json::object();
  for (std::size_t q = 0; q < kNumQuantities; ++q) {
    const Spread& sp = spec.spread[q];
    if (sp.law == Spread::Law::Fixed) continue;
    nlohmann::json e = {{"law", kRobustLawNames[static_cast<int>(sp.law)]},
                        {"scale", sp.scale},
                        {"relative", sp.relative},
                        {"range", sp.has_range},
                        {"axes", sp.axes}};
    if (std::isfinite(sp.min)) e["min"] = sp.min;
    if (std::isfinite(sp.max)) e["max"] = sp.max;
    u[std::string(kQuantityNames[q])] = e;
  }
  return u;
}

/// The law of the stiffness from a summary's "uncertainty" entry (uncertainty_table_json).
inline Spread stiffness_spread_of(const nlohmann::json& u) {
  Spread sp;
  const std::string law = u.at("law").get<std::string>();
  const auto* it = std::find(std::begin(kRobustLawNames), std::end(kRobustLawNames), law);
  if (it == std::end(kRobustLawNames)) throw InputError(str("the summary's stiffness law '", law, "' is unknown"));
  sp.law = static_cast<Spread::Law>(it - std::begin(kRobustLawNames));
  sp.scale = u.at("scale").get<double>();
  sp.relative = u.at("relative").get<bool>();
  sp.has_range = u.at("range").get<bool>();
  if (u.contains("min")) sp.min = u.at("min").get<double>();
  if (u.contains("max")) sp.max = u.at("max").get<double>();
  return sp;
}

inline nlohmann::json interval_json(const ForceSummary::Interval& ci, bool delta) {
  // a bound that does not exist (too few samples) is left out: the JSON has no null
  nlohmann::json out;
  if (delta)
    out = {{"method", "delta"}, {"log_standard_error", ci.log_standard_error}, {"coverage", ci.coverage}};
  else
    out = {{"method", "order-statistics"},
           {"lower_rank", ci.lower},
           {"upper_rank", ci.upper},
           {"coverage", ci.coverage}};
  if (ci.has_lo) out["lo"] = ci.lo;
  if (ci.has_hi) out["hi"] = ci.hi;
  return out;
}

inline nlohmann::json force_summary_json(const ForceSummary& s) {
  const bool conditional = s.estimator == ForceSummary::Estimator::StiffnessConditional;
  return {{"n", s.n},
          {"mean", s.mean},
          {"std", s.std},
          {"p50", s.p50},
          {"p95", s.p95},
          {"p99", s.p99},
          {"max", s.max},
          {"estimator", conditional ? "stiffness-conditional" : "order-statistics"},
          {"p95_ci95", interval_json(s.p95_ci, conditional)},
          {"order_statistics",
           {{"p50", s.order.p50},
            {"p95", s.order.p95},
            {"p99", s.order.p99},
            {"p95_ci95", interval_json(s.order.p95_ci, false)}}}};
}

inline nlohmann::json sample_force_json(const SampleForce& f) {
  return {{"M_ie", f.M_ie}, {"approach_velocity", f.approach_velocity}, {"f_max", f.f_max}};
}

/// The configuration's summary of a run: its pose, nominal force, every sample's F_max, the tail.
inline RobustConfigurationSummary configuration_summary(const RobustRun& run, const RobustRun::Evaluated& e) {
  RobustConfigurationSummary c;
  const RobustConfiguration& k = e.configuration;
  c.name = k.name;
  for (Eigen::Index i = 0; i < k.theta.size(); ++i) c.joints_deg.push_back(k.theta(i) * (180.0 / M_PI));
  c.base_position = {k.base.position(0), k.base.position(1), k.base.position(2)};
  const Eigen::Vector4d q = k.base.orientation.coeffs();
  c.base_quaternion_wxyz = {q(3), q(0), q(1), q(2)};
  c.nominal = e.nominal;
  const std::uint64_t count = run.end - run.first;
  c.f_max.resize(count);
  for (std::uint64_t i = 0; i < count; ++i) c.f_max[i] = e.forces[i].f_max;
  std::vector<std::uint64_t> order(count);
  for (std::uint64_t i = 0; i < count; ++i) order[i] = i;
  const std::size_t n = std::min<std::size_t>(kRobustTail, count);
  const std::vector<double>& f = c.f_max;
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n), order.end(),
                    [&](std::uint64_t a, std::uint64_t b) { return f[a] != f[b] ? f[a] > f[b] : a < b; });
  for (std::size_t t = 0; t < n; ++t) {
    const auto i = order[t];
    c.tail.push_back({run.first + i, e.forces[i], sample_extremes_json(run.samples[i], run.spec),
                      sample_parameters_json(run.samples[i])});
  }
  return c;
}

}  // namespace detail

inline RobustSummary robust_summary(const Scenario& sc, const RobustRun& run, const std::string& source,
                                    const std::string& version) {
  RobustSummary s;
  s.version = version;
  s.source = source;
  s.urdf = sc.keys.urdf;
  s.model = sc.keys.model;
  s.duration = sc.keys.duration;
  s.force_model = robust_force_model_name(run.options.force_model);
  s.law = sc.problem.law;
  s.seed = run.spec.seed;
  s.samples = run.spec.samples;
  s.shard_k = run.options.shard_k;
  s.shard_n = run.options.shard_n;
  s.first = run.first;
  s.end = run.end;
  s.uncertainty = detail::uncertainty_table_json(run.spec);
  // the percentiles: conditional on the stiffness where F_max scales exactly with it (sampling.hpp)
  s.stiffness_conditional = stiffness_conditional_applies(run.options.force_model, run.spec[Quantity::Stiffness]);
  if (s.stiffness_conditional) {
    s.stiffness_nominal = run.nominal.contact.K;
    for (const auto& smp : run.samples) {
      s.stiffness.push_back(smp.contact.K);
      s.exponent.push_back(smp.contact.alpha);
    }
  }
  s.redraws = run.redraws;
  for (const auto& e : run.configurations) s.configurations.push_back(detail::configuration_summary(run, e));
  finish_robust_summary(s);
  return s;
}

inline void finish_robust_summary(RobustSummary& s) {
  Spread law;
  if (s.stiffness_conditional) {
    if (!s.uncertainty.contains("stiffness"))
      throw InputError("the summary's stiffness-conditional estimator lacks the law of the stiffness");
    law = detail::stiffness_spread_of(s.uncertainty.at("stiffness"));
  }
  const RobustConfigurationSummary* global = nullptr;
  const RobustConfigurationSummary* robust = nullptr;
  for (RobustConfigurationSummary& c : s.configurations) {
    c.summary = s.stiffness_conditional
                    ? summarize_stiffness_conditional(c.f_max, s.stiffness, s.exponent, law, s.stiffness_nominal)
                    : summarize(c.f_max);
    std::stable_sort(c.tail.begin(), c.tail.end(), [](const RobustTailSample& a, const RobustTailSample& b) {
      return a.force.f_max != b.force.f_max ? a.force.f_max > b.force.f_max : a.index < b.index;
    });
    if (c.tail.size() > kRobustTail) c.tail.resize(kRobustTail);
    if (c.name == "global") global = &c;
    if (c.name == "robust") robust = &c;
  }
  // the robust configuration against the nominal global one, on the same samples: the ratio of the
  // 95th percentiles, with a paired interval when the estimator has one
  s.robust_vs_global.reset();
  if (!global || !robust) return;
  if (s.stiffness_conditional) {
    s.robust_vs_global = compare_p95_stiffness_conditional(global->f_max, robust->f_max, s.stiffness, s.exponent,
                                                           law, s.stiffness_nominal);
  } else {
    PercentileRatio r;
    r.ratio = robust->summary.p95 / global->summary.p95;
    s.robust_vs_global = r;
  }
}

inline nlohmann::json RobustSummary::to_json() const {
  nlohmann::json j;
  j["kind"] = "ffsr-robust";
  j["version"] = version;
  j["scenario"] = {{"source", source}, {"urdf", urdf}, {"model", model}, {"duration", duration}};
  j["force_model"] = force_model;
  j["law"] = law;
  j["seed"] = seed;
  j["samples"] = samples;
  j["shard"] = {{"k", shard_k}, {"n", shard_n}, {"first", first}, {"end", end}};
  if (merged_from) j["shard"]["merged_from"] = *merged_from;
  j["uncertainty"] = uncertainty;
  j["estimator"] = stiffness_conditional ? "stiffness-conditional" : "order-statistics";
  if (stiffness_conditional) {
    j["stiffness_nominal"] = stiffness_nominal;
    j["stiffness"] = stiffness;
    j["exponent"] = exponent;
  }
  j["redraws"] = redraws;
  j["configurations"] = nlohmann::json::array();
  for (const RobustConfigurationSummary& c : configurations) {
    nlohmann::json tail = nlohmann::json::array();
    for (const RobustTailSample& t : c.tail)
      tail.push_back({{"index", t.index},
                      {"f_max", t.force.f_max},
                      {"M_ie", t.force.M_ie},
                      {"approach_velocity", t.force.approach_velocity},
                      {"extreme", t.extreme},
                      {"parameters", t.parameters}});
    j["configurations"].push_back({{"name", c.name},
                                   {"joints_deg", c.joints_deg},
                                   {"base_position", c.base_position},
                                   {"base_quaternion_wxyz", c.base_quaternion_wxyz},
                                   {"nominal", detail::sample_force_json(c.nominal)},
                                   {"f_max", c.f_max},
                                   {"tail", tail},
                                   {"summary", detail::force_summary_json(c.summary)}});
  }
  if (robust_vs_global) {
    nlohmann::json r = {{"p95_ratio", robust_vs_global->ratio}};
    if (robust_vs_global->has_interval)
      r["p95_ratio_ci95"] = {
          {"lo", robust_vs_global->lo}, {"hi", robust_vs_global->hi}, {"method", "paired delta method"}};
    j["robust_vs_global"] = r;
  }
  return j;
}

inline RobustSummary RobustSummary::from_json(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object() || j.value("kind", "") != "ffsr-robust")
    throw InputError(detail::str(where, ": not a summary of ffsr-optimize robust"));
  RobustSummary s;
  try {
    s.version = j.at("version").get<std::string>();
    const auto& sc = j.at("scenario");
    s.source = sc.at("source").get<std::string>();
    s.urdf = sc.at("urdf").get<std::string>();
    s.model = sc.at("model").get<std::string>();
    s.duration = sc.at("duration").get<double>();
    s.force_model = j.at("force_model").get<std::string>();
    s.law = j.at("law").get<std::string>();
    s.seed = j.at("seed").get<std::uint64_t>();
    s.samples = j.at("samples").get<std::uint64_t>();
    const auto& sh = j.at("shard");
    s.shard_k = sh.at("k").get<std::uint64_t>();
    s.shard_n = sh.at("n").get<std::uint64_t>();
    s.first = sh.at("first").get<std::uint64_t>();
    s.end = sh.at("end").get<std::uint64_t>();
    if (sh.contains("merged_from")) s.merged_from = sh.at("merged_from").get<std::uint64_t>();
    s.uncertainty = j.at("uncertainty");
    s.stiffness_conditional = j.value("estimator", "order-statistics") == "stiffness-conditional";
    if (s.stiffness_conditional) {
      s.stiffness_nominal = j.at("stiffness_nominal").get<double>();
      s.stiffness = j.at("stiffness").get<std::vector<double>>();
      s.exponent = j.at("exponent").get<std::vector<double>>();
    }
    s.redraws = j.value("redraws", std::uint64_t{0});
    for (const auto& c : j.at("configurations")) {
      RobustConfigurationSummary x;
      x.name = c.at("name").get<std::string>();
      x.joints_deg = c.at("joints_deg").get<std::vector<double>>();
      x.base_position = c.at("base_position").get<std::vector<double>>();
      x.base_quaternion_wxyz = c.at("base_quaternion_wxyz").get<std::vector<double>>();
      const auto& n = c.at("nominal");
      x.nominal = {n.at("M_ie").get<double>(), n.at("approach_velocity").get<double>(), n.at("f_max").get<double>()};
      x.f_max = c.at("f_max").get<std::vector<double>>();
      for (const auto& t : c.at("tail"))
        x.tail.push_back({t.at("index").get<std::uint64_t>(),
                          {t.at("M_ie").get<double>(), t.at("approach_velocity").get<double>(),
                           t.at("f_max").get<double>()},
                          t.at("extreme"),
                          t.at("parameters")});
      s.configurations.push_back(std::move(x));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(detail::str(where, ": not a summary of ffsr-optimize robust (", e.what(), ")"));
  }
  return s;
}

namespace detail {

/// Whether two summaries are of one run: the same seed, samples, laws, force model and scenario.
inline std::string robust_shard_mismatch(const RobustSummary& a, const RobustSummary& b) {
  if (a.seed != b.seed) return "seed";
  if (a.samples != b.samples) return "samples";
  if (a.uncertainty != b.uncertainty) return "uncertainty";
  if (a.force_model != b.force_model) return "force_model";
  if (a.law != b.law) return "law";
  if (a.source != b.source || a.urdf != b.urdf || a.model != b.model || a.duration != b.duration)
    return "scenario";
  if (a.stiffness_conditional != b.stiffness_conditional) return "estimator";
  if (a.stiffness_nominal != b.stiffness_nominal) return "stiffness_nominal";
  return "";
}

}  // namespace detail

inline RobustSummary merge_shards(std::vector<RobustSummary> parts) {
  using detail::str;
  if (parts.empty()) throw InputError("merge_shards: no summary to merge");
  std::sort(parts.begin(), parts.end(),
            [](const RobustSummary& a, const RobustSummary& b) { return a.first < b.first; });
  const RobustSummary& first = parts.front();
  for (const RobustSummary& p : parts) {
    const std::string key = detail::robust_shard_mismatch(first, p);
    if (!key.empty())
      throw InputError(str("--merge: the summaries differ in '", key, "': they are not shards of one run"));
  }
  RobustSummary m = first;
  std::uint64_t next = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const RobustSummary& p = parts[i];
    if (p.first != next)
      throw InputError(
          str("--merge: samples ", next, " to ", p.first, " are ", p.first > next ? "missing" : "in two shards"));
    next = p.end;
    if (p.configurations.size() != first.configurations.size())
      throw InputError("--merge: the summaries have different configurations");
    if (i == 0) continue;
    m.redraws += p.redraws;  // the samples each shard redrew, counted once
    m.stiffness.insert(m.stiffness.end(), p.stiffness.begin(), p.stiffness.end());  // by index
    m.exponent.insert(m.exponent.end(), p.exponent.begin(), p.exponent.end());
    for (std::size_t c = 0; c < p.configurations.size(); ++c) {
      const RobustConfigurationSummary& pc = p.configurations[c];
      RobustConfigurationSummary& mc = m.configurations[c];
      if (pc.name != mc.name || pc.joints_deg != mc.joints_deg)
        throw InputError("--merge: the summaries have different configurations");
      mc.f_max.insert(mc.f_max.end(), pc.f_max.begin(), pc.f_max.end());
      mc.tail.insert(mc.tail.end(), pc.tail.begin(), pc.tail.end());
    }
  }
  if (next != first.samples)
    throw InputError(str("--merge: the shards cover samples 0 to ", next, " of ", first.samples));
  for (const auto* list : {&m.stiffness, &m.exponent})
    if (m.stiffness_conditional && list->size() != next)
      throw InputError(str("--merge: the summaries' '", list == &m.stiffness ? "stiffness" : "exponent",
                           "' lists do not hold one value per sample"));
  m.shard_k = 0;
  m.shard_n = 1;
  m.first = 0;
  m.end = next;
  m.merged_from = parts.size();
  finish_robust_summary(m);
  return m;
}

inline RobustConfiguration given_robust_configuration(const Model& model, const std::vector<double>& joints_deg,
                                                      const std::vector<double>& base_position,
                                                      const std::vector<double>& base_rpy_deg) {
  using detail::str;
  if (static_cast<int>(joints_deg.size()) != model.n())
    throw InputError(str("--capture-joints-deg: got ", joints_deg.size(), " angles, the robot has ", model.n(),
                         " joints"));
  RobustConfiguration c;
  c.name = "given";
  c.theta = Eigen::Map<const Eigen::VectorXd>(joints_deg.data(), model.n()) * (M_PI / 180.0);
  for (double x : joints_deg)
    if (!std::isfinite(x)) throw InputError("--capture-joints-deg: values must be finite");
  if (base_position.size() != 3) throw InputError("--capture-base-position: expected 3 numbers");
  if (base_rpy_deg.size() != 3) throw InputError("--capture-base-rpy-deg: expected 3 numbers");
  c.base.position = Vector3(base_position[0], base_position[1], base_position[2]);
  const Vector3 rpy(base_rpy_deg[0], base_rpy_deg[1], base_rpy_deg[2]);
  if (!c.base.position.allFinite() || !rpy.allFinite())
    throw InputError("--capture-base-position/--capture-base-rpy-deg: values must be finite");
  c.base.orientation = Quaternion(rotation_from_rpy(rpy * (M_PI / 180.0)));
  return c;
}

}  // namespace ffsr
