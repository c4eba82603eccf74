// ffsr/jobs/map.hpp -- the job `map`: the integrated effective mass M_ie (Eq. 14) under the scenario's
// joint model and the closed-form maximum contact force F_max (Eq. 24) over a grid of joint angles
// (the paper's Figures 8 and 9), the joints not varied held at the scenario's start configuration; and the
// run's summary as JSON (the keys and values of `ffsr-optimize map --json`). Component
// ffsr::scenario. Never prints.
#pragma once

#include "ffsr/detail/parallel.hpp"
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/optimize/objective.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

// The grid. Varied joint j (1-based, URDF tree order) takes the angles lo_j + i step_j, i = 0, 1, ...,
// below hi_j: the half-open range [lo_j, hi_j), so that -180,180 in steps of 2 gives 180 angles and
// no angle twice. Points are numbered row-major: the last varied joint changes fastest.
//
// Shards. Shard K of N evaluates the K-th of N contiguous parts of that numbering (part k holds points
// [k P/N, (k+1) P/N) up to rounding: the first P mod N parts hold one point more).
//
// The points go to a sink in blocks (MapSink): each block is handed to `evaluated` on the thread that
// computed it (the command formats its CSV rows there, in parallel) and then to `commit` in point
// order, one block at a time (the command appends the rows to its file: the output does not depend
// on the thread count and never has to fit in memory). Each thread has its own Data and buffers: no
// heap allocation per point.

namespace ffsr {

/// One varied joint: angles lo + i step (degrees), i = 0..count-1.
struct MapAxis {
  int joint = 0;  ///< 0-based joint index
  double lo = 0, step = 0;
  std::uint64_t count = 0;
  double angle_deg(std::uint64_t i) const { return lo + static_cast<double>(i) * step; }
};

/// The grid: its axes, the first varied joint slowest.
struct MapGrid {
  std::vector<MapAxis> axes;
  std::uint64_t size = 0;  ///< the number of points
  /// The angles of point `index`, deg, one per varied joint.
  std::vector<double> point_angles(std::uint64_t index) const;
};

struct MapJobOptions {
  std::vector<int> vary;                      ///< the varied joints, 1-based in URDF tree order
  std::vector<double> range_deg{-180, 180};   ///< lo,hi of every varied joint, or one pair per joint, deg
  std::vector<double> step_deg{2};            ///< one step for all, or one per varied joint, deg
  std::uint64_t shard_k = 0, shard_n = 1;     ///< evaluate part K of N of the points
  unsigned threads = 0;                       ///< 0: one per core
  std::uint64_t max_points = 1000000000ULL;   ///< refuse larger grids
  std::uint64_t block = 2048;                 ///< points per block handed to the sink
};

/// What a map evaluates, checked before any point is: the grid, the law, the joint model, the shard's
/// points [first, end) and the threads.
struct MapPlan {
  explicit MapPlan(AnyContactLaw contact_law) : law(std::move(contact_law)) {}
  AnyContactLaw law;  ///< at the scenario's approach velocity
  MapGrid grid;
  ContactJoints joints;
  std::uint64_t first = 0, end = 0;
  std::uint64_t shard_k = 0, shard_n = 1;
  unsigned threads = 1;
  std::uint64_t block = 2048;
  std::uint64_t count() const { return end - first; }
};

/// Points [first, first + count) of the grid: per point its varied angles (deg, row-major, one row of
/// grid.axes.size() per point), M_ie (kg) and F_max (N). Valid during the sink's call only.
struct MapBlock {
  std::uint64_t first = 0, count = 0;
  const double* angles_deg = nullptr;
  const double* M_ie = nullptr;
  const double* f_max = nullptr;
};

/// Where the points go (see the notes after the includes). Any member may be empty.
struct MapSink {
  /// on the thread `thread` (0 .. plan.threads-1) that computed the block, blocks in any order
  std::function<void(unsigned thread, const MapBlock&)> evaluated;
  /// in point order, one block at a time, on the thread that computed it
  std::function<void(unsigned thread, const MapBlock&)> commit;
  /// on the calling thread: points done of the shard's count
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

/// The largest and the smallest M_ie of the evaluated points, and where (the first point of a tie).
struct MapExtremes {
  double max_M = 0, min_M = 0;
  std::uint64_t argmax = 0, argmin = 0;
};

struct MapRun {
  MapPlan plan;
  std::optional<MapExtremes> extremes;  ///< unless the shard is empty
  double seconds = 0;                   ///< wall-clock time of the evaluation
};

/// The grid of `o` for a robot of `n_joints` joints read from `urdf` (named in the messages).
/// InputError naming --vary, --range-deg, --step-deg or --max-points.
MapGrid map_grid(const MapJobOptions& o, const std::string& urdf, int n_joints);

/// The contact law at the scenario's approach velocity (Eq. 10-12). InputError naming --model ('all'
/// or an unknown law) or --approach-speed (the end-effector does not approach the target).
AnyContactLaw map_law(const Scenario& s);

/// Everything checked, nothing evaluated. InputError naming the flag.
MapPlan plan_map(const Scenario& s, const MapJobOptions& o);

/// Evaluates the plan's points into `sink`. Exceptions of the sink or of a point propagate.
MapRun evaluate_map(const Scenario& s, const MapPlan& plan, const MapSink& sink);

/// The summary of a run: the grid, the shard's points and the extremes of M_ie with their F_max.
nlohmann::json map_json(const Scenario& s, const MapRun& r, const std::string& version);

/// The CSV's header line (with its newline): one column per varied joint, then M_ie and F_max.
std::string map_csv_header(const Scenario& s, const MapPlan& plan);

// ---------------------------------------------------------------------------------------------------

inline std::vector<double> MapGrid::point_angles(std::uint64_t index) const {
  std::vector<double> a(axes.size());
  for (size_t i = axes.size(); i-- > 0;) {
    a[i] = axes[i].angle_deg(index % axes[i].count);
    index /= axes[i].count;
  }
  return a;
}

namespace detail {

/// `values` has one of the sizes `counts` (InputError naming `flag` otherwise).
inline void map_list_size(const std::vector<double>& values, const char* flag, std::vector<size_t> counts) {
  std::string expected;
  for (size_t c : counts) {
    if (values.size() == c) return;
    expected += (expected.empty() ? "" : " or ") + std::to_string(c);
  }
  throw InputError(str(flag, ": expected ", expected, " numbers, got ", values.size()));
}

/// What one thread needs: its own Data, joint vector and block buffers, and its extremes of M_ie.
struct MapWorker {
  Data data;
  Eigen::VectorXd theta;
  std::vector<double> angles, M, F;
  double max_M = -1, min_M = std::numeric_limits<double>::infinity();
  std::uint64_t argmax = 0, argmin = 0;
  MapBlock block;

