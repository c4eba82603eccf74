// ffsr-optimize xi: the relative error xi of the closed-form maximum force (Eq. 24 against the
// exact peak of Eq. 16) for the eight damping laws, against K, delta_dot^- and c_r -- the studies of
// Figures 4-6. The parameters held fixed in each study are a scenario's contact law (--config, or the
// built-in scenario: the paper's), flags override them. CSV always (a file, or stdout), pictures on
// request.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/scenario_run.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace ffsr::cli {
namespace {

struct XiOptions {
  std::string config;
  ScenarioFlags flags;  ///< exponent, restitution
  int points = 41;
  OutputKeys out;  ///< --json, --csv, --plot, --quiet
};

/// n values from a to b, evenly spaced (on a log scale when `log`).
std::vector<double> spaced(double a, double b, int n, bool log) {
  std::vector<double> v;
  for (int k = 0; k < n; ++k) {
    const double f = n == 1 ? 0.0 : double(k) / double(n - 1);
    v.push_back(log ? a * std::pow(b / a, f) : a + (b - a) * f);
  }
  v.back() = b;
  return v;
}

/// The three studies of Figures 4-6, checked: the fixed contact parameters, the laws, and for each
/// study the values of the varied parameter (xi still empty).
struct XiSetup {
  ContactParams base;
  double approach_speed = 0;
  plot::Format plot_format = plot::Format::Png;
  std::vector<figures::XiStudy> studies;
};

/// The varied parameter of each study as the CSV names it; the study is xi_<column>.
constexpr const char* kColumns[] = {"stiffness", "approach_speed", "restitution"};

/// One study of `laws` against `x`.
figures::XiStudy study(const char* column, std::string title, std::string xlabel, bool log_x,
                       std::vector<double> x, const std::vector<std::string>& laws) {
  return {std::string("xi_") + column, std::move(title), std::move(xlabel), log_x, std::move(x), laws, {}};
}

XiSetup parse(const XiOptions& o) {
  using detail::str;
  if (o.points < 2 || o.points > 100000)
    throw InputError(str("--points: expected 2 to 100000, got ", o.points));
  const ScenarioKeys k = command_scenario_keys(o.config, o.flags);
  try {  // every key read is checked, a file's keys for other jobs too (as load_subject does)
    for (const ScenarioKey& key : scenario_keys())
      if (key.check) key.check(k);
  } catch (const InputError& e) {
    throw InputError(located_key_message(k, e.what()));
  }
  XiSetup s;
  s.base = {k.stiffness, k.exponent, k.restitution};
  try {
    validate(s.base, "contact");
  } catch (const InputError& e) {
    throw InputError(str("--stiffness/--exponent/--restitution: ", e.what()));
  }
  if (!std::isfinite(k.approach_speed) || k.approach_speed <= 0)
    throw InputError(str("--approach-speed: must be positive and finite, got ", k.approach_speed));
  s.approach_speed = k.approach_speed;
  s.plot_format = plot::check_request(o.out.plot, o.out.plot_format);
  std::vector<std::string> laws;
  for (auto n : contact_law_names()) laws.emplace_back(n);
  auto g = [](double x) {
    std::ostringstream os;
    os << std::setprecision(4) << x;
    return os.str();
  };
  const std::string fixed_k = "K = " + g(s.base.K) + " N/m^" + g(s.base.alpha),
                    fixed_v = "δ̇⁻ = " + g(s.approach_speed) + " m/s", fixed_c = "c#dr#u = " + g(s.base.c_r);
  s.studies = {
      study(kColumns[0], "ξ against K (Figure 4): " + fixed_v + ", " + fixed_c, "contact stiffness K (N/m^α)",
            true, spaced(1e7, 1e11, o.points, true), laws),
      study(kColumns[1], "ξ against δ̇⁻ (Figure 5): " + fixed_k + ", " + fixed_c,
            "initial relative contact velocity δ̇⁻ (m/s)", true, spaced(0.01, 1.0, o.points, true), laws),
      study(kColumns[2], "ξ against c#dr#u (Figure 6): " + fixed_k + ", " + fixed_v,
            "coefficient of restitution c#dr#u", false, spaced(0.1, 1.0, o.points, false), laws)};
  return s;
}

/// Fills xi[law][k] of each study: study 0 varies K, study 1 delta_dot^-, study 2 c_r.
void compute(XiSetup& s) {
  for (size_t k = 0; k < s.studies.size(); ++k) {
    auto& st = s.studies[k];
    st.xi.assign(st.laws.size(), {});
    for (size_t l = 0; l < st.laws.size(); ++l)
      for (double x : st.x) {
        ContactParams p = s.base;
        double v = s.approach_speed;
        if (k == 0) p.K = x;
        if (k == 1) v = x;
        if (k == 2) p.c_r = x;
        st.xi[l].push_back(relative_error(make_contact_law(st.laws[l], p, v)));
      }
  }
}

/// study,parameter,law,xi_percent: one row per study, law and value.
std::string xi_csv(const XiSetup& s) {
  std::ostringstream csv;
  csv << std::setprecision(12) << "study,parameter,law,xi_percent\n";
  for (size_t k = 0; k < s.studies.size(); ++k) {
    const auto& st = s.studies[k];
    for (size_t l = 0; l < st.laws.size(); ++l)
      for (size_t i = 0; i < st.x.size(); ++i)
        csv << kColumns[k] << "," << st.x[i] << "," << st.laws[l] << "," << st.xi[l][i] << "\n";
  }
  return csv.str();
}

/// The fixed parameters and, per study, the varied values and xi (percent) of each law.
nlohmann::json xi_json(const XiSetup& s) {
  nlohmann::json j;
  j["parameters"] = {{"stiffness", s.base.K},
                     {"exponent", s.base.alpha},
                     {"restitution", s.base.c_r},
                     {"approach_speed", s.approach_speed}};
  j["studies"] = nlohmann::json::array();
  for (size_t k = 0; k < s.studies.size(); ++k) {
    const auto& st = s.studies[k];
    nlohmann::json laws = nlohmann::json::object();
    for (size_t l = 0; l < st.laws.size(); ++l) laws[st.laws[l]] = st.xi[l];
    j["studies"].push_back({{"study", kColumns[k]}, {"parameter", st.x}, {"xi_percent", laws}});
  }
  j["version"] = FFSR_VERSION;
  return j;
}

/// The figures (when asked), the JSON and the CSV; without --csv the CSV is the table (standard
/// output, or standard error when the JSON goes there).
int report(const XiOptions& o, const XiSetup& s) {
  Outputs outputs = o.out.outputs();
  if (!o.out.plot.empty()) {
    std::vector<plot::Figure> figs;
    for (const auto& st : s.studies) figs.push_back(figures::xi(st));
    outputs.stage(plot::draw(figs, o.out.plot, s.plot_format));
  }
  const std::string csv = xi_csv(s);
  outputs.set("--json", xi_json(s).dump(2) + "\n");
  outputs.set("--csv", csv);
  outputs.write();
  if (o.out.csv.empty()) outputs.table() << csv;
  return 0;
}

int run_xi(const XiOptions& o) {
  set_quiet(o.out.quiet);
  XiSetup s = parse(o);
  compute(s);
  return report(o, s);
}

}  // namespace

