// ffsr-optimize robust --config SCENARIO.toml [flags]: Monte Carlo of the maximum contact force over
// what is not known about the target (the scenario's [uncertainty] table), for the capture
// configurations of the main job (plain, optimized and, unless global = false, the global run --
// with objective = "robust-force" both the nominal global run and the robust one -- planned as the
// main job plans them) or one given with --capture-joints-deg. Samples are common to all configurations and depend on
// (seed, index) only, so --shard K/N runs can be merged exactly (--merge): a shard's JSON keeps every
// sample's F_max, the merge concatenates them by index and recomputes the summary.
//
// The scenario file (its keys and its [uncertainty] table) is read by the library's one reader
// (ffsr/io/scenario.hpp); a flag overrides a key of the file.
#include "common.hpp"
#include "plot.hpp"
#include "scenario.hpp"
#include "subcommands.hpp"

#include "ffsr/uncertainty/multibody.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

namespace ffsr::cli {
namespace {

using detail::str;

/// Tail samples kept per configuration (the largest F_max), in the summary and across a merge.
constexpr std::size_t kTail = 5;

struct RobustOptions : OutputKeys {
  ScenarioFlags flags;  ///< the scenario keys as flags (a flag overrides the file)
  std::string config;
  std::string force_model = "exact";
  std::string samples, seed, shard = "0/1";
  int threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<double> capture_joints_deg, capture_base_position{0, 0, 0}, capture_base_rpy_deg{0, 0, 0};
  std::vector<std::string> merge;
};

// --- evaluation ---------------------------------------------------------------------------------

struct Configuration {
  std::string name;
  Eigen::VectorXd theta;
  BasePose base;
  SampleForce nominal;
  std::vector<SampleForce> forces;  // by sample, shard-local
};

std::string quantity_label(std::size_t q) { return std::string(kQuantityNames[q]); }

/// The distribution of F_max per configuration (kN): the empirical CDF with the 95th percentile
/// marked, and the histogram (shared bins, drawn as steps) -- from the summary JSON's f_max arrays,
/// so a merged summary is drawn the same way as a run.
plot::Figure robust_figure(const nlohmann::json& summary) {
  plot::Figure fig;
  fig.name = "robust";
  fig.title = str("F_max over ", summary["samples"].get<std::uint64_t>(), " samples (",
                  summary["force_model"].get<std::string>(), " model, seed ",
                  summary["seed"].get<std::uint64_t>(), ")");
  fig.cols = 2;
  fig.width = 1200;
  fig.height = 700;
  plot::Panel cdf, hist;
  cdf.title = summary.value("estimator", "order-statistics") == "stiffness-conditional"
                  ? "empirical CDF; dot: p95 of the law (conditional on K)"
                  : "empirical CDF, 95th percentile marked";
  cdf.xlabel = hist.xlabel = "F_max (kN)";
  cdf.ylabel = "fraction";
  hist.title = "histogram (40 shared bins)";
  hist.ylabel = "fraction per bin";
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& c : summary["configurations"])
    for (const auto& f : c["f_max"]) {
      lo = std::min(lo, f.get<double>() / 1e3);
      hi = std::max(hi, f.get<double>() / 1e3);
    }
  if (!(hi > lo)) hi = lo + 1.0;
  constexpr int kBins = 40;
  const double w = (hi - lo) / kBins;
  int color = 0;
  for (const auto& c : summary["configurations"]) {
    std::vector<double> f = c["f_max"].get<std::vector<double>>();
    for (double& x : f) x /= 1e3;
    std::sort(f.begin(), f.end());
    const double n = static_cast<double>(f.size());
    plot::Curve line;
    line.label = c["name"].get<std::string>();
    line.color = color;
    line.line_style = 1 + color % 4;
    for (std::size_t i = 0; i < f.size(); ++i) {  // the CDF as steps
      line.x.push_back(f[i]);
      line.y.push_back(static_cast<double>(i) / n);
      line.x.push_back(f[i]);
      line.y.push_back(static_cast<double>(i + 1) / n);
    }
    plot::Curve p95;
    p95.color = color;
    p95.line_style = 0;
    p95.symbol = "●";
    p95.x = {c["summary"]["p95"].get<double>() / 1e3};
    p95.y = {0.95};
    cdf.curves.push_back(std::move(line));
    cdf.curves.push_back(std::move(p95));
    std::vector<double> count(kBins, 0.0);
    for (double x : f)
      count[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>((x - lo) / w)))] += 1.0 / n;
    plot::Curve steps;
    steps.label = c["name"].get<std::string>();
    steps.color = color;
    steps.line_style = 1 + color % 4;
    for (int b = 0; b < kBins; ++b) {
      steps.x.push_back(lo + b * w);
      steps.y.push_back(count[static_cast<std::size_t>(b)]);
      steps.x.push_back(lo + (b + 1) * w);
      steps.y.push_back(count[static_cast<std::size_t>(b)]);
    }
    hist.curves.push_back(std::move(steps));
    ++color;
  }
  fig.panels.emplace_back(std::move(cdf));
  fig.panels.emplace_back(std::move(hist));
  return fig;
}

