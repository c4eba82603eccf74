// ffsr-optimize map: the integrated effective mass M_ie (Eq. 14) and the closed-form maximum contact
// force F_max (Eq. 24) over a grid of joint angles (the paper's Figures 8 and 9), the joints not
// varied held at --joints-deg.
//
// The grid. Varied joint j (1-based, URDF tree order) takes the angles lo_j + i step_j, i = 0, 1, ...,
// below hi_j: the half-open range [lo_j, hi_j), so that -180,180 in steps of 2 gives 180 angles and
// no angle twice. Points are numbered row-major: the last varied joint changes fastest; the CSV has
// one row per point in that order.
//
// Shards. --shard K/N evaluates the K-th of N contiguous parts of that numbering (part k holds
// points [k P/N, (k+1) P/N) up to rounding: the first P mod N parts hold one point more). Only shard
// 0 writes the header line, so `cat` of the N shard files in the order k = 0..N-1 is, byte for byte,
// the CSV of the whole grid.
//
// Speed. Each thread has its own Data and buffers (no heap allocation per point); blocks of points
// are claimed in order, formatted with std::to_chars (the shortest text that reads back as the same
// double) and appended to the output in order, so the output never has to fit in memory. The file
// is written like every output of the command (StreamingOutput: a temporary next to the
// destination, renamed at the end: all or nothing).
//
// Pictures (--plot DIR): one varied joint gives M_ie against the angle; two a heat map with contour
// lines and a colour bar (Figure 9); three the orthogonal slices through --slice-deg (Figure 9's
// theta_i = 0 slices) and the grid as coloured points in 3-D (Figure 8). The values are kept in memory
// for that (8 bytes a point), so a plotted grid is limited to kMaxPlotPoints; a shard holds part of
// the grid only and is not plotted.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/scenario_run.hpp"

#include "ffsr/detail/parallel.hpp"
#include "ffsr/optimize/objective.hpp"

#include <charconv>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <thread>

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
  OutputKeys out;  ///< --csv (required: the map), --json (its summary), --plot, --quiet
};

/// One varied joint: angles lo + i step (degrees), i = 0..count-1.
struct Axis {
  int joint = 0;  // 0-based joint index
  double lo = 0, step = 0;
  std::uint64_t count = 0;
  double angle_deg(std::uint64_t i) const { return lo + static_cast<double>(i) * step; }
};

struct Grid {
  std::vector<Axis> axes;
  std::uint64_t size = 0;
};

/// Parses --vary, --range-deg, --step-deg and checks the size against --max-points.
Grid parse_grid(const MapOptions& o, const std::string& urdf, int n_joints) {
  const auto joints = parse_list(o.vary, "--vary");
  Grid g;
  for (double j : joints) {
    if (j != std::floor(j) || j < 1 || j > n_joints)
      throw InputError(str("--vary: joint ", j, " is not one of 1..", n_joints, " (the robot in ", urdf,
                           " has ", n_joints, " joints, numbered from 1 in URDF tree order)"));
    for (const Axis& a : g.axes)
      if (a.joint == static_cast<int>(j) - 1) throw InputError(str("--vary: joint ", j, " is given twice"));
    g.axes.push_back({static_cast<int>(j) - 1, 0, 0, 0});
  }
  const size_t k = g.axes.size();
  const auto range =
      parse_list(o.range_deg, "--range-deg", k == 1 ? std::vector<size_t>{2} : std::vector<size_t>{2, 2 * k});
  const auto step =
      parse_list(o.step_deg, "--step-deg", k == 1 ? std::vector<size_t>{1} : std::vector<size_t>{1, k});
  double total = 1.0;
  for (size_t i = 0; i < k; ++i) {
    Axis& a = g.axes[i];
    const double lo = range.size() == 2 ? range[0] : range[2 * i],
                 hi = range.size() == 2 ? range[1] : range[2 * i + 1];
    a.step = step.size() == 1 ? step[0] : step[i];
    if (!(a.step > 0)) throw InputError(str("--step-deg: the step must be positive, got ", a.step));
    if (!(lo < hi))
      throw InputError(str("--range-deg: the range of joint ", a.joint + 1, " is ",
                           lo == hi ? "empty" : "inverted", " (from ", lo, " to ", hi,
                           "; expected lo < hi)"));
    a.lo = lo;
    const double r = (hi - lo) / a.step;
    if (!(r < 9.0e15))
      throw InputError(str("--step-deg: the step ", a.step, " is too small for the range ", lo, ",", hi));
    a.count = static_cast<std::uint64_t>(std::ceil(r - 1e-9));  // half-open [lo, hi), tolerant of rounding
    if (a.count == 0) a.count = 1;
    total *= static_cast<double>(a.count);
  }
  if (total > static_cast<double>(o.max_points))
    throw InputError(str("--max-points: the grid has ", total, " points, more than the limit ", o.max_points,
                         "; pass a larger --max-points to run it"));
  g.size = 1;
  for (const Axis& a : g.axes) g.size *= a.count;
  return g;
}

