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

void refuse_shapes_without_clearance(const ScenarioKeys& keys, const std::string& job) {
  if (keys.clearance > 0) return;
  for (const ScenarioKey& key : scenario_keys())
    if (key.group == KeyGroup::Shapes && key.name != "clearance" && keys.overridden.count(key.name))
      throw InputError(detail::str("--", key.name, ": ", job,
                                   " uses the shapes through the clearance only, and this run has none (clearance = 0)"));
}

}  // namespace ffsr::cli