/// The parameters of a sample as JSON (the CSV columns, by name), SI units, spin in deg/s.
nlohmann::json sample_json(const UncertainSample& s) {
  const Matrix3& I = s.target.inertia;
  return {{"target_mass", s.target.mass},
          {"target_inertia", {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)}},
          {"contact_offset", to_json(Eigen::VectorXd(s.target.contact_offset))},
          {"normal", to_json(Eigen::VectorXd(s.target.normal))},
          {"spin_deg", to_json(Eigen::VectorXd(s.target.angular_velocity * (180.0 / M_PI)))},
          {"target_velocity", to_json(Eigen::VectorXd(s.target.velocity))},
          {"approach_speed", s.approach_speed},
          {"stiffness", s.contact.K},
          {"exponent", s.contact.alpha},
          {"restitution", s.contact.c_r},
          {"robot_contact_offset", to_json(Eigen::VectorXd(s.robot_offset))}};
}

/// The three most extreme uncertain quantities of a sample, as "name score".
nlohmann::json extremes(const UncertainSample& s, const UncertaintySpec& spec) {
  std::vector<std::size_t> idx;
  for (std::size_t q = 0; q < kNumQuantities; ++q)
    if (spec.spread[q].law != Spread::Law::Fixed) idx.push_back(q);
  std::stable_sort(idx.begin(), idx.end(),
                   [&](std::size_t a, std::size_t b) { return std::abs(s.score[a]) > std::abs(s.score[b]); });
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < std::min<std::size_t>(3, idx.size()); ++k)
    out.push_back({{"quantity", quantity_label(idx[k])}, {"score", s.score[idx[k]]}});
  return out;
}

