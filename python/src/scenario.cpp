// python/src/scenario.cpp -- scenario files and the command's jobs in ffsr._ffsr: Scenario.load(path,
// **overrides) (the library's reader and validation, a keyword for each key the command takes as a flag)
// and Scenario.run(), the main job of `ffsr-optimize` (plain, paper's-method and global runs), whose
// result's to_dict() is the command's --json for the same scenario (with each run's post-capture phase
// when the scenario gives a Detumble key).
#include "bindings.hpp"
#include "job_helpers.hpp"

#include "ffsr/jobs/whole_capture.hpp"

#include <nanobind/stl/optional.h>
#include <nanobind/stl/vector.h>

#include <cstdlib>
#include <sstream>
#include <string>

namespace ffsr::python {
namespace {

using namespace nb::literals;
using detail::str;

/// A keyword's value as the text a flag would give: numbers as the shortest text that reads back as the
/// same double, booleans as true/false, lists (and 1-D arrays) joined with commas.
std::string flag_text(nb::handle v, const std::string& key) {
  auto number = [&](nb::handle x) -> std::string {
    if (PyBool_Check(x.ptr())) return x.ptr() == Py_True ? "true" : "false";
    if (PyLong_Check(x.ptr())) return nb::cast<std::string>(nb::str(x));
    if (PyFloat_Check(x.ptr())) return detail::shortest_number(PyFloat_AsDouble(x.ptr()));
    if (PyUnicode_Check(x.ptr())) return nb::cast<std::string>(x);
    if (nb::hasattr(x, "item") && nb::hasattr(x, "ndim") && nb::cast<int>(x.attr("ndim")) == 0)
      return flag_text(x.attr("item")(), key);  // a numpy scalar
    throw InputError(str("--", key, ": expected a number, a string, a boolean or a list, got ",
                         nb::cast<std::string>(nb::str(x.type().attr("__name__")))));
  };
  if (PyList_Check(v.ptr()) || PyTuple_Check(v.ptr()) ||
      (nb::hasattr(v, "tolist") && nb::hasattr(v, "ndim") && nb::cast<int>(v.attr("ndim")) == 1)) {
    nb::object seq = (PyList_Check(v.ptr()) || PyTuple_Check(v.ptr())) ? nb::borrow(v) : v.attr("tolist")();
    std::string text;
    for (nb::handle x : seq) text += (text.empty() ? "" : ",") + number(x);
    return text;
  }
  return number(v);
}

/// The main job's result and its JSON (the command's --json), made together, with its time series as
/// the command's --csv writes it (made from the same result).
struct RunResult : JobRun<ScenarioResult> {
  std::string series_csv;
};

/// The columns of a CSV (the main job's series): {name: numpy array} for the numbers, {name: list of
/// str} for the text columns `run` and `phase`; every value as the CSV writes it.
nb::dict csv_columns(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    std::vector<std::string>& row = rows.emplace_back();
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) row.push_back(f);
  }
  nb::dict d;
  if (rows.empty()) return d;
  const std::vector<std::string>& header = rows.front();
  const size_t n = rows.size() - 1;
  for (size_t c = 0; c < header.size(); ++c) {
    if (header[c] == "run" || header[c] == "phase") {
      nb::list texts;
      for (size_t i = 1; i <= n; ++i) texts.append(nb::str(rows[i].at(c).c_str()));
      d[header[c].c_str()] = texts;
    } else {
      double* data = nullptr;
      NewArray a = new_array(n, &data);
      for (size_t i = 1; i <= n; ++i) data[i - 1] = std::strtod(rows[i].at(c).c_str(), nullptr);
      d[header[c].c_str()] = a;
    }
  }
  return d;
}

/// A run of the main job that holds a result, else None.
std::optional<CaptureResult> run_or_none(bool ok, const CaptureResult& run) {
  return ok ? std::optional<CaptureResult>(run) : std::nullopt;
}

}  // namespace

void bind_capture_result(nb::module_& m) {
  nb::class_<CaptureResult>(m, "CaptureResult",
                            "One capture run of the planner (plain, paper's method or global).")
      .def_prop_ro(
          "theta", [](const CaptureResult& r) { return out(r.theta); }, "Capture configuration, rad.",
          nb::rv_policy::automatic)
      .def_ro("base", &CaptureResult::base, "Base pose at T.")
      .def_prop_ro(
          "end_effector", [](const CaptureResult& r) { return out(r.end_effector); },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "capture_point", [](const CaptureResult& r) { return out(r.capture_point); },
          nb::rv_policy::automatic)
      .def_ro("M_ie", &CaptureResult::M_ie, "Integrated effective mass at the capture (Eq. 14), kg.")
      .def_ro("approach_velocity", &CaptureResult::approach_velocity, "delta_dot^- at the capture, m/s.")
      .def_ro("f_max_closed_form", &CaptureResult::f_max_closed_form, "Peak force, closed form (Eq. 24), N.")
      .def_ro("f_max_exact", &CaptureResult::f_max_exact, "Peak force, exact single-body peak (Eq. 16), N.")
      .def_ro("tracking_error", &CaptureResult::tracking_error,
              "|p_e(T) - capture point| on the task's axes, m.")
      .def_ro("orientation_error", &CaptureResult::orientation_error,
              "Pose task: orientation error at T, rad.")
      .def_ro("max_joint_rate", &CaptureResult::max_joint_rate, "Largest |theta_dot_k| along the run, rad/s.")
      .def_ro("steps", &CaptureResult::steps);
}