void register_xi(CLI::App& app, Action& action) {
  auto o = std::make_shared<XiOptions>();
  CLI::App* sub = app.add_subcommand(
      "xi",
      "Relative error xi of the closed-form maximum force against K, delta_dot^- and c_r (Figures 4-6)");
  sub->add_option("--config", o->config,
                  "Scenario file (TOML) whose contact law (stiffness, exponent, restitution, approach-speed) "
                  "the studies hold fixed; flags override it (default: the built-in scenario, the paper's)")
      ->check(CLI::ExistingFile);
  // every law of Table 1 damps with chi(c_r) K / delta_dot^-: xi depends on the exponent and the
  // restitution only, so the stiffness and the approach speed are not taken (the studies show xi flat
  // against both)
  o->flags.add_to(*sub, [](const std::string& name) { return name == "exponent" || name == "restitution"; });
  sub->add_option("--points", o->points, "Values per study")->capture_default_str();
  add_output_flags(
      *sub, o->out,
      {"Write the studies (the fixed parameters, xi of each law against each value) as JSON to FILE",
       "Write study,parameter,law,xi_percent as CSV to FILE (default: the table, on standard output)",
       "Draw the three studies"});
  sub->callback([o, &action] { action = [o] { return run_xi(*o); }; });
}

}  // namespace ffsr::cli