nlohmann::json interval_json(const ForceSummary::Interval& ci, bool delta) {
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

nlohmann::json summary_json(const ForceSummary& s) {
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

/// The summary JSON's names of Spread::Law, in the enum's order (written by run_robust, read back by
/// stiffness_spread).
constexpr const char* kLawNames[] = {"fixed", "normal", "uniform", "log-normal", "cone"};

/// The law of the stiffness from the summary's "uncertainty" entry (written by run_robust).
Spread stiffness_spread(const nlohmann::json& u) {
  Spread sp;
  const std::string law = u.at("law").get<std::string>();
  const auto* it = std::find(std::begin(kLawNames), std::end(kLawNames), law);
  if (it == std::end(kLawNames)) throw InputError(str("the summary's stiffness law '", law, "' is unknown"));
  sp.law = static_cast<Spread::Law>(it - std::begin(kLawNames));
  sp.scale = u.at("scale").get<double>();
  sp.relative = u.at("relative").get<bool>();
  sp.has_range = u.at("range").get<bool>();
  if (u.contains("min")) sp.min = u.at("min").get<double>();
  if (u.contains("max")) sp.max = u.at("max").get<double>();
  return sp;
}

std::string extremes_text(const nlohmann::json& ex) {
  std::ostringstream os;
  os << std::showpos << std::fixed << std::setprecision(2);
  for (std::size_t k = 0; k < ex.size(); ++k)
    os << (k ? ", " : "") << ex[k]["quantity"].get<std::string>() << " " << ex[k]["score"].get<double>();
  return os.str();
}

/// The terminal table of a summary JSON (a run or a merge: the same struct).
void print_summary(const nlohmann::json& j, std::ostream& out) {
  out << std::left << std::setw(14) << "configuration" << std::right << std::setw(12) << "nominal M_ie"
      << std::setw(11) << "nominal F" << std::setw(10) << "mean" << std::setw(10) << "std" << std::setw(10)
      << "p50" << std::setw(10) << "p95" << std::setw(10) << "p99" << std::setw(10) << "max"
      << "\n";
  out << std::left << std::setw(14) << "" << std::right << std::setw(12) << "(kg)" << std::setw(11) << "(kN)"
      << std::setw(60) << "F_max over the samples (kN)"
      << "\n";
  for (const auto& c : j["configurations"]) {
    const auto& s = c["summary"];
    out << std::left << std::setw(14) << c["name"].get<std::string>() << std::right << std::fixed
        << std::setprecision(3) << std::setw(12) << c["nominal"]["M_ie"].get<double>() << std::setw(11)
        << c["nominal"]["f_max"].get<double>() / 1e3;
    for (const char* k : {"mean", "std", "p50", "p95", "p99", "max"})
      out << std::setw(10) << s[k].get<double>() / 1e3;
    out << "\n";
  }
  const bool conditional = j.value("estimator", "order-statistics") == "stiffness-conditional";
  if (conditional) {
    // the percentiles above are the stiffness-conditional ones; the order statistics beside them
    out << "p50, p95, p99: the law's percentiles conditional on the stiffness (the single-body F_max scales "
           "as"
        << " K^(1/(alpha+1)); README); mean, std, max: the samples'."
        << "\norder statistics of the same samples, p95 (kN):";
    const char* sep = " ";
    for (const auto& c : j["configurations"]) {
      out << sep << c["name"].get<std::string>() << " " << std::fixed << std::setprecision(3)
          << c["summary"]["order_statistics"]["p95"].get<double>() / 1e3;
      sep = ", ";
    }
    out << "\n";
  }
  // how well the samples pin the 95th percentile of the law down
  out << "95 % confidence interval of the 95th percentile ("
      << (conditional ? "conditional on the stiffness, delta method" : "order statistics, distribution-free")
      << "), kN:";
  const char* sep = "\n  ";
  for (const auto& c : j["configurations"]) {
    const auto& ci = c["summary"]["p95_ci95"];
    auto bound = [&ci](const char* key, const char* none) {
      std::ostringstream os;
      if (!ci.contains(key))
        os << none;
      else
        os << std::fixed << std::setprecision(3) << ci[key].get<double>() / 1e3;
      return os.str();
    };
    out << sep << c["name"].get<std::string>() << " [" << bound("lo", "-") << ", "
        << bound("hi", "none: too few samples") << "]";
    sep = ", ";
  }
  out << "\n";
  if (j.contains("robust_vs_global")) {
    const auto& r = j["robust_vs_global"];
    auto pct = [](double ratio) {
      std::ostringstream os;
      os << std::showpos << std::fixed << std::setprecision(2) << 100.0 * (ratio - 1.0) << " %";
      return os.str();
    };
    out << "robust against global on the same samples: p95 " << pct(r["p95_ratio"].get<double>());
    if (r.contains("p95_ratio_ci95"))
      out << ", 95 % interval [" << pct(r["p95_ratio_ci95"]["lo"].get<double>()) << ", "
          << pct(r["p95_ratio_ci95"]["hi"].get<double>()) << "] (paired)";
    out << "\n";
  }
  for (const auto& c : j["configurations"]) {
    out << "\nlargest F_max, " << c["name"].get<std::string>()
        << " (score: z for normal laws, ln(x/x0)/sigma, "
        << "[-1, 1] in a uniform range, angle/half-angle in the cone):\n";
    for (const auto& t : c["tail"])
      out << "  sample " << std::setw(7) << t["index"].get<std::uint64_t>() << "  F_max " << std::fixed
          << std::setprecision(3) << t["f_max"].get<double>() / 1e3 << " kN  M_ie " << t["M_ie"].get<double>()
          << " kg  delta_dot " << std::setprecision(4) << t["approach_velocity"].get<double>()
          << " m/s  extreme: " << extremes_text(t["extreme"]) << "\n";
  }
}

/// Summary JSON of the configurations from the per-sample F_max (by index) and the tail entries.
/// With the stiffness-conditional estimator (single-body force models, K uncertain) the run's
/// per-sample K and alpha and the law of K are in the JSON too, so a merge recomputes the same digits.
void finish_summary(nlohmann::json& j) {
  const bool conditional = j.value("estimator", "order-statistics") == "stiffness-conditional";
  std::vector<double> K, alpha;
  Spread law;
  double K0 = 0;
  if (conditional) {
    if (!j.contains("stiffness") || !j.contains("exponent") || !j.contains("stiffness_nominal") ||
        !j["uncertainty"].contains("stiffness"))
      throw InputError("the summary's stiffness-conditional estimator lacks its stiffness, exponent or law");
    K = j["stiffness"].get<std::vector<double>>();
    alpha = j["exponent"].get<std::vector<double>>();
    K0 = j["stiffness_nominal"].get<double>();
    law = stiffness_spread(j["uncertainty"]["stiffness"]);
  }
  for (auto& c : j["configurations"]) {
    const std::vector<double> f = c["f_max"].get<std::vector<double>>();
    c["summary"] =
        summary_json(conditional ? summarize_stiffness_conditional(f, K, alpha, law, K0) : summarize(f));
    auto tail = c["tail"];
    std::vector<nlohmann::json> t(tail.begin(), tail.end());
    std::stable_sort(t.begin(), t.end(), [](const nlohmann::json& a, const nlohmann::json& b) {
      const double fa = a["f_max"].get<double>(), fb = b["f_max"].get<double>();
      return fa != fb ? fa > fb : a["index"].get<std::uint64_t>() < b["index"].get<std::uint64_t>();
    });
    if (t.size() > kTail) t.resize(kTail);
    c["tail"] = t;
  }
  // the robust configuration against the nominal global one, on the same samples: the ratio of the
  // 95th percentiles, with a paired interval when the estimator has one
  const nlohmann::json* global = nullptr;
  const nlohmann::json* robust = nullptr;
  for (const auto& c : j["configurations"]) {
    if (c["name"] == "global") global = &c;
    if (c["name"] == "robust") robust = &c;
  }
  j.erase("robust_vs_global");
  if (global && robust) {
    nlohmann::json r;
    if (conditional) {
      const PercentileRatio q =
          compare_p95_stiffness_conditional((*global)["f_max"].get<std::vector<double>>(),
                                            (*robust)["f_max"].get<std::vector<double>>(), K, alpha, law, K0);
      r["p95_ratio"] = q.ratio;
      if (q.has_interval)
        r["p95_ratio_ci95"] = {{"lo", q.lo}, {"hi", q.hi}, {"method", "paired delta method"}};
    } else {
      r["p95_ratio"] = (*robust)["summary"]["p95"].get<double>() / (*global)["summary"]["p95"].get<double>();
    }
    j["robust_vs_global"] = r;
  }
}

int run_merge(const RobustOptions& o) {
  const plot::Format plot_format = plot::check_request(o.plot, o.plot_format);
  std::vector<nlohmann::json> parts;
  for (const auto& path : o.merge) {
    std::ifstream in(path);
    if (!in) throw InputError(str("--merge: cannot read '", path, "'"));
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      throw InputError(str("--merge: '", path, "' is not JSON: ", e.what()));
    }
    if (!j.is_object() || j.value("kind", "") != "ffsr-robust")
      throw InputError(str("--merge: '", path, "' is not a summary of ffsr-optimize robust"));
    parts.push_back(std::move(j));
  }
  std::sort(parts.begin(), parts.end(), [](const nlohmann::json& a, const nlohmann::json& b) {
    return a["shard"]["first"].get<std::uint64_t>() < b["shard"]["first"].get<std::uint64_t>();
  });
  const nlohmann::json& first = parts.front();
  for (const char* key :
       {"seed", "samples", "uncertainty", "force_model", "law", "scenario", "estimator", "stiffness_nominal"})
    for (const auto& p : parts)
      if (p.contains(key) != first.contains(key) || (p.contains(key) && p[key] != first[key]))
        throw InputError(str("--merge: the summaries differ in '", key, "': they are not shards of one run"));
  nlohmann::json m = first;
  std::uint64_t next = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto& p = parts[i];
    const std::uint64_t a = p["shard"]["first"], b = p["shard"]["end"];
    if (a != next)
      throw InputError(
          str("--merge: samples ", next, " to ", a, " are ", a > next ? "missing" : "in two shards"));
    next = b;
    if (p["configurations"].size() != first["configurations"].size())
      throw InputError("--merge: the summaries have different configurations");
    if (i == 0) continue;
    for (const char* key : {"stiffness", "exponent"})  // per sample, by index (stiffness-conditional)
      if (p.contains(key) && m.contains(key))
        for (const auto& x : p[key]) m[key].push_back(x);
    for (std::size_t c = 0; c < p["configurations"].size(); ++c) {
      const auto& pc = p["configurations"][c];
      auto& mc = m["configurations"][c];
      if (pc["name"] != mc["name"] || pc["joints_deg"] != mc["joints_deg"])
        throw InputError("--merge: the summaries have different configurations");
      for (const auto& f : pc["f_max"]) mc["f_max"].push_back(f);
      for (const auto& t : pc["tail"]) mc["tail"].push_back(t);
    }
  }
  if (next != first["samples"].get<std::uint64_t>())
    throw InputError(
        str("--merge: the shards cover samples 0 to ", next, " of ", first["samples"].get<std::uint64_t>()));
  for (const char* key : {"stiffness", "exponent"})
    if (m.contains(key) && (!m[key].is_array() || m[key].size() != next))
      throw InputError(str("--merge: the summaries' '", key, "' lists do not hold one value per sample"));
  m["shard"] = {{"k", 0}, {"n", 1}, {"first", 0}, {"end", next}, {"merged_from", parts.size()}};
  finish_summary(m);
  Outputs outputs;  // the table goes to standard error when the JSON goes to standard output
  outputs.add("--json", o.json);
  outputs.set("--json", m.dump(1) + "\n");
  std::vector<std::string> drawn;
  if (!o.plot.empty()) drawn = plot::render({robust_figure(m)}, o.plot, plot_format);
  outputs.write();
  std::ostream& out = outputs.table();
  out << "ffsr-optimize " << FFSR_VERSION << " robust: merged " << parts.size() << " shard summaries, "
      << next << " samples (seed " << m["seed"].get<std::uint64_t>() << ", "
      << m["force_model"].get<std::string>() << " F_max)\n\n";
  print_summary(m, out);
  for (const std::string& f : drawn) out << "wrote " << f << "\n";
  return 0;
}