void bind_run_result(nb::module_& m) {
  job_result_class<RunResult>(
      m, "RunResult",
      "The main job's result: the plain run, the paper's method (Eq. 29-31) and the global run.\n"
      "to_dict() is the command's --json for the same scenario.")
      .def_prop_ro(
          "plain", [](const RunResult& r) { return run_or_none(r.result.plain_ok(), r.result.plain); },
          "The plain run (rho = 0), or None when it failed (plain_failure).")
      .def_prop_ro(
          "optimized",
          [](const RunResult& r) { return run_or_none(r.result.optimized_ok(), r.result.optimized); },
          "The paper's method (the optimized run), or None when it failed (optimized_failure).")
      .def_prop_ro(
          "global_run",
          [](const RunResult& r) {
            return r.result.global ? std::optional<CaptureResult>(r.result.global->result.run) : std::nullopt;
          },
          "The global run, or None when the scenario has global = false.")
      .def_prop_ro("plain_failure", [](const RunResult& r) { return r.result.plain_failure; })
      .def_prop_ro("optimized_failure", [](const RunResult& r) { return r.result.optimized_failure; })
      .def_prop_ro(
          "post_capture",
          [](const RunResult& r) {
            nb::dict d;  // a copy of each run's summary and series
            for (const DetumbleJobResult& x : r.result.post_capture)
              d[x.run.c_str()] = nb::cast(x.result, nb::rv_policy::copy);
            return d;
          },
          "Each run's post-capture phase with a Detumble key, {run: DetumbleResult}; else empty.")
      .def(
          "series_csv", [](const RunResult& r) { return r.series_csv; },
          "The time series of every run as the command's --csv writes it (run, t, joint angles, the base's,\n"
          "the target's and every body's pose, M_ie, the F_max estimate, phase).")
      .def_prop_ro(
          "series", [](const RunResult& r) { return csv_columns(r.series_csv); },
          "The columns of series_csv(): {name: numpy array}, the text columns run and phase as lists of\n"
          "str. ffsr.view.capture(result) draws the run from them.");
}

void bind_scenario(nb::module_& m) {
  nb::class_<Scenario>(
      m, "Scenario",
      "A validated capture scenario (the command's --config file): the robot, the target, the\n"
      "contact, the tasks, the planner and the global run.")
      .def_static(
          "load",
          [](const std::string& path, nb::kwargs overrides) {
            ScenarioKeys keys = read_scenario_file(path);
            std::vector<std::string> keywords;  // an error about one names the keyword, not the flag
            for (auto [k, v] : overrides) keywords.push_back(nb::cast<std::string>(k));
            return with_keyword_errors("Scenario.load", keywords, [&] {
              for (auto [k, v] : overrides) {
                std::string key = nb::cast<std::string>(k);
                for (char& c : key)
                  if (c == '_') c = '-';
                if (!find_scenario_key(key)) throw InputError(str("--", key, ": not a scenario key"));
                override_scenario_key(keys, key, flag_text(v, key));
              }
              // a stack that holds its target needs none of the main job's keys: built as `detumble`
              // builds it when it lacks one (require_capture_scenario refuses the other jobs)
              bool run = true;
              for (const std::string& key : required_scenario_keys()) run = run && keys.given.count(key);
              const bool held = holds_target(keys) && !run;
              return std::make_unique<Scenario>(build_scenario(
                  std::move(keys), nullptr, held ? ScenarioScope::Configuration : ScenarioScope::Run));
            });
          },
          "path"_a, "overrides"_a,
          "Reads and validates a scenario file. A keyword overrides the key of the same name, as the "
          "command's\n"
          "flag does (an underscore for a dash: Scenario.load(path, gain=-0.02, joints_deg=[0, 90, -90])).\n"
          "InputError naming the file or the key; ModelError from the URDF loader.")
      .def_prop_ro("where", [](const Scenario& s) { return s.where; })
      .def_prop_ro(
          "model", [](const Scenario& s) -> const Model& { return *s.model; },
          nb::rv_policy::reference_internal, "The robot as loaded.")
      .def_prop_ro(
          "target", [](const Scenario& s) { return s.problem.target; }, "The target at t = 0.")
      .def_prop_ro(
          "base", [](const Scenario& s) { return s.problem.base; }, "The base pose at t = 0.")
      .def_prop_ro(
          "theta", [](const Scenario& s) { return out(s.problem.theta); }, "The joint angles at t = 0, rad.",
          nb::rv_policy::automatic)
      .def(
          "run",
          [](const Scenario& sc) {
            require_capture_scenario(sc);
            return run_job<RunResult>([&sc](RunResult& r) {
              ScenarioRunOptions o;
              o.keep_going = true;     // as the command: a failed plain or paper's-method row is reported
              o.record_series = true;  // the series of the command's --csv (RunResult.series)
              r.result = run_whole_capture(sc, o);  // with a Detumble key: each run's post-capture phase
              r.json = scenario_json(sc, r.result, FFSR_VERSION).dump();
              r.series_csv = scenario_series_csv(sc, r.result);
            });
          },
          "The main job (ffsr-optimize --config FILE): the plain run, the paper's method (Eq. 29-31) and, "
          "unless\n"
          "global = false, the global run; M_ie (Eq. 14) and the peak force (Eq. 24, Eq. 16) of each;\n"
          "with a Detumble key, each run's post-capture phase (RunResult.post_capture); the time series\n"
          "of the command's --csv (RunResult.series, series_csv()): ffsr.view.capture(scenario.run()).");
}

}  // namespace ffsr::python
