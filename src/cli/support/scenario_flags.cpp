#include "support/scenario_flags.hpp"

namespace ffsr::cli {

using detail::str;

void ScenarioFlags::add_to(CLI::App& app, const std::function<bool(const std::string&)>& only) {
  for (const ScenarioKey& key : scenario_keys()) {
    const std::string flag = "--" + key.name;
    if ((only && !only(key.name)) || app.get_option_no_throw(flag)) continue;
    CLI::Option* opt = nullptr;
    if (key.kind == KeyKind::Numbers || key.kind == KeyKind::Texts)
      // no delimiter: the list reaches the scenario parser whole, which names an empty item or a trailing comma
      opt = app.add_option(flag, lists_[key.name], key.help)->allow_extra_args(false);
    else
      opt = app.add_option(flag, text_[key.name], key.help);
    if (!key.default_text.empty()) opt->default_str(key.default_text);
    options_.emplace_back(&key, opt);
  }
}

void ScenarioFlags::add_groups(CLI::App& app, std::initializer_list<KeyGroup> groups,
                               const std::set<std::string>& except) {
  const std::set<std::string> names = scenario_key_names(groups);
  add_to(app, [&](const std::string& name) { return names.count(name) && !except.count(name); });
}

bool ScenarioFlags::given(const std::string& name) const {
  for (const auto& [key, opt] : options_)
    if (key->name == name) return opt->count() > 0;
  return false;
}

void ScenarioFlags::apply(ScenarioKeys& keys) const {
  for (const auto& [key, opt] : options_) {
    if (opt->count() == 0) continue;
    std::string text;
    if (key->kind == KeyKind::Numbers || key->kind == KeyKind::Texts) {
      for (const std::string& item : lists_.at(key->name)) text += (text.empty() ? "" : ",") + item;
    } else {
      text = text_.at(key->name);
    }
    override_scenario_key(keys, key->name, text);
  }
}

namespace {

/// What a key of `group` describes, and what a subcommand that does not take it does not do.
const char* group_reason(KeyGroup group) {
  switch (group) {
    case KeyGroup::Robot: return "a key of the robot, which";
    case KeyGroup::Start: return "a key of the start state, which";
    case KeyGroup::Target: return "a key of the target, which";
    case KeyGroup::TargetPlace: return "a key of where the target is (the capture point, distances), which";
    case KeyGroup::Contact: return "a key of the contact law, which";
    case KeyGroup::Planner: return "a key of the capture planner's runs (plain and optimized), which";
    case KeyGroup::Global: return "a key of the global capture optimization, which";
    case KeyGroup::JointModels: return "a key of the joints' model during the contact, which";
    case KeyGroup::Shapes: return "a key of the collision shapes, which";
    case KeyGroup::Detumble: return "a key of the post-capture phase, which";
    case KeyGroup::PostCapture: return "a key of the global search's post-capture constraints, which";
  }
  return "a key which";
}

/// A subcommand's own reason for leaving out keys of a group it takes.
struct UntakenReason {
  const char* sub;
  std::vector<std::string> keys;
  std::string why;
};

/// The subcommands' own reasons (their registrations leave these keys out of groups they take).
const std::vector<UntakenReason>& untaken_reasons() {
  static const std::vector<UntakenReason> reasons = {
      {"map", {"base-position"}, "M_ie and F_max do not depend on where the base is"},
      {"closed-loop", {"global"}, "the controller flies the plan that --plan names"},
      {"closed-loop",
       {"baseline-task", "base-attitude"},
       "the controller flies the plan as planned: the planner's tasks are not the controller's"},
      {"inspect",
       {"stiffness", "exponent"},
       "the law's stiffness and exponent change neither M_ie nor the base's jump at the impact that inspect "
       "reports"},
      {"pareto",
       {"stiffness", "exponent"},
       "the law's stiffness and exponent change neither M_ie nor the base's jump at the impact that pareto "
       "reports"},
      {"inspect",
       {"clearance", "contact-exemption"},
       "inspect reports the distances between whole bodies; the clearance constrains plans only"},
      {"robust", {"joint-stiffness", "joint-damping"}, "robust's multibody force model runs with the library's default servo"},
      {"xi",
       {"stiffness", "approach-speed"},
       "xi depends on the exponent and the restitution only; its studies vary the stiffness and the "
       "approach speed"},
  };
  return reasons;
}

/// Why `sub` does not take `key`: its own reason where it has one (untaken_reasons), else its group's.
std::string untaken_reason(const std::string& sub, const ScenarioKey& key) {
  for (const UntakenReason& r : untaken_reasons())
    if (sub == r.sub && std::find(r.keys.begin(), r.keys.end(), key.name) != r.keys.end()) return r.why;
  return str(group_reason(key.group), " ", sub, " does not evaluate");
}

}  // namespace

void refuse_untaken_scenario_keys(CLI::App& app) {
  const std::vector<CLI::App*> subs = app.get_subcommands([](CLI::App*) { return true; });
  for (const ScenarioKey& key : scenario_keys()) {
    const std::string flag = "--" + key.name;
    std::vector<std::string> takers;
    if (app.get_option_no_throw(flag)) takers.push_back("the main job");
    for (const CLI::App* sub : subs)
      if (sub->get_option_no_throw(flag)) takers.push_back(sub->get_name());
    std::string who;
    for (size_t i = 0; i < takers.size(); ++i)
      who += (i == 0 ? "" : i + 1 == takers.size() ? " and " : ", ") + takers[i];
    for (CLI::App* sub : subs) {
      if (sub->get_option_no_throw(flag)) continue;
      const std::string others = who.empty() ? "" : "; " + who + (takers.size() > 1 ? " do" : " does");
      const std::string why = str(flag, ": ", untaken_reason(sub->get_name(), key), " (the subcommand ",
                                  sub->get_name(), " does not take it", others, ")");
      // one value, as the flag takes where it is taken, refused whatever it is (InputError: one line,
      // exit 2; a hidden option has no name for the parser's own messages)
      sub->add_option(flag)->group("")->allow_extra_args(false)->each([why](const std::string&) {
        throw InputError(why);
      });
    }
  }
}

void refuse_shapes_without_clearance(const ScenarioKeys& keys, const std::string& job) {
  if (keys.clearance > 0) return;
  for (const ScenarioKey& key : scenario_keys())
    if (key.group == KeyGroup::Shapes && key.name != "clearance" && keys.overridden.count(key.name))
      throw InputError(detail::str("--", key.name, ": ", job,
                                   " uses the shapes through the clearance only, and this run has none (clearance = 0)"));
}

}  // namespace ffsr::cli