/// The scenario of the run: the file's keys, the flags as overrides. A top-level `seed` key of the file
/// is not the global search's seed here (--seed is the Monte Carlo seed): the global runs use seed 1.
Scenario robust_scenario(ScenarioKeys keys, const RobustOptions& o) {
  o.flags.apply(keys);
  keys.seed = "1";
  keys.given.erase("seed");
  return command_scenario(std::move(keys));
}

ForceModel robust_force_model(const std::string& name) {
  if (name == "closed") return ForceModel::Closed;
  if (name == "exact") return ForceModel::Exact;
  if (name == "multibody") return ForceModel::Multibody;
  throw InputError(str("--force-model: unknown model '", name, "'; expected closed, exact or multibody"));
}

/// The capture configuration given with --capture-joints-deg.
Configuration given_configuration(const RobustOptions& o, const Model& model) {
  if (static_cast<int>(o.capture_joints_deg.size()) != model.n())
    throw InputError(str("--capture-joints-deg: got ", o.capture_joints_deg.size(), " angles, the robot has ",
                         model.n(), " joints"));
  Configuration c;
  c.name = "given";
  c.theta = Eigen::Map<const Eigen::VectorXd>(o.capture_joints_deg.data(), model.n()) * (M_PI / 180.0);
  for (double x : o.capture_joints_deg)
    if (!std::isfinite(x)) throw InputError("--capture-joints-deg: values must be finite");
  if (o.capture_base_position.size() != 3) throw InputError("--capture-base-position: expected 3 numbers");
  if (o.capture_base_rpy_deg.size() != 3) throw InputError("--capture-base-rpy-deg: expected 3 numbers");
  c.base.position =
      Vector3(o.capture_base_position[0], o.capture_base_position[1], o.capture_base_position[2]);
  const Vector3 rpy(o.capture_base_rpy_deg[0], o.capture_base_rpy_deg[1], o.capture_base_rpy_deg[2]);
  if (!c.base.position.allFinite() || !rpy.allFinite())
    throw InputError("--capture-base-position/--capture-base-rpy-deg: values must be finite");
  c.base.orientation = Quaternion(rotation_from_rpy(rpy * (M_PI / 180.0)));
  return c;
}

