// ffsr-optimize map: the integrated effective mass M_ie (Eq. 14) and the closed-form maximum contact
// force F_max (Eq. 24) over a grid of joint angles (the paper's Figures 8 and 9), the joints not
// varied held at --joints-deg. The grid, its numbering and its shards are the library's job
// (ffsr/jobs/map.hpp); this file parses the flags and writes what the job hands it.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/map.hpp"

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>

// The CSV: one row per point in the grid's numbering. Only shard 0 writes the header line, so `cat` of
// the N shard files in the order k = 0..N-1 is, byte for byte, the CSV of the whole grid. Each block
// of points is formatted with std::to_chars (the shortest text that reads back as the same double) on
// the thread that evaluated it and appended to the output in point order, so the output never has
// to fit in memory. The file is written like every output of the command (Outputs::stream: a
// temporary next to the destination, renamed with the other outputs at the end: all or nothing).
//
// Pictures (--plot DIR): one varied joint gives M_ie against the angle; two a heat map with contour
// lines and a colour bar (Figure 9); three the orthogonal slices through --slice-deg (Figure 9's
// theta_i = 0 slices) and the grid as coloured points in 3-D (Figure 8). The values are kept in memory
// for that (8 bytes a point), so a plotted grid is limited to kMaxPlotPoints; a shard holds part of
// the grid only and is not plotted.

