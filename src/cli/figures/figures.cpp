// src/cli/figures/figures.cpp -- the figures of figures.hpp but the capture ones (capture.cpp):
// closed loop, contact, xi, Pareto front, maps and the Monte Carlo of robust (no PLplot here: plain data).
#include "figures/figure_tools.hpp"
#include "figures/figures.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <utility>

namespace ffsr::cli::figures {

using namespace tools;  // str, Curve, Panel, fixed, labelled, kBlack

plot::Figure closed_loop(const ClosedLoopSeries& s) {
  const size_t m = s.t.size();
  if (s.theta.size() != m || s.lag.size() != m || s.torque.size() != m || s.reference_error.size() != m)
    throw InputError("figures::closed_loop: the series have different lengths");
  plot::Figure fig;
  fig.name = "closed_loop";
  fig.title = s.title;
  fig.rows = fig.cols = 2;
  fig.width = 1200;
  fig.height = 900;
  // the tracking error in the unit that keeps its axis numbers plain: mm, or um below 0.1 mm
  double e_max = 0, tau_max = 0;
  for (size_t i = 0; i < m; ++i) {
    e_max = std::max(e_max, s.reference_error[i]);
    tau_max = std::max(tau_max, s.torque[i].cwiseAbs().maxCoeff());
  }
  const bool micro = e_max < 1e-4;
  const bool limit_lines = s.torque_limit > 0 && tau_max > 0.3 * s.torque_limit;
  Panel angles =
            labelled("joint angles: closed loop (solid), plan (dashed)", "time t (s)", "joint angle (deg)"),
        track = labelled("end effector to the reference line", "time t (s)",
                         micro ? "|p#de#u - x#dd#u| (µm)" : "|p#de#u - x#dd#u| (mm)"),
        torque = labelled(limit_lines ? str("joint torques (limit ±", s.torque_limit, " N m: dashed)")
                                      : str("joint torques (limit ±", s.torque_limit, " N m)"),
                          "time t (s)", "torque (N m)"),
        lag = labelled("rate loops' lag: command - joint rate", "time t (s)", "lag (deg/s)");
  const size_t n = s.joint_names.size();
  for (size_t j = 0; j < n; ++j) {
    const auto k = static_cast<Eigen::Index>(j);
    Curve a, q, u, e;
    a.label = s.joint_names[j];
    a.color = q.color = u.color = e.color = static_cast<int>(j % plot::kPaletteSize);
    a.width = q.width = u.width = e.width = 1.6;
    q.line_style = 2;
    for (size_t i = 0; i < m; ++i) {
      a.x.push_back(s.t[i]);
      a.y.push_back(s.theta[i](k) * 180.0 / M_PI);
      u.y.push_back(s.torque[i](k));
      e.y.push_back(s.lag[i](k) * 180.0 / M_PI);
    }
    u.x = e.x = a.x;
    if (s.open_loop)
      for (const CaptureSample& o : s.open_loop->series) {
        q.x.push_back(o.t);
        q.y.push_back(o.theta(k) * 180.0 / M_PI);
      }
    angles.curves.push_back(std::move(a));
    if (!q.x.empty()) angles.curves.push_back(std::move(q));
    torque.curves.push_back(std::move(u));
    lag.curves.push_back(std::move(e));
  }
  Curve d;
  d.color = kBlack;
  d.width = 1.6;
  d.x = s.t;
  for (double x : s.reference_error) d.y.push_back(x * (micro ? 1e6 : 1e3));
  track.curves.push_back(std::move(d));
  if (m > 0 && limit_lines)
    for (double sign : {1.0, -1.0}) {
      Curve l;
      l.color = kBlack;
      l.line_style = 2;
      l.width = 1.0;
      l.x = {s.t.front(), s.t.back()};
      l.y = {sign * s.torque_limit, sign * s.torque_limit};
      torque.curves.push_back(std::move(l));
    }
  fig.panels = {angles, track, torque, lag};
  return fig;
}

plot::Figure contact(const std::vector<ContactCurve>& curves, double M_ie, double approach_velocity) {
  plot::Figure fig;
  fig.name = "contact";
  fig.title = str("Contact force (multibody run): M#die#u = ", fixed(M_ie, 3),
                  " kg, δ̇⁻ = ", fixed(approach_velocity, 3), " m/s");
  fig.cols = 2;
  Panel loop = labelled("F-δ hysteresis loop (Figure 3)", "deformation δ (mm)", "contact force F (kN)"),
        time = labelled("force history (colours as on the left)", "time from first touch (ms)",
                        "contact force F (kN)");
  const bool one = curves.size() == 1;
  std::vector<Curve> markers;
  for (size_t k = 0; k < curves.size(); ++k) {
    const auto& c = curves[k];
    Curve l, t;
    l.label = t.label = c.law;
    l.color = t.color = static_cast<int>(k);
    l.line_style = t.line_style = static_cast<int>(k / 4) + 1;
    l.width = t.width = 1.8;
    for (size_t i = 0; i < c.t.size(); ++i) {
      l.x.push_back(c.delta[i] * 1e3);
      l.y.push_back(c.force[i] / 1e3);
      t.x.push_back(c.t[i] * 1e3);
      t.y.push_back(c.force[i] / 1e3);
    }
    t.label.clear();
    loop.curves.push_back(std::move(l));
    time.curves.push_back(std::move(t));
    Curve peak, dmax;
    peak.line_style = dmax.line_style = 0;
    peak.color = dmax.color = one ? 1 : static_cast<int>(k);
    peak.symbol = "*";
    peak.symbol_scale = 1.6;
    dmax.symbol = "○";
    dmax.symbol_scale = 1.1;
    peak.x = {c.delta_at_f_max * 1e3};
    peak.y = {c.f_max / 1e3};
    dmax.x = {c.delta_max * 1e3};
    dmax.y = {c.force_at_delta_max / 1e3};
    if (one || k == 0) {
      peak.label = "* (δ'max, Fmax)";
      dmax.label = "○ (δmax, F'max)";
    }
    markers.push_back(std::move(peak));
    markers.push_back(std::move(dmax));
  }
  for (auto& m : markers) loop.curves.push_back(std::move(m));  // after the laws: last in the legend
  loop.legend_outside = false;
  fig.panels.emplace_back(std::move(loop));
  fig.panels.emplace_back(std::move(time));
  return fig;
}

plot::Figure xi(const XiStudy& s) {
  plot::Figure fig;
  fig.name = s.name;
  Panel p;
  p.title = s.title;
  p.xlabel = s.xlabel;
  p.ylabel = "relative error ξ of the closed form (%)";
  p.log_x = s.log_x;
  p.legend_outside = true;
  for (size_t l = 0; l < s.laws.size(); ++l) {
    Curve c;
    c.label = s.laws[l];
    c.color = static_cast<int>(l);
    c.line_style = static_cast<int>(l / 4) + 1;
    c.symbol = s.x.size() <= 25 ? "●" : "";
    c.symbol_scale = 0.6;
    c.x = s.x;
    c.y = s.xi[l];
    p.curves.push_back(std::move(c));
  }
  fig.panels.emplace_back(std::move(p));
  return fig;
}

namespace {
std::string scientific(double x, int digits) {
  std::ostringstream s;
  s << std::scientific << std::setprecision(digits) << x;
  return s.str();
}

/// "1.2866 kg, 1.72e-03 deg/s"
std::string mass_rate(double mass, double rate, const std::string& unit = "deg/s") {
  return fixed(mass, 4) + " kg, " + (unit == "deg/s" ? scientific(rate, 2) : fixed(rate, 3)) + " " + unit;
}

Curve marker(std::string label, std::vector<double> x, std::vector<double> y, int color, const char* symbol,
             double scale) {
  Curve c;
  c.label = std::move(label);
  c.x = std::move(x);
  c.y = std::move(y);
  c.color = color;
  c.line_style = 0;
  c.symbol = symbol;
  c.symbol_scale = scale;
  return c;
}
}  // namespace

plot::Figure pareto(const ParetoSeries& s) {
  const size_t n = s.mass.size();
  if (n == 0 || s.rate.size() != n)
    throw InputError(str("pareto plot: ", n, " masses and ", s.rate.size(), " rates (equal, at least 1)"));
  if (s.knee >= n) throw InputError(str("pareto plot: knee index ", s.knee, " out of 0..", n - 1));
  auto bad = [](double m, double r) { return !std::isfinite(m) || !std::isfinite(r) || m <= 0 || r < 0; };
  for (size_t i = 0; i < n; ++i)
    if (bad(s.mass[i], s.rate[i]))
      throw InputError(str("pareto plot: front point ", i, " is (", s.mass[i], ", ", s.rate[i], ")"));
  for (const auto& r : s.runs)
    if (bad(r.mass, r.rate))
      throw InputError(str("pareto plot: ", r.label, " is (", r.mass, ", ", r.rate, ")"));

  // the front's extent grown by a quarter on every side: the runs inside are drawn beside the front
  const auto mass = std::minmax_element(s.mass.begin(), s.mass.end());
  const auto rate = std::minmax_element(s.rate.begin(), s.rate.end());
  const double m0 = *mass.first, m1 = *mass.second, r0 = *rate.first, r1 = *rate.second;
  const double dm = 0.25 * std::max(m1 - m0, 1e-6 * m1), dr = 0.25 * std::max(r1 - r0, 1e-6 * (r1 + 1e-12));
  auto near = [&](const ParetoSeries::Run& r) {
    return r.mass >= m0 - dm && r.mass <= m1 + dm && r.rate >= r0 - dr && r.rate <= r1 + dr;
  };
  const bool wide = std::any_of(s.runs.begin(), s.runs.end(), [&](const auto& r) { return !near(r); });

  constexpr int kRunColors[] = {2, 3, 4, 5, 7};
  auto run_marker = [&](size_t i) {
    const auto& r = s.runs[i];
    return marker(r.label + ": " + mass_rate(r.mass, r.rate, s.y_unit), {r.mass}, {r.rate},
                  kRunColors[i % std::size(kRunColors)], "▲", 1.0);
  };
  Curve line;
  line.x = s.mass;
  line.y = s.rate;
  line.color = 0;
  line.width = 1.5;
  line.symbol = "●";

  const std::string& ylabel = s.y_label;
  Panel front =
      labelled("the front at the global run's base pose, the runs at their own", "M_ie (kg)", ylabel);
  line.label = str("front (", n, " points)");
  line.symbol_scale = 0.55;
  front.curves.push_back(line);
  front.curves.push_back(marker("least M_ie: " + mass_rate(s.mass.front(), s.rate.front(), s.y_unit),
                                {s.mass.front()}, {s.rate.front()}, kBlack, "■", 0.9));
  front.curves.push_back(
      marker("least " + s.y_name + ": " + mass_rate(s.mass.back(), s.rate.back(), s.y_unit), {s.mass.back()},
             {s.rate.back()}, kBlack, "□", 0.9));
  front.curves.push_back(marker("knee: " + mass_rate(s.mass[s.knee], s.rate[s.knee], s.y_unit),
                                {s.mass[s.knee]}, {s.rate[s.knee]}, 1, "◆", 1.2));
  for (size_t i = 0; i < s.runs.size(); ++i)
    if (near(s.runs[i])) front.curves.push_back(run_marker(i));

  plot::Figure fig;
  fig.name = "pareto";
  fig.title = s.title.empty() ? "Pareto front" : "Pareto front: " + s.title;
  fig.width = 1200;
  fig.panels.emplace_back(std::move(front));
  if (wide) {  // below: the front as one line and every run, on the scale of the runs
    Panel all = labelled("", "M_ie (kg)", ylabel);
    line.label = "front (above)";
    line.symbol_scale = 0.3;
    all.curves.push_back(line);
    for (size_t i = 0; i < s.runs.size(); ++i) all.curves.push_back(run_marker(i));
    fig.panels.emplace_back(std::move(all));
    fig.rows = 2;
    fig.height = 1100;
  }
  return fig;
}

void Grid::validate(size_t dims) const {
  if (axes.size() != dims || axis_labels.size() != dims)
    throw InputError(str("map plot: expected ", dims, " varied joints, got ", axes.size()));
  size_t n = 1;
  for (const auto& a : axes) {
    if (a.size() < 2) throw InputError("map plot: every varied joint needs at least 2 grid values");
    if (!std::is_sorted(a.begin(), a.end())) throw InputError("map plot: grid values must be ascending");
    n *= a.size();
  }
  if (values.size() != n)
    throw InputError(str("map plot: ", values.size(), " values for a grid of ", n, " points"));
}

namespace {
std::string point_text(const Grid& g, size_t flat) {
  std::vector<size_t> idx(g.axes.size());
  for (size_t d = g.axes.size(); d-- > 0;) {
    idx[d] = flat % g.axes[d].size();
    flat /= g.axes[d].size();
  }
  std::string s = "[";
  for (size_t d = 0; d < idx.size(); ++d) s += (d ? ", " : "") + fixed(g.axes[d][idx[d]], 1);
  return s + "] deg";
}

size_t nearest(const std::vector<double>& axis, double v) {
  return static_cast<size_t>(
      std::min_element(axis.begin(), axis.end(),
                       [&](double a, double b) { return std::abs(a - v) < std::abs(b - v); }) -
      axis.begin());
}
}  // namespace

plot::Figure map_heat(const Grid& g, const std::string& name, const std::string& title) {
  g.validate(2);
  plot::Figure fig;
  fig.name = name;
  plot::HeatPanel h;
  const size_t imax =
      static_cast<size_t>(std::max_element(g.values.begin(), g.values.end()) - g.values.begin());
  h.title = title.empty() ? str("maximum ", fixed(g.values[imax], 3), " at ", point_text(g, imax)) : title;
  h.xlabel = g.axis_labels[0];
  h.ylabel = g.axis_labels[1];
  h.zlabel = g.value_label;
  h.x = g.axes[0];
  h.y = g.axes[1];
  h.z = g.values;
  Curve m;
  m.label = "maximum";
  m.symbol = "▲";
  m.color = 1;
  m.line_style = 0;
  m.x = {g.axes[0][imax / g.axes[1].size()]};
  m.y = {g.axes[1][imax % g.axes[1].size()]};
  h.overlay.push_back(m);
  fig.panels.emplace_back(std::move(h));
  return fig;
}

plot::Figure map_slices(const Grid& g, const std::vector<double>& point, const std::string& name,
                        const std::string& title) {
  g.validate(3);
  if (point.size() != 3) throw InputError("map plot: the slice point needs one value per varied joint");
  plot::Figure fig;
  fig.name = name;
  const size_t imax =
      static_cast<size_t>(std::max_element(g.values.begin(), g.values.end()) - g.values.begin());
  fig.title =
      title.empty() ? str("grid maximum ", fixed(g.values[imax], 3), " at ", point_text(g, imax)) : title;
  fig.cols = 3;
  const size_t n1 = g.axes[1].size(), n2 = g.axes[2].size();
  const size_t c[3] = {nearest(g.axes[0], point[0]), nearest(g.axes[1], point[1]),
                       nearest(g.axes[2], point[2])};
  double lo = *std::min_element(g.values.begin(), g.values.end()), hi = g.values[imax];
  for (int fixed_axis = 0; fixed_axis < 3; ++fixed_axis) {
    const int a = fixed_axis == 0 ? 1 : 0, b = fixed_axis == 2 ? 1 : 2;
    plot::HeatPanel h;
    h.title = g.axis_labels[static_cast<size_t>(fixed_axis)] + " = " +
              fixed(g.axes[static_cast<size_t>(fixed_axis)][c[fixed_axis]], 1);
    h.xlabel = g.axis_labels[static_cast<size_t>(a)];
    h.ylabel = g.axis_labels[static_cast<size_t>(b)];
    h.zlabel = g.value_label;
    h.x = g.axes[static_cast<size_t>(a)];
    h.y = g.axes[static_cast<size_t>(b)];
    h.zmin = lo;
    h.zmax = hi;
    h.levels = 16;
    h.contours = 8;
    size_t smax = 0;
    for (size_t i = 0; i < h.x.size(); ++i)
      for (size_t j = 0; j < h.y.size(); ++j) {
        size_t idx[3];
        idx[fixed_axis] = c[fixed_axis];
        idx[a] = i;
        idx[b] = j;
        h.z.push_back(g.values[idx[0] * n1 * n2 + idx[1] * n2 + idx[2]]);
        if (h.z.back() > h.z[smax]) smax = h.z.size() - 1;
      }
    Curve m;
    m.label = fixed_axis == 2 ? "slice maximum" : "";
    m.symbol = "▲";
    m.color = 1;
    m.line_style = 0;
    m.x = {h.x[smax / h.y.size()]};
    m.y = {h.y[smax % h.y.size()]};
    h.overlay.push_back(m);
    fig.panels.emplace_back(std::move(h));
  }
  fig.height = 420;
  fig.width = 1400;
  return fig;
}

plot::Figure map_cloud(const Grid& g, const std::string& name, const std::string& title, size_t max_points) {
  g.validate(3);
  plot::Figure fig;
  fig.name = name;
  plot::CloudPanel p;
  p.title = title.empty() ? "M_ie over the joint grid" : title;
  p.xlabel = g.axis_labels[0];
  p.ylabel = g.axis_labels[1];
  p.zlabel = g.axis_labels[2];
  p.clabel = g.value_label;
  // an even stride per axis so that at most max_points remain
  const size_t n0 = g.axes[0].size(), n1 = g.axes[1].size(), n2 = g.axes[2].size();
  size_t stride = 1;
  while ((n0 + stride - 1) / stride * ((n1 + stride - 1) / stride) * ((n2 + stride - 1) / stride) >
         max_points)
    ++stride;
  for (size_t i = 0; i < n0; i += stride)
    for (size_t j = 0; j < n1; j += stride)
      for (size_t k = 0; k < n2; k += stride) {
        p.x.push_back(g.axes[0][i]);
        p.y.push_back(g.axes[1][j]);
        p.z.push_back(g.axes[2][k]);
        p.c.push_back(g.values[i * n1 * n2 + j * n2 + k]);
      }
  fig.panels.emplace_back(std::move(p));
  return fig;
}

/// The distribution of F_max per configuration (kN): the empirical CDF with the 95th percentile
/// marked, and the histogram (shared bins, drawn as steps) -- a run and a merged summary alike.
plot::Figure robust(const RobustSeries& s) {
  plot::Figure fig;
  fig.name = "robust";
  fig.title = s.title;
  fig.cols = 2;
  fig.width = 1200;
  fig.height = 700;
  plot::Panel cdf, hist;
  cdf.title = s.stiffness_conditional ? "empirical CDF; dot: p95 of the law (conditional on K)"
                                      : "empirical CDF, 95th percentile marked";
  cdf.xlabel = hist.xlabel = "F_max (kN)";
  cdf.ylabel = "fraction";
  hist.title = "histogram (40 shared bins)";
  hist.ylabel = "fraction per bin";
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& c : s.configurations)
    for (double f : c.f_max) {
      lo = std::min(lo, f / 1e3);
      hi = std::max(hi, f / 1e3);
    }
  if (!(hi > lo)) hi = lo + 1.0;
  constexpr int kBins = 40;
  const double w = (hi - lo) / kBins;
  int color = 0;
  for (const auto& c : s.configurations) {
    std::vector<double> f = c.f_max;
    for (double& x : f) x /= 1e3;
    std::sort(f.begin(), f.end());
    const double n = static_cast<double>(f.size());
    plot::Curve line;
    line.label = c.name;
    line.color = color;
    line.line_style = 1 + color % 4;
    for (std::size_t i = 0; i < f.size(); ++i) {  // the CDF as steps
      line.x.push_back(f[i]);
      line.y.push_back(static_cast<double>(i) / n);
      line.x.push_back(f[i]);
      line.y.push_back(static_cast<double>(i + 1) / n);
    }
    plot::Curve p95;
    p95.color = color;
    p95.line_style = 0;
    p95.symbol = "●";
    p95.x = {c.p95 / 1e3};
    p95.y = {0.95};
    cdf.curves.push_back(std::move(line));
    cdf.curves.push_back(std::move(p95));
    std::vector<double> count(kBins, 0.0);
    for (double x : f)
      count[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>((x - lo) / w)))] += 1.0 / n;
    plot::Curve steps;
    steps.label = c.name;
    steps.color = color;
    steps.line_style = 1 + color % 4;
    for (int b = 0; b < kBins; ++b) {
      steps.x.push_back(lo + b * w);
      steps.y.push_back(count[static_cast<std::size_t>(b)]);
      steps.x.push_back(lo + (b + 1) * w);
      steps.y.push_back(count[static_cast<std::size_t>(b)]);
    }
    hist.curves.push_back(std::move(steps));
    ++color;
  }
  fig.panels.emplace_back(std::move(cdf));
  fig.panels.emplace_back(std::move(hist));
  return fig;
}

}  // namespace ffsr::cli::figures