/// The planned configurations: plain, optimized and (unless global = false) global -- for
/// robust-force the nominal global run (mass) beside the robust one, on the same samples: the price
/// and the gain of robustness side by side.
std::vector<Configuration> planned_configurations(const Scenario& sc, bool quiet) {
  std::vector<Configuration> configs;
  auto add = [&](const char* name, const CaptureResult& r) {
    Configuration c;
    c.name = name;
    c.theta = r.theta;
    c.base = r.base;
    configs.push_back(std::move(c));
  };
  Progress p1{"plain"}, p2{"optimized"};
  ScenarioRunOptions run;
  if (!quiet) {
    run.plain_progress = std::ref(p1);
    run.optimized_progress = std::ref(p2);
  }
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

/// A run of `robust`: what is evaluated (the scenario, the configurations, this shard's samples) and
/// what came out (the F_max per configuration and sample).
struct RobustRun {
  Scenario sc;
  UncertaintySpec spec;
  ForceModel force_model = ForceModel::Exact;
  std::uint64_t shard_k = 0, shard_n = 1, first = 0, end = 0;
  std::vector<Configuration> configs;
  std::vector<UncertainSample> samples;  // this shard's, shard-local index
  UncertainNominal nominal;
  std::uint64_t redraws = 0;
};

/// The flags and the scenario file: the keys, the [uncertainty] table (samples and seed overridden
/// by the flags), the force model and the shard.
RobustRun parse_robust(const RobustOptions& o, ScenarioKeys keys) {
  std::optional<std::uint64_t> samples_flag, seed_flag;
  if (!o.samples.empty()) samples_flag = parse_count(o.samples, "--samples");
  if (!o.seed.empty()) seed_flag = parse_count(o.seed, "--seed");
  if (samples_flag && *samples_flag < 1) throw InputError("--samples: must be at least 1, got 0");
  RobustRun run;
  run.spec = uncertainty_spec(keys, samples_flag, seed_flag);
  run.force_model = robust_force_model(o.force_model);
  const Shard shard = parse_shard(o.shard);
  run.shard_k = shard.k;
  run.shard_n = shard.n;
  if (o.threads < 1 || o.threads > 1024)
    throw InputError(str("--threads: must be in [1, 1024], got ", o.threads));
  run.sc = robust_scenario(std::move(keys), o);
  if (run.force_model == ForceModel::Multibody && run.sc.problem.joints.model != JointModel::Free)
    throw InputError(
        str("--contact-joints: the multibody force model simulates the joints free (servoed by "
            "joint-stiffness and joint-damping); use it with --force-model exact or closed"));
  run.first = run.spec.samples * run.shard_k / run.shard_n;
  run.end = run.spec.samples * (run.shard_k + 1) / run.shard_n;
  return run;
}

/// Draws this shard's samples (common to all configurations) and evaluates F_max of every
/// configuration on each, on o.threads threads.
void evaluate_samples(RobustRun& run, const RobustOptions& o) {
  const Model& model = *run.sc.model;
  const CaptureProblem& pb = run.sc.problem;
  run.nominal.target = propagate_target(pb.target, run.sc.capture.duration);
  run.nominal.contact = pb.contact;
  run.nominal.approach_speed = pb.approach_speed;
  const std::uint64_t count = run.end - run.first;
  run.samples.resize(count);
  Progress progress("robust", o.quiet, "evaluations");
  const std::uint64_t total_work = count * (1 + run.configs.size());
  std::atomic<std::uint64_t> work_done{0};
  auto report = [&](std::uint64_t) { progress(work_done.load(), total_work); };
  auto each = [&](const std::function<void(std::uint64_t)>& f) {
    parallel_for(
        0, count, o.threads,
        [&](std::uint64_t i) {
          f(i);
          work_done.fetch_add(1);
        },
        report);
  };
  each([&](std::uint64_t i) { run.samples[i] = draw_sample(run.spec, run.nominal, run.first + i); });
  Data data(model);
  UncertaintySpec fixed;  // the nominal sample: no spread
  fixed.seed = run.spec.seed;
  const UncertainSample nominal_sample = draw_sample(fixed, run.nominal, 0);
  for (auto& c : run.configs) {
    c.forces.resize(count);
    if (run.force_model == ForceModel::Multibody) {
      auto force = [&](const UncertainSample& s) {
        return sample_force_multibody(model, c.base, c.theta, pb.frame, s, pb.law);
      };
      c.nominal = force(nominal_sample);
      each([&](std::uint64_t i) { c.forces[i] = force(run.samples[i]); });
    } else {
      // Lambda^-1 of the scenario's joint model (the capture objective's); each sample its own target and law
      const Matrix6 G = CaptureEvaluator(model, pb.frame, run.nominal.target, nullptr, pb.joints)
                            .inverse_inertia(data, c.base, c.theta);
      c.nominal = sample_force(G, nominal_sample, pb.law, run.force_model);
      each([&](std::uint64_t i) { c.forces[i] = sample_force(G, run.samples[i], pb.law, run.force_model); });
    }
  }
  progress(total_work, total_work);  // ends the line if one was shown
  for (const auto& smp : run.samples) run.redraws += static_cast<std::uint64_t>(smp.redraws);
}

/// The [uncertainty] table as drawn (an absent bound is left out: the JSON has no null).
nlohmann::json uncertainty_json(const UncertaintySpec& spec) {
  nlohmann::json u = nlohmann::json::object();
  for (std::size_t q = 0; q < kNumQuantities; ++q) {
    const Spread& sp = spec.spread[q];
    if (sp.law == Spread::Law::Fixed) continue;
    nlohmann::json e = {{"law", kLawNames[static_cast<int>(sp.law)]},
                        {"scale", sp.scale},
                        {"relative", sp.relative},
                        {"range", sp.has_range},
                        {"axes", sp.axes}};
    if (std::isfinite(sp.min)) e["min"] = sp.min;
    if (std::isfinite(sp.max)) e["max"] = sp.max;
    u[quantity_label(q)] = e;
  }
  return u;
}

/// One configuration: its pose, the nominal force, every sample's F_max and the largest kTail.
nlohmann::json configuration_json(const RobustRun& run, const Configuration& c) {
  const std::uint64_t count = run.end - run.first;
  nlohmann::json cj;
  cj["name"] = c.name;
  cj["joints_deg"] = to_json(Eigen::VectorXd(c.theta * (180.0 / M_PI)));
  cj["base_position"] = to_json(Eigen::VectorXd(c.base.position));
  const Eigen::Vector4d q = c.base.orientation.coeffs();
  cj["base_quaternion_wxyz"] = {q(3), q(0), q(1), q(2)};
  cj["nominal"] = {{"M_ie", c.nominal.M_ie},
                   {"approach_velocity", c.nominal.approach_velocity},
                   {"f_max", c.nominal.f_max}};
  std::vector<double> f(count);
  for (std::uint64_t i = 0; i < count; ++i) f[i] = c.forces[i].f_max;
  cj["f_max"] = f;
  std::vector<std::uint64_t> order(count);
  for (std::uint64_t i = 0; i < count; ++i) order[i] = i;
  const std::size_t k = std::min<std::size_t>(kTail, count);
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end(),
                    [&](std::uint64_t a, std::uint64_t b) { return f[a] != f[b] ? f[a] > f[b] : a < b; });
  cj["tail"] = nlohmann::json::array();
  for (std::size_t t = 0; t < k; ++t) {
    const auto i = order[t];
    cj["tail"].push_back({{"index", run.first + i},
                          {"f_max", f[i]},
                          {"M_ie", c.forces[i].M_ie},
                          {"approach_velocity", c.forces[i].approach_velocity},
                          {"extreme", extremes(run.samples[i], run.spec)},
                          {"parameters", sample_json(run.samples[i])}});
  }
  return cj;
}