namespace ffsr::cli {
namespace map_impl {  // named, not anonymous: the command is one unity translation unit

using detail::str;

struct MapOptions {
  SubjectOptions subject;  ///< the robot, the target, the law and the joint model of the mapped M_ie
  std::string vary;
  std::string range_deg = "-180,180";
  std::string step_deg = "2";
  std::string shard = "0/1";
  std::string slice_deg;
  unsigned threads = 0;
  std::uint64_t max_points = 1000000000ULL;
  OutputKeys out;  ///< --csv (the map), --json (its summary), --plot, --quiet
};

/// The job's options from the flags' text: the lists parsed, the joints checked to be whole numbers.
MapJobOptions job_options(const MapOptions& o, const std::string& urdf, int n_joints) {
  MapJobOptions j;
  for (double v : parse_list(o.vary, "--vary")) {
    if (v != std::floor(v) || v < 1 || v > n_joints)
      throw InputError(str("--vary: joint ", v, " is not one of 1..", n_joints, " (the robot in ", urdf, " has ",
                           n_joints, " joints, numbered from 1 in URDF tree order)"));
    j.vary.push_back(static_cast<int>(v));
  }
  const size_t k = j.vary.size();
  j.range_deg =
      parse_list(o.range_deg, "--range-deg", k == 1 ? std::vector<size_t>{2} : std::vector<size_t>{2, 2 * k});
  j.step_deg = parse_list(o.step_deg, "--step-deg", k == 1 ? std::vector<size_t>{1} : std::vector<size_t>{1, k});
  const Shard shard = parse_shard(o.shard);
  j.shard_k = shard.k;
  j.shard_n = shard.n;
  j.threads = o.threads;
  j.max_points = o.max_points;
  return j;
}

/// Appends the shortest round-trip text of x and a separator.
inline char* put(char* p, char* end, double x, char sep) {
  const auto r = std::to_chars(p, end, x);
  *r.ptr = sep;
  return r.ptr + 1;
}

/// A block's CSV rows, formatted on the thread that evaluated it (one buffer per thread, no heap
/// allocation per block).
struct RowText {
  std::vector<char> text;
  size_t bytes = 0;
  void format(const MapBlock& b, size_t k) {
    char* p = text.data();
    char* const end = text.data() + text.size();
    for (std::uint64_t i = 0; i < b.count; ++i) {
      for (size_t a = 0; a < k; ++a) p = put(p, end, b.angles_deg[i * k + a], ',');
      p = put(p, end, b.M_ie[i], ',');
      p = put(p, end, b.f_max[i], '\n');
    }
    bytes = static_cast<size_t>(p - text.data());
  }
};

std::string point_deg(const MapGrid& g, std::uint64_t idx) {
  const std::vector<double> a = g.point_angles(idx);
  std::ostringstream os;
  os << "[";
  for (size_t i = 0; i < a.size(); ++i) os << (i ? ", " : "") << a[i];
  os << "]";
  return os.str();
}

constexpr std::uint64_t kMaxPlotPoints = 50000000;

/// The figures of a plotted grid (see the notes after the includes).
std::vector<plot::Figure> map_figures(const MapGrid& grid, const std::vector<std::string>& names,
                                      std::vector<double> values, const std::vector<double>& slice_deg) {
  figures::Grid g;
  for (const MapAxis& a : grid.axes) {
    g.axis_labels.push_back(str("θ", a.joint + 1, " (deg)"));
    std::vector<double> axis(a.count);
    for (std::uint64_t i = 0; i < a.count; ++i) axis[i] = a.angle_deg(i);
    g.axes.push_back(std::move(axis));
  }
  g.values = std::move(values);
  std::string joints;
  for (const MapAxis& a : grid.axes)
    joints += (joints.empty() ? "" : ", ") + names[static_cast<size_t>(a.joint)];
  if (grid.axes.size() == 1) {
    plot::Figure fig;
    fig.name = "map";
    plot::Panel p;
    const size_t imax =
        static_cast<size_t>(std::max_element(g.values.begin(), g.values.end()) - g.values.begin());
    p.title = str("M_ie over ", joints, ": maximum ", g.values[imax], " kg at ", g.axes[0][imax], " deg");
    p.xlabel = g.axis_labels[0];
    p.ylabel = g.value_label;
    plot::Curve c;
    c.label = "M_ie";
    c.x = g.axes[0];
    c.y = g.values;
    plot::Curve m;
    m.label = "maximum";
    m.symbol = "▲";
    m.color = 1;
    m.line_style = 0;
    m.x = {g.axes[0][imax]};
    m.y = {g.values[imax]};
    p.curves = {c, m};
    fig.panels.emplace_back(std::move(p));
    return {fig};
  }
  if (grid.axes.size() == 2) return {figures::map_heat(g, "map", "")};
  return {figures::map_slices(g, slice_deg, "map_slices", ""),
          figures::map_cloud(g, "map_cloud", "M_ie over " + joints + " (Figure 8)")};
}

/// The pictures' arguments, checked before the grid is evaluated; returns the slices (deg).
std::vector<double> check_map_plot(const MapOptions& o, const MapPlan& plan) {
  const MapGrid& grid = plan.grid;
  std::vector<double> slice_deg(grid.axes.size(), 0.0);
  if (!o.slice_deg.empty()) {
    slice_deg = parse_list(o.slice_deg, "--slice-deg", {grid.axes.size()});
    if (grid.axes.size() != 3) throw InputError("--slice-deg: slices are drawn for three varied joints only");
  }
  if (o.out.plot.empty()) return slice_deg;
  plot::require_available("--plot");
  plot::check_folder(o.out.plot, "--plot");
  if (grid.axes.size() > 3)
    throw InputError(str("--plot: pictures are drawn for 1 to 3 varied joints, got ", grid.axes.size(),
                         " (the CSV holds every point)"));
  if (plan.shard_n > 1)
    throw InputError(
        "--plot: a shard holds part of the grid only; run the whole grid (--shard 0/1) to plot it");
  if (grid.size > kMaxPlotPoints)
    throw InputError(str("--plot: the grid has ", grid.size, " points; pictures are drawn for at most ",
                         kMaxPlotPoints, " (use a coarser --step-deg)"));
  return slice_deg;
}

void print_map_summary(std::ostream& os, const MapOptions& o, const MapRun& r) {
  const MapPlan& p = r.plan;
  const std::uint64_t count = p.count();
  os << "map: " << count << " of " << p.grid.size << " points (shard " << p.shard_k << "/" << p.shard_n << ") in "
     << r.seconds << " s, " << (r.seconds > 0 ? static_cast<double>(count) / r.seconds : 0.0) << " points/s on "
     << p.threads << " thread" << (p.threads > 1 ? "s" : "") << "\n";
  if (r.extremes) {
    const MapExtremes& e = *r.extremes;
    os << "max M_ie = " << e.max_M << " kg at " << point_deg(p.grid, e.argmax) << " deg; min M_ie = " << e.min_M
       << " kg at " << point_deg(p.grid, e.argmin) << " deg\n";
  }
  if (!o.out.csv.empty() && !is_stdout_name(o.out.csv)) os << "wrote " << o.out.csv << "\n";
}

int run_map(const MapOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs;  // the JSON summary; the CSV is streamed (below)
  outputs.add("--json", o.out.json);
  const Scenario subject = load_subject(o.subject);
  const MapPlan plan = plan_map(subject, job_options(o, subject.keys.urdf, subject.model->n()));
  const bool plotting = !o.out.plot.empty();
  const plot::Format plot_format = plot::parse_format(o.out.plot_format, "--plot-format");
  const std::vector<double> slice_deg = check_map_plot(o, plan);
  std::vector<double> values(plotting ? plan.count() : 0);

  // the map; without --csv, the summary (--json, the table) only; checked before any point is evaluated
  StreamingOutput* out = o.out.csv.empty() ? nullptr : &outputs.stream("--csv", o.out.csv);
  if (out && plan.shard_k == 0) {
    const std::string header = map_csv_header(subject, plan);
    out->write(header.data(), header.size());
  }
  const size_t k = plan.grid.axes.size();
  std::vector<RowText> rows(out ? plan.threads : 0);
  for (RowText& t : rows) t.text.resize((k + 2) * 32 * static_cast<size_t>(plan.block) + 1);
  Progress progress("map", o.out.quiet);
  MapSink sink;
  sink.evaluated = [&](unsigned t, const MapBlock& b) {
    if (out) rows[t].format(b, k);
    if (plotting)
      std::copy(b.M_ie, b.M_ie + b.count, values.begin() + static_cast<std::ptrdiff_t>(b.first - plan.first));
  };
  sink.commit = [&](unsigned t, const MapBlock&) {
    if (out) out->write(rows[t].text.data(), rows[t].bytes);
  };
  sink.progress = [&](std::uint64_t done, std::uint64_t total) { progress(done, total); };
  MapRun run = evaluate_map(subject, plan, sink);
  // the pictures, the summary and the CSV are put in place together: a failed one leaves none behind
  std::vector<std::string> drawn;
  const auto t0 = std::chrono::steady_clock::now();
  if (plotting)
    drawn = outputs.stage(plot::draw(map_figures(plan.grid, subject.model->joint_names(), std::move(values), slice_deg),
                                     o.out.plot, plot_format));
  run.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  outputs.set("--json", map_json(subject, run, FFSR_VERSION).dump(2) + "\n");
  outputs.write();
  std::ostream& os = outputs.table();  // standard error when the CSV or the JSON goes to standard output
  print_map_summary(os, o, run);
  for (const std::string& f : drawn) os << "wrote " << f << "\n";
  return 0;
}

}  // namespace map_impl

void register_map(CLI::App& app, Action& action) {
  using namespace map_impl;
  auto o = std::make_shared<MapOptions>();
  CLI::App* sub =
      app.add_subcommand("map", "M_ie (Eq. 14) and closed-form F_max (Eq. 24) over a grid of joint angles");
  // M_ie and F_max do not depend on where the base is, only on its attitude: no --base-position
  o->subject.add_to(*sub, {"contact-joints", "armature"}, {"base-position"});
  sub->add_option("--vary", o->vary,
                  "Joints to vary, 1-based in URDF tree order, e.g. 1,2,3; the others stay at --joints-deg")
      ->required();
  sub->add_option(
         "--range-deg", o->range_deg,
         "Half-open range lo,hi of every varied joint, or lo1,hi1,lo2,hi2,... one pair per varied joint, deg")
      ->capture_default_str();
  sub->add_option("--step-deg", o->step_deg, "Grid step, one for all or one per varied joint, deg")
      ->capture_default_str();
  sub->add_option("--shard", o->shard,
                  "Evaluate the K-th of N contiguous parts of the grid (K/N, 0 <= K < N); only part 0 writes "
                  "the header, "
                  "so the parts concatenated in order are the whole CSV")
      ->capture_default_str();
  sub->add_option("--threads", o->threads, "Worker threads; 0: all cores")
      ->check(CLI::Range(0U, 1024U))
      ->capture_default_str();
  sub->add_option("--max-points", o->max_points, "Refuse grids with more points than this")
      ->capture_default_str();
  add_output_flags(
      *sub, o->out,
      {"Write the map's summary (the grid, the points of this shard, the extremes of M_ie) as JSON to FILE",
       "Write the map (one row per point: varied angles deg, M_ie kg, F_max N) as CSV to FILE",
       "Draw the map: M_ie against one joint, a heat map for two (Figure 9), slices and a 3-D view for "
       "three (Figures 8, 9)"});
  sub->add_option("--slice-deg", o->slice_deg,
                  "Three varied joints: the point the slices go through, one angle per varied joint, deg "
                  "(default 0,0,0)");
  sub->callback([o, &action] { action = [o] { return run_map(*o); }; });
}

}  // namespace ffsr::cli
