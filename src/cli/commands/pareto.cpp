// ffsr-optimize pareto: the front of (M_ie, base angular rate jump at the impact) on the capture
// manifold at the global run's base pose (ffsr/optimize/pareto.hpp), for a scenario as the main job; the
// job is the library's (ffsr/jobs/pareto.hpp).
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "figures/plot.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/pareto.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace ffsr::cli {
namespace {

struct ParetoCliOptions {
  ScenarioFlags flags;
  std::string config;
  ParetoJobOptions job;  ///< --levels, --starts
  OutputKeys out;        ///< --json, --csv, --plot, --quiet
};

constexpr double kDeg = 180.0 / M_PI;
const char* const kRunNames[] = {"plain run", "paper's method", "global run"};

void print_front(std::ostream& out, const Scenario& sc, const ParetoFront& f,
                 const std::vector<ParetoPoint>& runs) {
  auto row = [&](const char* label, const ParetoPoint& p, std::vector<std::string> not_applied = {}) {
    out << std::left << std::setw(26) << label << std::right << std::fixed << std::setprecision(4)
        << std::setw(11) << p.M_ie << std::scientific << std::setprecision(4) << std::setw(16)
        << p.base_rate * kDeg << std::defaultfloat;
    const char* sep = "  not applied: ";  // the keys of the scenario this run does not take
    for (const std::string& key : not_applied) {
      out << sep << key;
      sep = ", ";
    }
    out << "\n";
  };
  out << "ffsr-optimize pareto: " << sc.where << ": " << f.points.size()
      << " non-dominated capture configurations at the global run's base pose\n\n"
      << std::left << std::setw(26) << "" << std::right << std::setw(11) << "M_ie (kg)" << std::setw(16)
      << "|dw_0| (deg/s)"
      << "\n";
  row("least M_ie (end)", f.min_mass);
  row("knee", f.points[f.knee]);
  row("least base rate (end)", f.min_rate);
  const ScenarioRow rows[] = {ScenarioRow::Plain, ScenarioRow::Optimized, ScenarioRow::Global};
  for (size_t i = 0; i < runs.size(); ++i) row(kRunNames[i], runs[i], keys_not_applied(sc.keys, rows[i]));
  out << "\nhypervolume " << f.hypervolume * kDeg << " kg deg/s up to the nadir of the ends (normalized "
      << f.hypervolume_normalized << "); " << f.evaluations << " evaluations, " << f.seconds << " s\n"
      << "|dw_0|: jump of the base's angular velocity from the contact impulse (single-body model)\n";
}

/// The picture's data: the front and the runs, in the units of the table.
plot::Figure pareto_figure(const Scenario& sc, const ParetoFront& f, const std::vector<ParetoPoint>& runs) {
  figures::ParetoSeries s;
  s.title = sc.where;
  for (const ParetoPoint& p : f.points) {
    s.mass.push_back(p.M_ie);
    s.rate.push_back(p.base_rate * kDeg);
  }
  s.knee = f.knee;
  for (size_t i = 0; i < runs.size(); ++i)
    s.runs.push_back({kRunNames[i], runs[i].M_ie, runs[i].base_rate * kDeg});
  return figures::pareto(s);
}

/// A post-capture front: the table (its ends, knee and the runs, each with M_ie, the axis' value and
/// the impact's base rate) and the picture's data.
void print_post_capture_front(std::ostream& out, const Scenario& sc, const PostCaptureFront& f) {
  const std::string unit = detail::pareto_axis_unit(f.axis);
  auto row = [&](const char* label, const PostCaptureFrontPoint& p) {
    out << std::left << std::setw(32) << label << std::right << std::fixed << std::setprecision(4)
        << std::setw(11) << p.point.M_ie << std::setw(26);
    if (std::isfinite(p.value))
      out << p.value;
    else
      out << "not at rest";
    out << std::scientific << std::setprecision(4) << std::setw(16) << p.point.base_rate * kDeg
        << std::defaultfloat << "\n";
  };
  out << "ffsr-optimize pareto --axis " << f.axis << ": " << sc.where << ": " << f.points.size()
      << " non-dominated of " << f.candidates << " candidate capture configurations (" << f.at_rest
      << " at rest) at the global run's base pose\n\n"
      << std::left << std::setw(32) << "" << std::right << std::setw(11) << "M_ie (kg)" << std::setw(26)
      << (f.axis + " (" + unit + ")") << std::setw(16) << "|dw_0| (deg/s)"
      << "\n";
  row("least M_ie (end)", f.points.front());
  row("knee", f.points[f.knee]);
  row(("least " + f.axis + " (end)").c_str(), f.points.back());
  for (size_t i = 0; i < f.runs.size(); ++i) row(kRunNames[i], f.runs[i]);
  out << "\ncandidates: the global search's local optima and the (M_ie, base rate) sweep's points, each run "
         "through the grasp and the detumbling (docs/whole-capture.md)\n";
}

plot::Figure post_capture_figure(const Scenario& sc, const PostCaptureFront& f) {
  figures::ParetoSeries s;
  s.title = sc.where;
  for (const PostCaptureFrontPoint& p : f.points) {
    s.mass.push_back(p.point.M_ie);
    s.rate.push_back(p.value);
  }
  s.knee = f.knee;
  for (size_t i = 0; i < f.runs.size(); ++i)
    if (std::isfinite(f.runs[i].value))
      s.runs.push_back({kRunNames[i], f.runs[i].point.M_ie, f.runs[i].value});
  s.y_unit = detail::pareto_axis_unit(f.axis);
  s.y_name = f.axis;
  s.y_label = "post-capture " + f.axis + " (" + s.y_unit + ")";
  return figures::pareto(s);
}

int run_pareto(const ParetoCliOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs = o.out.outputs();
  check_pareto_job(o.job);
  const plot::Format plot_format = plot::check_request(o.out.plot, o.out.plot_format);
  ScenarioKeys keys = command_scenario_keys(o.config, o.flags);
  refuse_shapes_without_clearance(keys, "pareto");
  Scenario sc = command_scenario(std::move(keys));
  const ParetoJobResult job = pareto(sc, o.job);  // the main job's runs, then the front
  const ParetoFront& f = job.front;
  const std::vector<ParetoPoint>& runs = job.runs;
  const PostCaptureFront* pc = job.post_capture ? &*job.post_capture : nullptr;
  outputs.set("--json", pareto_json(sc, job, FFSR_VERSION).dump(2) + "\n");
  outputs.set("--csv", pc ? post_capture_front_csv(*pc) : pareto_csv(f));
  std::vector<std::string> drawn;
  if (!o.out.plot.empty())
    drawn = outputs.stage(plot::draw({pc ? post_capture_figure(sc, *pc) : pareto_figure(sc, f, runs)},
                                     o.out.plot, plot_format));
  outputs.write();
  std::ostream& out = outputs.table();
  if (pc)
    print_post_capture_front(out, sc, *pc);
  else
    print_front(out, sc, f, runs);
  for (const std::string& d : drawn) out << "wrote " << d << "\n";
  return 0;
}

}  // namespace