/// The shard's summary (every sample's F_max, for merging).
nlohmann::json robust_json(const RobustRun& run, const RobustOptions& o) {
  const ScenarioKeys& so = run.sc.keys;
  nlohmann::json j;
  j["kind"] = "ffsr-robust";
  j["version"] = FFSR_VERSION;
  j["scenario"] = {{"source", o.config}, {"urdf", so.urdf}, {"model", so.model}, {"duration", so.duration}};
  j["force_model"] = o.force_model;
  j["law"] = run.sc.problem.law;
  j["seed"] = run.spec.seed;
  j["samples"] = run.spec.samples;
  j["shard"] = {{"k", run.shard_k}, {"n", run.shard_n}, {"first", run.first}, {"end", run.end}};
  j["uncertainty"] = uncertainty_json(run.spec);
  // the percentiles: conditional on the stiffness where F_max scales exactly with it (sampling.hpp)
  if (stiffness_conditional_applies(run.force_model, run.spec[Quantity::Stiffness])) {
    j["estimator"] = "stiffness-conditional";
    j["stiffness_nominal"] = run.nominal.contact.K;
    std::vector<double> K, alpha;
    for (const auto& smp : run.samples) {
      K.push_back(smp.contact.K);
      alpha.push_back(smp.contact.alpha);
    }
    j["stiffness"] = K;
    j["exponent"] = alpha;
  } else {
    j["estimator"] = "order-statistics";
  }
  j["configurations"] = nlohmann::json::array();
  j["redraws"] = run.redraws;
  for (const auto& c : run.configs) j["configurations"].push_back(configuration_json(run, c));
  finish_summary(j);
  return j;
}