/// The first point of part j of N of a grid of `size` points (the first size mod N parts hold one
/// point more).
std::uint64_t shard_begin(const Shard& s, std::uint64_t size, std::uint64_t j) {
  return j * (size / s.n) + std::min(j, size % s.n);
}

/// Appends the shortest round-trip text of x and a separator.
inline char* put(char* p, char* end, double x, char sep) {
  const auto r = std::to_chars(p, end, x);
  *r.ptr = sep;
  return r.ptr + 1;
}

/// What one thread needs: its own Data and joint vector; evaluates a block of points.
struct Worker {
  const Model& model;
  const Grid& grid;
  const CaptureEvaluator& objective;  ///< M_ie of the joint model (free: the fast path) and F_max
  const BasePose base;
  Data data;
  Eigen::VectorXd theta;
  std::vector<char> text;
  std::vector<double> angles;
  double* values = nullptr;  // M_ie by point index - first_point, when the grid is plotted
  std::uint64_t first_point = 0;
  // the largest and smallest M_ie seen, and where (smallest point index on ties)
  double max_M = -1, min_M = std::numeric_limits<double>::infinity();
  std::uint64_t argmax = 0, argmin = 0;

  Worker(const Model& m, const Grid& g, const CaptureEvaluator& f, const Robot& r, size_t block)
      : model(m),
        grid(g),
        objective(f),
        base(r.base),
        data(m),
        theta(r.theta),
        text((g.axes.size() + 2) * 32 * block + 1),
        angles(g.axes.size()) {}

  /// Evaluates points [first, last) and formats their rows into `text`; returns the byte count.
  size_t run(std::uint64_t first, std::uint64_t last) {
    char* p = text.data();
    char* const end = text.data() + text.size();
    const size_t k = grid.axes.size();
    for (std::uint64_t idx = first; idx < last; ++idx) {
      std::uint64_t rest = idx;
      for (size_t a = k; a-- > 0;) {
        const Axis& ax = grid.axes[a];
        angles[a] = ax.angle_deg(rest % ax.count);
        rest /= ax.count;
        theta(ax.joint) = angles[a] * (M_PI / 180.0);  // as load_robot converts --joints-deg
      }
      const double M = objective.mass_fast(data, base, theta);  // Eq. 14
      const double F = objective.f_max_closed_form(M);          // Eq. 24
      if (values) values[idx - first_point] = M;
      if (M > max_M) max_M = M, argmax = idx;
      if (M < min_M) min_M = M, argmin = idx;
      for (size_t a = 0; a < k; ++a) p = put(p, end, angles[a], ',');
      p = put(p, end, M, ',');
      p = put(p, end, F, '\n');
    }
    return static_cast<size_t>(p - text.data());
  }
};

/// The angles of point `idx`, deg, one per varied joint.
std::vector<double> point_angles(const Grid& g, std::uint64_t idx) {
  std::vector<double> a(g.axes.size());
  for (size_t i = g.axes.size(); i-- > 0;) {
    a[i] = g.axes[i].angle_deg(idx % g.axes[i].count);
    idx /= g.axes[i].count;
  }
  return a;
}

std::string point_deg(const Grid& g, std::uint64_t idx) {
  const std::vector<double> a = point_angles(g, idx);
  std::ostringstream os;
  os << "[";
  for (size_t i = 0; i < a.size(); ++i) os << (i ? ", " : "") << a[i];
  os << "]";
  return os.str();
}

constexpr std::uint64_t kMaxPlotPoints = 50000000;