  MapWorker(const Scenario& s, size_t axes, size_t block_points)
      : data(*s.model), theta(s.problem.theta), angles(axes * block_points), M(block_points), F(block_points) {}

  /// Evaluates points [first, last) into the buffers.
  void run(const MapGrid& grid, const CaptureEvaluator& objective, const BasePose& base, std::uint64_t first,
           std::uint64_t last) {
    const size_t k = grid.axes.size();
    for (std::uint64_t idx = first; idx < last; ++idx) {
      const size_t row = static_cast<size_t>(idx - first);
      std::uint64_t rest = idx;
      for (size_t a = k; a-- > 0;) {
        const MapAxis& ax = grid.axes[a];
        const double deg = ax.angle_deg(rest % ax.count);
        angles[row * k + a] = deg;
        rest /= ax.count;
        theta(ax.joint) = deg * (M_PI / 180.0);  // as the scenario converts joints-deg
      }
      const double m = objective.mass_fast(data, base, theta);  // Eq. 14
      M[row] = m;
      F[row] = objective.f_max_closed_form(m);  // Eq. 24
      if (m > max_M) max_M = m, argmax = idx;
      if (m < min_M) min_M = m, argmin = idx;
    }
    block = {first, last - first, angles.data(), M.data(), F.data()};
  }
};

}  // namespace detail

namespace detail {

/// The axes of --vary (joints 1-based, each once), their ranges and steps not yet set.
inline std::vector<MapAxis> map_axes(const std::vector<int>& vary, const std::string& urdf, int n_joints) {
  std::vector<MapAxis> axes;
  if (vary.empty()) throw InputError("--vary: no joint to vary");
  for (int j : vary) {
    if (j < 1 || j > n_joints)
      throw InputError(str("--vary: joint ", j, " is not one of 1..", n_joints, " (the robot in ", urdf, " has ",
                           n_joints, " joints, numbered from 1 in URDF tree order)"));
    for (const MapAxis& a : axes)
      if (a.joint == j - 1) throw InputError(str("--vary: joint ", j, " is given twice"));
    axes.push_back({j - 1, 0, 0, 0});
  }
  return axes;
}

/// Sets axis `a`'s first angle, step and count from the half-open range [lo, hi) and the step.
inline void map_axis_range(MapAxis& a, double lo, double hi, double step) {
  a.step = step;
  if (!std::isfinite(lo) || !std::isfinite(hi))
    throw InputError(str("--range-deg: the range of joint ", a.joint + 1, " is not finite (", lo, ",", hi, ")"));
  if (!(a.step > 0) || !std::isfinite(a.step))
    throw InputError(str("--step-deg: the step must be positive, got ", a.step));
  if (!(lo < hi))
    throw InputError(str("--range-deg: the range of joint ", a.joint + 1, " is ", lo == hi ? "empty" : "inverted",
                         " (from ", lo, " to ", hi, "; expected lo < hi)"));
  a.lo = lo;
  const double r = (hi - lo) / a.step;
  if (!(r < 9.0e15)) throw InputError(str("--step-deg: the step ", a.step, " is too small for the range ", lo, ",", hi));
  a.count = static_cast<std::uint64_t>(std::ceil(r - 1e-9));  // half-open [lo, hi), tolerant of rounding
  if (a.count == 0) a.count = 1;
}

}  // namespace detail

inline MapGrid map_grid(const MapJobOptions& o, const std::string& urdf, int n_joints) {
  using detail::str;
  MapGrid g;
  g.axes = detail::map_axes(o.vary, urdf, n_joints);
  const size_t k = g.axes.size();
  detail::map_list_size(o.range_deg, "--range-deg", k == 1 ? std::vector<size_t>{2} : std::vector<size_t>{2, 2 * k});
  detail::map_list_size(o.step_deg, "--step-deg", k == 1 ? std::vector<size_t>{1} : std::vector<size_t>{1, k});
  const bool one_range = o.range_deg.size() == 2, one_step = o.step_deg.size() == 1;
  double total = 1.0;
  for (size_t i = 0; i < k; ++i) {
    detail::map_axis_range(g.axes[i], o.range_deg[one_range ? 0 : 2 * i], o.range_deg[one_range ? 1 : 2 * i + 1],
                           o.step_deg[one_step ? 0 : i]);
    total *= static_cast<double>(g.axes[i].count);
  }
  if (total > static_cast<double>(o.max_points))
    throw InputError(str("--max-points: the grid has ", total, " points, more than the limit ", o.max_points,
                         "; pass a larger --max-points to run it"));
  g.size = 1;
  for (const MapAxis& a : g.axes) g.size *= a.count;
  return g;
}

inline AnyContactLaw map_law(const Scenario& s) {
  using detail::str;
  const Target& target = s.problem.target;
  if (s.problem.law == "all") throw InputError("--model: map evaluates one law; 'all' is for the contact subcommand");
  const Vector3 u = target.normal_world();
  const double v_in = approach_velocity(u, Vector3(s.problem.approach_speed * u), target.velocity,
                                        target.angular_velocity_world(), target.offset_world());  // Eq. 10-12
  if (!(v_in > 0))
    throw InputError(str("--approach-speed: the end-effector does not approach the target (delta_dot^- = ", v_in,
                         " m/s); increase the approach speed"));
  try {
    return make_contact_law(s.problem.law, s.problem.contact, v_in);
  } catch (const InputError& e) {
    throw InputError(std::string("--model: ") + e.what());
  }
}

inline MapPlan plan_map(const Scenario& s, const MapJobOptions& o) {
  using detail::str;
  MapPlan p(map_law(s));
  p.grid = map_grid(o, s.keys.urdf, s.model->n());
  if (o.shard_n < 1) throw InputError("--shard: N must be at least 1");
  if (o.shard_k >= o.shard_n)
    throw InputError(str("--shard: K must be less than N (K counts from 0), got ", o.shard_k, "/", o.shard_n));
  p.shard_k = o.shard_k;
  p.shard_n = o.shard_n;
  const auto begin = [&](std::uint64_t j) {
    return j * (p.grid.size / o.shard_n) + std::min(j, p.grid.size % o.shard_n);
  };
  p.first = begin(o.shard_k);
  p.end = begin(o.shard_k + 1);
  if (s.all_joint_models())
    throw InputError("--contact-joints: map evaluates one joint model; 'all' is for the contact subcommand");
  p.joints = s.contact_joints();
  if (o.threads > 1024) throw InputError(str("--threads: must be in [0, 1024], got ", o.threads));
  if (o.block < 1) throw InputError("map: the block must hold at least one point");
  p.block = o.block;
  const std::uint64_t blocks = (p.count() + p.block - 1) / p.block;
  const unsigned threads = o.threads ? o.threads : std::max(1U, std::thread::hardware_concurrency());
  p.threads = static_cast<unsigned>(std::max<std::uint64_t>(1, std::min<std::uint64_t>(threads, blocks)));
  return p;
}

inline MapRun evaluate_map(const Scenario& s, const MapPlan& plan, const MapSink& sink) {
  const CaptureEvaluator objective(*s.model, s.problem.frame, s.problem.target, &plan.law, plan.joints);
  std::vector<std::unique_ptr<detail::MapWorker>> workers;
  for (unsigned t = 0; t < plan.threads; ++t)
    workers.push_back(std::make_unique<detail::MapWorker>(s, plan.grid.axes.size(), static_cast<size_t>(plan.block)));
  const auto t0 = std::chrono::steady_clock::now();
  detail::ParallelOptions opt;
  opt.chunk = plan.block;
  opt.commit = [&](unsigned t, std::uint64_t, std::uint64_t) {
    if (sink.commit) sink.commit(t, workers[t]->block);
  };
  if (sink.progress) {
    opt.progress = [&](std::uint64_t done) { sink.progress(done, plan.count()); };
    opt.progress_every = std::chrono::milliseconds(200);
  }
  detail::parallel_chunks(
      plan.count(), plan.threads,
      [&](unsigned t, std::uint64_t lo, std::uint64_t hi) {
        workers[t]->run(plan.grid, objective, s.problem.base, plan.first + lo, plan.first + hi);
        if (sink.evaluated) sink.evaluated(t, workers[t]->block);
      },
      opt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::optional<MapExtremes> extremes;
  if (plan.count() > 0) {
    const detail::MapWorker* hi = workers[0].get();
    const detail::MapWorker* lo = workers[0].get();
    for (const auto& w : workers) {
      if (w->max_M > hi->max_M || (w->max_M == hi->max_M && w->argmax < hi->argmax)) hi = w.get();
      if (w->min_M < lo->min_M || (w->min_M == lo->min_M && w->argmin < lo->argmin)) lo = w.get();
    }
    extremes = MapExtremes{hi->max_M, lo->min_M, hi->argmax, lo->argmin};
  }
  MapRun out{plan, extremes, seconds};
  return out;
}

inline nlohmann::json map_json(const Scenario& s, const MapRun& r, const std::string& version) {
  const MapPlan& p = r.plan;
  const auto names = s.model->joint_names();
  nlohmann::json axes = nlohmann::json::array();
  for (const MapAxis& a : p.grid.axes)
    axes.push_back({{"joint", names[static_cast<size_t>(a.joint)]},
                    {"from_deg", a.lo},
                    {"step_deg", a.step},
                    {"count", a.count}});
  nlohmann::json j = {{"urdf", s.keys.urdf},
                      {"joints_deg", s.keys.joints_deg},
                      {"contact_joints", joint_model_name(p.joints.model)},
                      {"axes", axes},
                      {"points", p.grid.size},
                      {"shard", {{"k", p.shard_k}, {"n", p.shard_n}, {"first", p.first}, {"end", p.end}}},
                      {"version", version}};
  if (r.extremes) {
    const MapExtremes& e = *r.extremes;
    // F_max (Eq. 24) grows with M_ie: its extremes are at the same points
    j["max"] = {{"integrated_effective_mass", e.max_M},
                {"f_max_closed_form", max_force_closed_form(p.law, e.max_M)},
                {"angles_deg", p.grid.point_angles(e.argmax)}};
    j["min"] = {{"integrated_effective_mass", e.min_M},
                {"f_max_closed_form", max_force_closed_form(p.law, e.min_M)},
                {"angles_deg", p.grid.point_angles(e.argmin)}};
  }
  return j;
}

inline std::string map_csv_header(const Scenario& s, const MapPlan& plan) {
  std::string header;
  const auto names = s.model->joint_names();
  for (const MapAxis& a : plan.grid.axes) header += names[static_cast<size_t>(a.joint)] + "_deg,";
  const JointModel jm = plan.joints.model;
  header += jm == JointModel::Free ? "M_ie_kg,F_max_N\n"
                                   : detail::str("M_ie_", joint_model_name(jm), "_kg,F_max_N\n");
  return header;
}

}  // namespace ffsr