/// One row per sample and configuration.
std::string robust_csv(const RobustRun& run) {
  std::ostringstream c;
  c << std::setprecision(12)
    << "configuration,sample,target_mass,Ixx,Iyy,Izz,Ixy,Ixz,Iyz,offset_x,offset_y,offset_z,normal_x,"
       "normal_y,"
       "normal_z,spin_x_deg,spin_y_deg,spin_z_deg,velocity_x,velocity_y,velocity_z,approach_speed,"
       "stiffness,"
       "exponent,restitution,robot_offset_x,robot_offset_y,robot_offset_z,M_ie,delta_dot,F_max\n";
  for (const auto& cf : run.configs)
    for (std::uint64_t i = 0; i < run.samples.size(); ++i) {
      const UncertainSample& s = run.samples[i];
      const Matrix3& I = s.target.inertia;
      const Vector3 w = s.target.angular_velocity * (180.0 / M_PI);
      c << cf.name << "," << run.first + i << "," << s.target.mass << "," << I(0, 0) << "," << I(1, 1) << ","
        << I(2, 2) << "," << I(0, 1) << "," << I(0, 2) << "," << I(1, 2);
      for (const Vector3* v : {&s.target.contact_offset, &s.target.normal, &w, &s.target.velocity})
        c << "," << (*v)(0) << "," << (*v)(1) << "," << (*v)(2);
      c << "," << s.approach_speed << "," << s.contact.K << "," << s.contact.alpha << "," << s.contact.c_r
        << "," << s.robot_offset(0) << "," << s.robot_offset(1) << "," << s.robot_offset(2) << ","
        << cf.forces[i].M_ie << "," << cf.forces[i].approach_velocity << "," << cf.forces[i].f_max << "\n";
    }
  return c.str();
}

/// JSON, CSV and the figure (the picture first: a failed drawing leaves no output file), then the table.
int report_robust(const RobustRun& run, const RobustOptions& o, Outputs& outputs, plot::Format plot_format) {
  const nlohmann::json j = robust_json(run, o);
  if (!o.json.empty()) outputs.set("--json", j.dump(1) + "\n");
  if (!o.csv.empty()) outputs.set("--csv", robust_csv(run));
  std::vector<std::string> drawn;
  if (!o.plot.empty()) drawn = plot::render({robust_figure(j)}, o.plot, plot_format);
  outputs.write();
  std::ostream& out = outputs.table();
  out << "ffsr-optimize " << FFSR_VERSION << " robust: " << run.sc.where << " (" << run.sc.model->n()
      << " joints, " << run.sc.problem.law << ", " << o.force_model << " F_max)\n"
      << run.spec.samples << " samples, seed " << run.spec.seed << "; this run: samples " << run.first
      << " to " << run.end << " (shard " << run.shard_k << "/" << run.shard_n << "), " << run.redraws
      << " redraws by the physical rules\n\n";
  print_summary(j, out);
  for (const std::string& f : drawn) out << "wrote " << f << "\n";
  return 0;
}