/// The figures of a plotted grid (see the top of this file).
std::vector<plot::Figure> map_figures(const Grid& grid, const std::vector<std::string>& names,
                                      std::vector<double> values, const std::vector<double>& slice_deg) {
  figures::Grid g;
  for (const Axis& a : grid.axes) {
    g.axis_labels.push_back(str("θ", a.joint + 1, " (deg)"));
    std::vector<double> axis(a.count);
    for (std::uint64_t i = 0; i < a.count; ++i) axis[i] = a.angle_deg(i);
    g.axes.push_back(std::move(axis));
  }
  g.values = std::move(values);
  std::string joints;
  for (const Axis& a : grid.axes)
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

/// The contact law at the approach velocity of the flags (Eq. 10-12); InputError when the end-effector
/// does not approach the target or the law is unknown.
AnyContactLaw map_law(const Subject& s) {
  const Target& target = s.target;
  if (s.law == "all") throw InputError("--model: map evaluates one law; 'all' is for the contact subcommand");
  const Vector3 u = target.normal_world();
  const double v_in = approach_velocity(u, Vector3(s.approach_speed * u), target.velocity,
                                        target.angular_velocity_world(), target.offset_world());  // Eq. 10-12
  if (!(v_in > 0))
    throw InputError(str("--approach-speed: the end-effector does not approach the target (delta_dot^- = ",
                         v_in, " m/s); increase the approach speed"));
  try {
    return make_contact_law(s.law, s.params, v_in);
  } catch (const InputError& e) {
    throw InputError(std::string("--model: ") + e.what());
  }
}

/// The pictures' arguments, checked before the grid is evaluated; returns the slices (deg).
std::vector<double> check_map_plot(const MapOptions& o, const Grid& grid, const Shard& shard) {
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
  if (shard.n > 1)
    throw InputError(
        "--plot: a shard holds part of the grid only; run the whole grid (--shard 0/1) to plot it");
  if (grid.size > kMaxPlotPoints)
    throw InputError(str("--plot: the grid has ", grid.size, " points; pictures are drawn for at most ",
                         kMaxPlotPoints, " (use a coarser --step-deg)"));
  return slice_deg;
}

/// The per-thread workers of a grid run (detail::parallel_chunks hands each thread its own).
struct GridRun {
  std::vector<std::unique_ptr<Worker>> workers;
  unsigned threads = 1;
};

/// The points [first, last) of the grid in blocks of `block` points on the shared thread pool
/// (ffsr/detail/parallel.hpp): each block is formatted by a worker and written to `out` once all
/// blocks before it are, so the CSV does not depend on the thread count.
void run_workers(GridRun& g, StreamingOutput& out, std::uint64_t first, std::uint64_t last,
                 std::uint64_t block, bool quiet) {
  Progress progress("map", quiet);
  std::vector<size_t> bytes(g.threads, 0);
  ffsr::detail::ParallelOptions opt;
  opt.chunk = block;
  opt.commit = [&](unsigned t, std::uint64_t, std::uint64_t) {
    out.write(g.workers[t]->text.data(), bytes[t]);
  };
  opt.progress = [&](std::uint64_t done) { progress(done, last - first); };
  opt.progress_every = std::chrono::milliseconds(200);
  ffsr::detail::parallel_chunks(
      last - first, g.threads,
      [&](unsigned t, std::uint64_t lo, std::uint64_t hi) {
        bytes[t] = g.workers[t]->run(first + lo, first + hi);
      },
      opt);
}

/// The largest and the smallest M_ie of the evaluated points (the first point of a tie).
struct Extremes {
  double max_M = 0, min_M = 0;
  std::uint64_t argmax = 0, argmin = 0;
};

Extremes extremes(const GridRun& g) {
  const Worker* hi = g.workers[0].get();
  const Worker* lo = g.workers[0].get();
  for (const auto& w : g.workers) {
    if (w->max_M > hi->max_M || (w->max_M == hi->max_M && w->argmax < hi->argmax)) hi = w.get();
    if (w->min_M < lo->min_M || (w->min_M == lo->min_M && w->argmin < lo->argmin)) lo = w.get();
  }
  return {hi->max_M, lo->min_M, hi->argmax, lo->argmin};
}

void print_map_summary(std::ostream& os, const MapOptions& o, const Grid& grid, const Shard& shard,
                       const GridRun& g, std::uint64_t count, double seconds) {
  os << "map: " << count << " of " << grid.size << " points (shard " << shard.k << "/" << shard.n << ") in "
     << seconds << " s, " << (seconds > 0 ? static_cast<double>(count) / seconds : 0.0) << " points/s on "
     << g.threads << " thread" << (g.threads > 1 ? "s" : "") << "\n";
  if (count > 0) {
    const Extremes e = extremes(g);
    os << "max M_ie = " << e.max_M << " kg at " << point_deg(grid, e.argmax) << " deg; min M_ie = " << e.min_M
       << " kg at " << point_deg(grid, e.argmin) << " deg\n";
  }
  if (!is_stdout_name(o.out.csv)) os << "wrote " << o.out.csv << "\n";
}

/// The map's summary: the grid, this shard's points and the extremes of M_ie with their closed-form
/// F_max (the CSV holds every point).
nlohmann::json map_json(const Subject& subject, const Grid& grid, const Shard& shard, const GridRun& g,
                        std::uint64_t first, std::uint64_t count, JointModel joints, const AnyContactLaw& law) {
  const auto names = subject.robot.model.joint_names();
  nlohmann::json axes = nlohmann::json::array();
  for (const Axis& a : grid.axes)
    axes.push_back({{"joint", names[static_cast<size_t>(a.joint)]},
                    {"from_deg", a.lo},
                    {"step_deg", a.step},
                    {"count", a.count}});
  nlohmann::json j = {{"urdf", subject.keys.urdf},
                      {"joints_deg", subject.keys.joints_deg},
                      {"contact_joints", joint_model_name(joints)},
                      {"axes", axes},
                      {"points", grid.size},
                      {"shard", {{"k", shard.k}, {"n", shard.n}, {"first", first}, {"end", first + count}}},
                      {"version", FFSR_VERSION}};
  if (count > 0) {
    const Extremes e = extremes(g);
    // F_max (Eq. 24) grows with M_ie: its extremes are at the same points
    j["max"] = {{"integrated_effective_mass", e.max_M},
                {"f_max_closed_form", max_force_closed_form(law, e.max_M)},
                {"angles_deg", point_angles(grid, e.argmax)}};
    j["min"] = {{"integrated_effective_mass", e.min_M},
                {"f_max_closed_form", max_force_closed_form(law, e.min_M)},
                {"angles_deg", point_angles(grid, e.argmin)}};
  }
  return j;
}

int run_map(const MapOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs;  // the JSON summary; the CSV is streamed (below)
  outputs.add("--json", o.out.json);
  if (is_stdout_name(o.out.csv)) outputs.claim_stdout("--csv " + o.out.csv);
  const Subject subject = load_subject(o.subject);
  const Robot& r = subject.robot;
  const Target& target = subject.target;
  const AnyContactLaw law = map_law(subject);
  const Grid grid = parse_grid(o, subject.keys.urdf, r.model.n());
  const Shard shard = parse_shard(o.shard);
  const std::uint64_t first = shard_begin(shard, grid.size, shard.k),
                      last = shard_begin(shard, grid.size, shard.k + 1);
  const std::uint64_t count = last - first;
  const bool plotting = !o.out.plot.empty();
  const plot::Format plot_format = plot::parse_format(o.out.plot_format, "--plot-format");
  const std::vector<double> slice_deg = check_map_plot(o, grid, shard);
  std::vector<double> values(plotting ? count : 0);

  if (subject.all_joint_models())
    throw InputError("--contact-joints: map evaluates one joint model; 'all' is for the contact subcommand");
  const ContactJoints joints = subject.contact_joints();  // checked before any output
  StreamingOutput out("--csv", o.out.csv);
  if (shard.k == 0) {
    std::string header;
    const auto names = r.model.joint_names();
    for (const Axis& a : grid.axes) header += names[static_cast<size_t>(a.joint)] + "_deg,";
    const JointModel jm = joints.model;
    header +=
        jm == JointModel::Free ? "M_ie_kg,F_max_N\n" : str("M_ie_", joint_model_name(jm), "_kg,F_max_N\n");
    out.write(header.data(), header.size());
  }
  constexpr std::uint64_t kBlock = 2048;
  const std::uint64_t blocks = (count + kBlock - 1) / kBlock;
  GridRun g;
  g.threads = o.threads ? o.threads : std::max(1U, std::thread::hardware_concurrency());
  g.threads = static_cast<unsigned>(std::max<std::uint64_t>(1, std::min<std::uint64_t>(g.threads, blocks)));
  const CaptureEvaluator objective(r.model, r.end_effector, target, &law, joints);
  for (unsigned t = 0; t < g.threads; ++t) {
    g.workers.push_back(std::make_unique<Worker>(r.model, grid, objective, r, kBlock));
    g.workers.back()->values = plotting ? values.data() : nullptr;
    g.workers.back()->first_point = first;
  }
  const auto t0 = std::chrono::steady_clock::now();
  run_workers(g, out, first, last, kBlock, o.out.quiet);
  // the pictures before the CSV is committed: a failed drawing leaves no CSV behind
  std::vector<std::string> drawn;
  if (plotting)
    drawn = plot::render(map_figures(grid, r.model.joint_names(), std::move(values), slice_deg), o.out.plot,
                         plot_format);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  outputs.set("--json", map_json(subject, grid, shard, g, first, count, joints.model, law).dump(2) + "\n");
  outputs.write();  // the summary first: a failed JSON leaves no CSV behind
  out.commit();
  std::ostream& os = outputs.table();  // standard error when the CSV or the JSON goes to standard output
  print_map_summary(os, o, grid, shard, g, count, seconds);
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
  sub->get_option("--csv")->required();
  sub->add_option("--slice-deg", o->slice_deg,
                  "Three varied joints: the point the slices go through, one angle per varied joint, deg "
                  "(default 0,0,0)");
  sub->callback([o, &action] { action = [o] { return run_map(*o); }; });
}

}  // namespace ffsr::cli