void register_pareto(CLI::App& app, Action& action) {
  auto o = std::make_shared<ParetoCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "pareto", "Front of M_ie against the base's angular rate jump at the impact, on the capture manifold");
  sub->add_option("--config", o->config, "Scenario file (TOML); default: the built-in paper 3-DOF scenario")
      ->check(CLI::ExistingFile);
  // the front is of M_ie under the scenario's joint model (the capture objective's); the multibody
  // reference's servo keys act with the global run's objective multibody-force only (refused otherwise)
  o->flags.add_groups(
      *sub,
      {KeyGroup::Robot, KeyGroup::Start, KeyGroup::Target, KeyGroup::TargetPlace, KeyGroup::Contact,
       KeyGroup::Planner, KeyGroup::Global, KeyGroup::JointModels, KeyGroup::Shapes, KeyGroup::Detumble},
      // the front is of M_ie and the base's jump (the impulse of the law's damping): the
      // stiffness and the exponent of the law change neither
      {"stiffness", "exponent"});
  sub->add_option("--levels", o->job.levels, "Epsilon levels of the sweep between the two ends")
      ->capture_default_str();
  sub->add_option("--starts", o->job.starts, "Random starts of the two single-objective searches")
      ->capture_default_str();
  sub->add_option("--axis", o->job.axis,
                  "Second objective: base-rate (the impact's), or a figure of the post-capture run under the "
                  "Detumble keys: time-to-rest, peak-joint-torque, gripper-force, gripper-moment")
      ->capture_default_str();
  add_output_flags(*sub, o->out,
                   {"Write the front (configurations, ends, knee, hypervolume) as JSON to FILE",
                    "Write the front, one configuration per row, as CSV to FILE",
                    "Draw the front (knee, ends and the three runs marked)"});
  sub->callback([o, &action] { action = [o] { return run_pareto(*o); }; });
}

}  // namespace ffsr::cli
