// python/src/job_helpers.hpp -- the pattern of every job of the command from Python: the job runs
// without the GIL into a new result that keeps the command's --json beside it, the result's class has
// to_dict() and to_json(), and the job is a method of ffsr.Scenario.
#pragma once

#include "arguments.hpp"
#include "outputs.hpp"

#include "ffsr/scenario/scenario.hpp"

#include <nanobind/stl/string.h>
#include <nanobind/stl/unique_ptr.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#ifndef FFSR_VERSION
#error "FFSR_VERSION must be defined (python/CMakeLists.txt reads it from the project)"
#endif

namespace ffsr::python {

/// A job's result and the command's --json for the same job, made together.
template <class Result>
struct JobRun {
  Result result;
  std::string json;
};

/// Runs `job(run)` on a new Run without the GIL: the job fills the result and its JSON.
template <class Run, class Job>
std::unique_ptr<Run> run_job(Job&& job) {
  auto run = std::make_unique<Run>();
  {
    nb::gil_scoped_release release;
    job(*run);
  }
  return run;
}

/// The class of a job's result, with to_dict() and to_json() (the command's --json).
template <class Run>
nb::class_<Run> job_result_class(nb::module_& m, const char* name, const char* doc) {
  nb::class_<Run> c(m, name, doc);
  c.def(
      "to_dict", [](const Run& r) { return json_loads(r.json); }, "The command's --json, as a dict.");
  c.def(
      "to_json", [](const Run& r) { return r.json; }, "The command's --json, as text.");
  return c;
}

/// Adds `fn` as the method `name` of ffsr.Scenario (bound before the jobs, by bind_scenario). An
/// error about one of its keyword arguments names the keyword ("Scenario.detumble: run: ...").
template <class Fn, class... Extra>
void def_scenario_method(const char* name, Fn&& fn, const Extra&... extra) {
  nb::handle scenario = nb::type<Scenario>();
  scenario.attr(name) =
      nb::cpp_function(keyword_errors(std::string("Scenario.") + name, std::forward<Fn>(fn), extra...),
                       nb::is_method(), nb::name(name), nb::scope(scenario), extra...);
}

/// A stack that holds its target (grasp-after = held) with none of the main job's keys is built as the
/// command's `detumble` builds it (Scenario.load: scope Configuration, no capture): detumble() runs on
/// it, and every other job refuses it, naming the first key it lacks.
inline void require_capture_scenario(const Scenario& sc) {
  if (sc.scope == ScenarioScope::Run) return;
  for (const std::string& key : required_scenario_keys())
    if (!sc.keys.given.count(key))
      throw InputError(detail::str(sc.where, ": missing key '", key,
                                   "' (grasp-after = held describes a stack that holds its target, on which "
                                   "Scenario.detumble() runs; this job evaluates a capture)"));
}

/// (key, value) given to a job as the command's flags; no value: the scenario's.
using KeyOverrides = std::vector<std::pair<const char*, std::optional<std::string>>>;

/// The scenario a one-configuration job evaluates: `sc` itself when no override is given; else the
/// scenario of its keys with `overrides` (values the main job refuses, as 'all'), built by the library
/// with scope Configuration into `variant` (as the command builds --config FILE with those flags).
inline const Scenario& scenario_with(const Scenario& sc, const KeyOverrides& overrides,
                                     std::optional<Scenario>& variant) {
  ScenarioKeys keys = sc.keys;
  bool changed = false;
  for (const auto& [key, value] : overrides)
    if (value) {
      override_scenario_key(keys, key, *value);
      changed = true;
    }
  if (!changed) return sc;
  variant.emplace(build_scenario(std::move(keys), nullptr, ScenarioScope::Configuration));
  return *variant;
}

}  // namespace ffsr::python
