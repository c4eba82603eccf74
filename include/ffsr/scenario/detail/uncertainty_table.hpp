// ffsr/scenario/detail/uncertainty_table.hpp -- the [uncertainty] table of a scenario file
// (ffsr/scenario/scenario.hpp: uncertainty_spec), read into the sampler's laws (uncertainty/sampling.hpp).
#pragma once

#include "ffsr/errors.hpp"
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <string>

namespace ffsr {

namespace detail {

inline double spread_number(const toml::node& n, const std::string& key) {
  if (auto i = n.value_exact<int64_t>()) return static_cast<double>(*i);
  if (auto d = n.value_exact<double>()) {
    if (!std::isfinite(*d)) throw InputError(str(key, ": must be finite, got ", *d));
    return *d;
  }
  throw InputError(str(key, ": expected a number"));
}

/// Exactly one of `opts` given, or InputError naming them.
inline void one_of(const std::string& key, const std::string& law,
                   std::initializer_list<std::pair<const char*, std::optional<double>>> opts) {
  int count = 0;
  std::string names;
  for (const auto& [n, v] : opts) {
    count += v.has_value();
    names += (names.empty() ? "" : " or ") + std::string(n);
  }
  if (count != 1) throw InputError(str(key, ": the ", law, " law takes exactly one of ", names));
}

/// Refuses a parameter of a law's table that no law takes.
inline void check_spread_parameter_names(const toml::table& t, const std::string& key) {
  static const std::set<std::string> known{"law", "std", "relative-std", "half-width", "relative",
                                           "min", "max", "sigma",        "angle-deg",  "axes-deg"};
  for (const auto& [k, v] : t)
    if (!known.count(std::string(k.str())))
      throw InputError(str(key, ".", k.str(),
                           ": unknown parameter; expected law, std, relative-std, half-width, ",
                           "relative, min, max, sigma, angle-deg or axes-deg"));
}

/// The numbers of a law's table, as given (units of the file); the spreads checked non-negative.
struct SpreadParameters {
  std::optional<double> sd, rsd, hw, rel, lo, hi, sigma, angle, axes;
};

inline SpreadParameters spread_parameters(const toml::table& t, const std::string& key) {
  auto get = [&](const char* name) -> std::optional<double> {
    if (const toml::node* n = t.get(name)) return spread_number(*n, str(key, ".", name));
    return std::nullopt;
  };
  SpreadParameters p;
  p.sd = get("std");
  p.rsd = get("relative-std");
  p.hw = get("half-width");
  p.rel = get("relative");
  p.lo = get("min");
  p.hi = get("max");
  p.sigma = get("sigma");
  p.angle = get("angle-deg");
  p.axes = get("axes-deg");
  for (const auto& [name, v] : {std::pair{"std", p.sd},
                                {"relative-std", p.rsd},
                                {"half-width", p.hw},
                                {"relative", p.rel},
                                {"sigma", p.sigma},
                                {"angle-deg", p.angle},
                                {"axes-deg", p.axes}})
    if (v && *v < 0)
      throw InputError(str(key, ".", name, ": a spread must be non-negative, got ", short_number(*v)));
  return p;
}

/// The law named `law` and its scale from the parameters (`unit`: file unit to SI of the scale).
inline Spread spread_law(const std::string& law, const SpreadParameters& p, const std::string& key,
                         double unit) {
  Spread sp;
  if (law == "normal") {
    sp.law = Spread::Law::Normal;
    one_of(key, law, {{"std", p.sd}, {"relative-std", p.rsd}});
    sp.relative = p.rsd.has_value();
    sp.scale = p.sd ? *p.sd * unit : *p.rsd;
  } else if (law == "uniform") {
    sp.law = Spread::Law::Uniform;
    const bool range = p.lo.has_value() && p.hi.has_value() && !p.hw && !p.rel;
    if (!range) one_of(key, law, {{"half-width", p.hw}, {"relative", p.rel}});
    sp.has_range = range;
    sp.relative = p.rel.has_value();
    sp.scale = p.hw ? *p.hw * unit : p.rel ? *p.rel : 0.0;
  } else if (law == "log-normal") {
    sp.law = Spread::Law::LogNormal;
    if (!p.sigma) throw InputError(str(key, ": the log-normal law needs sigma (standard deviation of ln x)"));
    sp.scale = *p.sigma;
  } else if (law == "cone") {
    sp.law = Spread::Law::Cone;
    if (!p.angle) throw InputError(str(key, ": the cone law needs angle-deg (half-angle)"));
    sp.scale = *p.angle * M_PI / 180.0;
  } else {
    throw InputError(str(key, ".law: unknown law '", law, "'; expected normal, uniform, log-normal or cone"));
  }
  return sp;
}

inline Spread spread_of(Quantity q, const toml::table& t, const std::string& key) {
  check_spread_parameter_names(t, key);
  const auto law = t["law"].value<std::string>();
  if (!law) throw InputError(str(key, ": missing law (normal, uniform, log-normal or cone)"));
  const SpreadParameters p = spread_parameters(t, key);
  // spin is given in deg/s, the library takes rad/s
  const double unit = q == Quantity::Spin ? M_PI / 180.0 : 1.0;
  Spread sp = spread_law(*law, p, key, unit);
  if (q == Quantity::TargetInertia && sp.law != Spread::Law::Cone && !sp.relative)
    throw InputError(str(key, ": the inertia takes a relative spread (relative-std or relative)"));
  if (p.lo) sp.min = *p.lo * unit;
  if (p.hi) sp.max = *p.hi * unit;
  if (p.axes) sp.axes = *p.axes * M_PI / 180.0;
  if (p.axes && q != Quantity::TargetInertia)
    throw InputError(str(key, ".axes-deg: only the inertia takes it"));
  return sp;
}

/// samples or seed of the table.
inline std::uint64_t count_of(const toml::node& v, const std::string& name, const std::string& key) {
  const auto i = v.value_exact<int64_t>();
  if (!i) throw InputError(str(key, ": must be an integer"));
  if (name == "samples" && *i < 1) throw InputError(str(key, ": must be at least 1, got ", *i));
  if (name == "seed" && *i < 0) throw InputError(str(key, ": must be a non-negative integer, got ", *i));
  return static_cast<std::uint64_t>(*i);
}

/// One entry `name` = `v` of the [uncertainty] table into `spec`: samples, seed or a quantity's law.
inline void read_uncertainty_entry(UncertaintySpec& spec, const std::string& name, const toml::node& v) {
  const std::string key = "uncertainty." + name;
  if (name == "samples" || name == "seed") {
    (name == "samples" ? spec.samples : spec.seed) = count_of(v, name, key);
    return;
  }
  const auto it = std::find(kQuantityNames.begin(), kQuantityNames.end(), name);
  if (it == kQuantityNames.end()) {
    std::string names;
    for (auto n : kQuantityNames) names += (names.empty() ? "" : ", ") + std::string(n);
    throw InputError(str(key, ": unknown uncertain quantity; expected one of ", names, ", samples, seed"));
  }
  const toml::table* t = v.as_table();
  if (!t) throw InputError(str(key, ": expected a table such as { law = \"normal\", std = 0.01 }"));
  const Quantity q = static_cast<Quantity>(it - kQuantityNames.begin());
  spec[q] = spread_of(q, *t, key);
}

}  // namespace detail

inline UncertaintySpec uncertainty_spec(const ScenarioKeys& keys, std::optional<std::uint64_t> samples,
                                        std::optional<std::uint64_t> seed) {
  using detail::str;
  const toml::node* node = keys.document ? keys.document->get("uncertainty") : nullptr;
  if (!node) throw InputError(str(keys.where, ": no [uncertainty] table"));
  const toml::table* u = node->as_table();
  if (!u) throw InputError(str(keys.where, ": 'uncertainty' must be a table"));
  UncertaintySpec spec;
  for (const auto& [k, v] : *u) {
    const std::string name(k.str());
    try {  // an entry's error is located at its line
      detail::read_uncertainty_entry(spec, name, v);
    } catch (const InputError& e) {
      throw InputError(detail::located(keys.where, v, e.what()));
    }
  }
  if (samples) spec.samples = *samples;
  if (seed) spec.seed = *seed;
  try {
    validate(spec);
  } catch (const InputError& e) {  // "uncertainty.<entry>...: ": located at the entry's line
    const std::string m = e.what(), prefix = "uncertainty.";
    const toml::node* entry =
        m.rfind(prefix, 0) == 0
            ? u->get(m.substr(prefix.size(), m.find_first_of(".:", prefix.size()) - prefix.size()))
            : nullptr;
    if (!entry) throw;
    throw InputError(detail::located(keys.where, *entry, m));
  }
  return spec;
}

}  // namespace ffsr