/// robust's own keys, also allowed in a scenario file (a flag overrides the file).
const std::set<std::string> kRobustKeys = {"force-model", "samples", "shard",       "threads", "json",
                                           "csv",         "plot",    "plot-format", "quiet"};

/// The flags, completed by the file's robust keys that no flag overrides.
RobustOptions with_file_keys(const RobustOptions& flags, const ScenarioKeys& keys, const CLI::App& app) {
  RobustOptions o = flags;
  for_each_file_key(keys, app,
                    [&](const std::string& name, const std::string& text, const std::string& flag) {
                      if (o.set_from_file(name, text, flag)) return;
                      if (name == "force-model") o.force_model = text;
                      if (name == "samples") o.samples = text;
                      if (name == "shard") o.shard = text;
                      if (name == "threads")
                        o.threads = static_cast<int>(detail::integer_from_text(text, flag));
                    });
  return o;
}

int run_robust(const RobustOptions& flags, const CLI::App& app) {
  if (!flags.merge.empty()) return run_merge(flags);
  if (flags.config.empty()) throw InputError("robust: --config SCENARIO.toml is required (or --merge FILES)");
  ScenarioKeys keys = read_scenario_file(flags.config, kRobustKeys);
  const RobustOptions o = with_file_keys(flags, keys, app);
  Outputs outputs;  // checked first (two outputs on standard output); the table goes to standard error then
  outputs.add("--json", o.json);
  outputs.add("--csv", o.csv);
  const plot::Format plot_format = plot::check_request(o.plot, o.plot_format);
  RobustRun run = parse_robust(o, std::move(keys));
  run.configs = o.capture_joints_deg.empty()
                    ? planned_configurations(run.sc, o.quiet)
                    : std::vector<Configuration>{given_configuration(o, *run.sc.model)};
  evaluate_samples(run, o);
  return report_robust(run, o, outputs, plot_format);
}

}  // namespace

void register_robust(CLI::App& app, Action& action) {
  auto o = std::make_shared<RobustOptions>();
  CLI::App* sub = app.add_subcommand(
      "robust",
      "Monte Carlo of F_max over the scenario's [uncertainty] table, for the planned capture configurations");
  sub->add_option("--config", o->config, "Scenario file (TOML) with an [uncertainty] table")
      ->check(CLI::ExistingFile);
  // before the scenario's keys: here --seed is the Monte Carlo seed, not the global search's
  // (ScenarioFlags leaves an existing --seed alone; robust_scenario sets the global search's to 1)
  sub->add_option("--seed", o->seed, "Seed, a non-negative integer (overrides uncertainty.seed)");
  o->flags.add_to(*sub);
  sub->add_option("--force-model", o->force_model,
                  "F_max per sample: closed (Eq. 24), exact (Eq. 16) or multibody (CVODE)")
      ->capture_default_str();
  sub->add_option("--samples", o->samples, "Number of samples (overrides uncertainty.samples)");
  sub->add_option("--threads", o->threads, "Worker threads")->capture_default_str();
  sub->add_option("--shard", o->shard, "Evaluate only shard K of N (K = 0..N-1) of the samples")
      ->capture_default_str();
  sub->add_option("--capture-joints-deg", o->capture_joints_deg,
                  "Evaluate this capture configuration instead of planning (deg; --joints-deg is the "
                  "scenario's start)")
      ->delimiter(',')
      ->allow_extra_args(false);
  sub->add_option("--capture-base-position", o->capture_base_position,
                  "Base position of that configuration, m")
      ->delimiter(',')
      ->allow_extra_args(false);
  sub->add_option("--capture-base-rpy-deg", o->capture_base_rpy_deg,
                  "Base attitude of that configuration, deg")
      ->delimiter(',')
      ->allow_extra_args(false);
  sub->add_option("--merge", o->merge,
                  "Merge these shard summaries (JSON files of --json) exactly; no scenario needed");
  sub->add_option("--json", o->json,
                  "Write the summary (with every sample's F_max, for merging) to this JSON file");
  sub->add_option("--csv", o->csv, "Write one row per sample and configuration to this CSV file");
  sub->add_option(
      "--plot", o->plot,
      "Draw the CDF and the histogram of F_max per configuration into this (existing) folder (robust.png)");
  sub->add_option("--plot-format", o->plot_format, "Figure format: png, svg or pdf")->capture_default_str();
  sub->add_flag("--quiet", o->quiet, "No progress line");
  sub->callback([o, sub, &action] { action = [o, sub] { return run_robust(*o, *sub); }; });
}

}  // namespace ffsr::cli
