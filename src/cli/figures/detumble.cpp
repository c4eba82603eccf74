// src/cli/figures/detumble.cpp -- the figure of `detumble`: the post-capture run against time (joint
// rates, the rest test, joint torques and limits, gripper load, base attitude, wheels or energy).
#include "figures/figure_tools.hpp"
#include "figures/figures.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

namespace ffsr::cli::figures {

using namespace tools;  // str, Curve, Panel, fixed, labelled, kBlack

namespace {

constexpr double kDeg = 180.0 / M_PI;

/// One quantity of a run against time, drawn in a panel shared by every run.
struct Quantity {
  std::string name;
  std::vector<double> y;
};

/// Draws each run's quantities: with one run, a colour per quantity and its name in the legend; with
/// several, a colour per run and a line style per quantity, the legend's keys as curves without points
/// (the runs in their colours, the quantities' styles in black).
void add_runs(Panel& p, const DetumbleSeries& s, const std::vector<std::vector<Quantity>>& per_run) {
  const bool one = s.runs.size() == 1;
  for (size_t r = 0; r < s.runs.size(); ++r)
    for (size_t q = 0; q < per_run[r].size(); ++q) {
      Curve c;
      c.x = s.runs[r].t;
      c.y = per_run[r][q].y;
      c.color = one ? static_cast<int>(q) : s.runs[r].color;
      c.line_style = one ? 1 : static_cast<int>(q % 8) + 1;
      c.width = 1.6;
      if (one && per_run[r].size() > 1) c.label = per_run[r][q].name;
      p.curves.push_back(std::move(c));
    }
  if (one) return;
  for (const auto& run : s.runs) {
    Curve key;
    key.label = run.label;
    key.color = run.color;
    p.curves.push_back(std::move(key));
  }
  if (per_run.front().size() > 1)
    for (size_t q = 0; q < per_run.front().size(); ++q) {
      Curve key;
      key.label = per_run.front()[q].name;
      key.color = kBlack;
      key.line_style = static_cast<int>(q % 8) + 1;
      p.curves.push_back(std::move(key));
    }
}

/// A horizontal line at y over the runs' time span.
Curve level(double y, double t0, double t1, std::string label, int style = 2) {
  Curve l;
  l.label = std::move(label);
  l.color = kBlack;
  l.line_style = style;
  l.width = 1.0;
  l.x = {t0, t1};
  l.y = {y, y};
  return l;
}

/// The joints' colours: the palette without its black (the runs' line-style keys are drawn in black)
/// and with the two blues far apart in the order (joint 1 blue, joint 7 sky blue).
constexpr std::array<int, 7> kJointColours{0, 1, 2, 3, 4, 7, 5};

/// Joint k of every run (colour by joint, line style by run), value scaled.
void add_joints(Panel& p, const DetumbleSeries& s, bool rates, bool labels) {
  const size_t n = s.joint_names.size();
  for (size_t j = 0; j < n; ++j)
    for (size_t r = 0; r < s.runs.size(); ++r) {
      const auto& run = s.runs[r];
      Curve c;
      c.color = kJointColours[j % kJointColours.size()];
      c.line_style = static_cast<int>(r % 8) + 1;
      c.width = 1.5;
      c.x = run.t;
      const auto& v = rates ? run.rate : run.torque;
      for (const auto& x : v) c.y.push_back(x(static_cast<Eigen::Index>(j)) * (rates ? kDeg : 1.0));
      if (labels && r == 0) c.label = s.joint_names[j];
      p.curves.push_back(std::move(c));
    }
  if (!labels || s.runs.size() < 2) return;
  for (size_t r = 0; r < s.runs.size(); ++r) {  // the runs' line styles, in black
    Curve key;
    key.label = s.runs[r].label;
    key.color = kBlack;
    key.line_style = static_cast<int>(r % 8) + 1;
    p.curves.push_back(std::move(key));
  }
}

/// The torque limits a joint comes near (above 30 %), one pair of lines per value with its joints; with
/// none, the title says so.
void add_limits(Panel& p, const DetumbleSeries& s, double t0, double t1) {
  std::map<double, std::string> near;  // limit -> "1, 2, 3"
  for (size_t j = 0; j < s.torque_limit.size(); ++j) {
    double peak = 0;
    for (const auto& run : s.runs)
      for (const auto& x : run.torque) peak = std::max(peak, std::abs(x(static_cast<Eigen::Index>(j))));
    if (peak > 0.3 * s.torque_limit[j]) {
      std::string& joints = near[s.torque_limit[j]];
      joints += (joints.empty() ? "" : ", ") + std::to_string(j + 1);
    }
  }
  if (near.empty()) p.title = "joint torques (below 30 % of the limits)";
  int style = 2;
  for (const auto& [limit, joints] : near) {
    p.curves.push_back(level(limit, t0, t1, str("limit ±", limit, " N m (joint ", joints, ")"), style));
    p.curves.push_back(level(-limit, t0, t1, "", style));
    style = style % 8 + 1;
  }
}

void check(const DetumbleSeries& s) {
  if (s.runs.empty()) throw InputError("detumble plot: no run");
  const size_t n = s.joint_names.size();
  if (s.torque_limit.size() != n)
    throw InputError(str("detumble plot: ", s.torque_limit.size(), " torque limits for ", n, " joints"));
  for (const auto& r : s.runs) {
    const size_t m = r.t.size();
    const bool equal = r.joint_rate.size() == m && r.relative_rate.size() == m && r.stack_rate.size() == m &&
                       r.force.size() == m && r.moment.size() == m && r.attitude.size() == m &&
                       r.energy.size() == m && r.rate.size() == m && r.torque.size() == m &&
                       r.wheel.size() == m;
    if (m == 0 || !equal)
      throw InputError(str("detumble plot: the series of run '", r.label, "' have different lengths"));
    for (size_t i = 0; i < m; ++i)
      if (static_cast<size_t>(r.rate[i].size()) != n || static_cast<size_t>(r.torque[i].size()) != n)
        throw InputError(str("detumble plot: run '", r.label, "' has another number of joints than ", n));
  }
}

}  // namespace

plot::Figure detumble(const DetumbleSeries& s) {
  check(s);
  double t0 = s.runs.front().t.front(), t1 = t0;
  for (const auto& r : s.runs) {
    t0 = std::min(t0, r.t.front());
    t1 = std::max(t1, r.t.back());
  }
  plot::Figure fig;
  fig.name = "detumble";
  fig.title = s.title;
  fig.rows = 3;
  fig.cols = 2;
  fig.width = 1200;
  fig.height = s.runs.size() > 1 ? 1250 : 1100;  // room for the joints' and the runs' legend
  const std::string time;  // the rows share the time axis: named under the last row only (below)
  Panel rates = labelled(s.runs.size() > 1 ? "joint rates (runs by line style)" : "joint rates", time,
                         "joint rate (deg/s)"),
        rest = labelled(str("rest test: at rest below ", fixed(s.rest_rate * kDeg, 3), " deg/s"), time,
                        "rate (deg/s)"),
        torque = labelled("joint torques (colours as above)", time, "torque (N m)"),
        load = labelled("gripper's load on the target", time, "force (N), moment (N m)"),
        attitude = labelled("base rotation since the grasp", time, "rotation (deg)"),
        last = s.wheel_bound > 0 ? labelled(str("wheels' momentum (bound ", s.wheel_bound, " N m s)"), time,
                                            "|h| per base axis (N m s)")
                                 : labelled("kinetic energy of robot and target", time, "energy (J)");
  add_joints(rates, s, true, true);
  // the legend inside, at the corner the curves leave freest (the rates fall to zero and stay there): an
  // outside legend took a third of the panel's width
  add_joints(torque, s, false, false);
  add_limits(torque, s, t0, t1);
  std::vector<std::vector<Quantity>> rest_q, load_q, attitude_q, last_q;
  for (const auto& r : s.runs) {
    auto deg = [](std::vector<double> v) {
      for (double& x : v) x *= kDeg;
      return v;
    };
    rest_q.push_back(
        {{"largest joint rate", deg(r.joint_rate)}, {"gripper relative to the base", deg(r.relative_rate)}});
    if (s.stack_rate) rest_q.back().push_back({"stack", deg(r.stack_rate)});
    load_q.push_back({{"force (N)", r.force}, {"moment (N m)", r.moment}});
    attitude_q.push_back({{"rotation", deg(r.attitude)}});
    if (s.wheel_bound > 0) {
      std::vector<Quantity> axes{{"x", {}}, {"y", {}}, {"z", {}}};
      for (const auto& h : r.wheel)
        for (int a = 0; a < 3; ++a) axes[static_cast<size_t>(a)].y.push_back(std::abs(h(a)));
      last_q.push_back(std::move(axes));
    } else {
      last_q.push_back({{"energy", r.energy}});
    }
  }
  add_runs(rest, s, rest_q);
  rest.curves.push_back(level(s.rest_rate * kDeg, t0, t1, "rest threshold", 4));  // styles 1-3: quantities
  add_runs(load, s, load_q);
  add_runs(attitude, s, attitude_q);
  add_runs(last, s, last_q);
  if (s.wheel_bound > 0) last.curves.push_back(level(s.wheel_bound, t0, t1, "bound", 4));
  attitude.xlabel = last.xlabel = "time since the grasp (s)";
  fig.panels = {rates, rest, torque, load, attitude, last};
  return fig;
}

}  // namespace ffsr::cli::figures
