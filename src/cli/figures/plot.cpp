// src/cli/figures/plot.cpp -- the PLplot renderer of plot.hpp (and the stub of a build without PLplot).
#include "figures/plot.hpp"

#include "ffsr/errors.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#ifndef FFSR_WITH_PLOT
#define FFSR_WITH_PLOT 0
#endif
#if FFSR_WITH_PLOT
#include <plplot/plstream.h>
#endif

namespace ffsr::cli::plot {

using ffsr::detail::str;

bool available() { return FFSR_WITH_PLOT != 0; }

void require_available(const std::string& flag) {
  if (!available())
    throw InputError(str(flag,
                         ": this ffsr-optimize was built without plotting (PLplot not found or "
                         "-DFFSR_WITH_PLOT=OFF); install libplplot-dev and plplot-driver-cairo and rebuild"));
}

namespace {
/// Each format's file extension (as --plot-format spells it) and PLplot device.
struct FormatNames {
  Format format;
  const char* extension;
  const char* device;
};
constexpr FormatNames kFormats[] = {
    {Format::Png, "png", "pngcairo"}, {Format::Svg, "svg", "svgcairo"}, {Format::Pdf, "pdf", "pdfcairo"}};

const FormatNames& names_of(Format f) {
  for (const auto& n : kFormats)
    if (n.format == f) return n;
  return kFormats[0];
}
}  // namespace

Format parse_format(const std::string& text, const std::string& flag) {
  for (const auto& n : kFormats)
    if (text == n.extension) return n.format;
  throw InputError(str(flag, ": unknown format '", text, "'; expected png, svg or pdf"));
}

const char* extension(Format f) { return names_of(f).extension; }

void check_folder(const std::string& dir, const std::string& flag) {
  std::error_code ec;
  if (dir.empty()) throw InputError(str(flag, ": empty folder name"));
  if (!std::filesystem::is_directory(dir, ec))
    throw InputError(str(flag, ": folder '", dir, "' does not exist (create it first)"));
}

Format check_request(const std::string& dir, const std::string& format) {
  const Format f = parse_format(format, "--plot-format");
  if (!dir.empty()) {
    require_available("--plot");
    check_folder(dir, "--plot");
  }
  return f;
}

std::array<int, 3> palette(int i) {
  static constexpr std::array<std::array<int, 3>, kPaletteSize> okabe_ito{{{0, 114, 178},
                                                                           {213, 94, 0},
                                                                           {0, 158, 115},
                                                                           {204, 121, 167},
                                                                           {230, 159, 0},
                                                                           {86, 180, 233},
                                                                           {0, 0, 0},
                                                                           {136, 34, 85}}};
  return okabe_ito[static_cast<size_t>(((i % kPaletteSize) + kPaletteSize) % kPaletteSize)];
}

#if FFSR_WITH_PLOT
namespace {

// cmap0 layout: 0 background (white), 1 text and axes (black), 2..9 the palette, 10 scratch (alpha).
constexpr int kText = 1, kFirst = 2, kScratch = 10, kGrey = 11;
// text size relative to PLplot's default: readable at 100 % on a 1000 x 700 page
constexpr double kScale = 0.75;

const char* device(Format f) { return names_of(f).device; }

/// The data range of several arrays, with a relative margin; a flat range is widened.
void range(const std::vector<const std::vector<double>*>& arrays, double margin, double& lo, double& hi) {
  lo = std::numeric_limits<double>::infinity();
  hi = -lo;
  for (const auto* a : arrays)
    for (double v : *a)
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  if (!std::isfinite(lo)) {
    lo = 0;
    hi = 1;
  }
  double d = hi - lo;
  if (d <= 1e-12 * std::max(1.0, std::abs(hi))) {
    d = std::max(1e-3, 0.1 * std::abs(hi));
    lo -= d / 2;
    hi += d / 2;
    return;
  }
  lo -= margin * d;
  hi += margin * d;
}

struct Cell {
  double x0, x1, y0, y1;  // normalized page coordinates of the panel's cell
  bool bottom = false;    // in the figure's last row: its x-axis label meets the page edge
};

class Renderer {
 public:
  Renderer(plstream& pls, const Figure& fig) : pls_(pls), fig_(fig) {}

  void draw() {
    pls_.adv(0);
    const double top = fig_.title.empty() ? 1.0 : 0.95;
    if (!fig_.title.empty()) {
      pls_.vpor(0, 1, 0, 1);
      pls_.wind(0, 1, 0, 1);
      pls_.col0(kText);
      pls_.schr(0, kScale * (1.15));
      pls_.ptex(0.5, 0.972, 1, 0, 0.5, fig_.title.c_str());
      pls_.schr(0, kScale);
    }
    const int rows = std::max(1, fig_.rows), cols = std::max(1, fig_.cols);
    for (size_t k = 0; k < fig_.panels.size(); ++k) {
      const int r = static_cast<int>(k) / cols, c = static_cast<int>(k) % cols;
      const double h = top / rows, w = 1.0 / cols;
      const bool bottom = r == static_cast<int>(fig_.panels.size() - 1) / cols;
      const Cell cell{c * w, (c + 1) * w, top - (r + 1) * h, top - r * h, bottom};
      std::visit([&](const auto& p) { draw(p, cell); }, fig_.panels[k]);
    }
  }

 private:
  plstream& pls_;
  const Figure& fig_;

  void color(int palette_index, double alpha) {
    const auto rgb = palette(palette_index);
    pls_.scol0a(kScratch, rgb[0], rgb[1], rgb[2], alpha);
    pls_.col0(kScratch);
  }

  /// The viewport of a 2-D panel inside its cell: room for tick labels, axis labels and the title.
  void viewport(const Cell& c, double right_extra, double& vx0, double& vx1, double& vy0, double& vy1) {
    const double px = 1.0 / fig_.width, py = 1.0 / fig_.height;
    vx0 = c.x0 + 96 * px;  // room for the y label and PLplot's "(x10^k)" scale label
    vx1 = c.x1 - (18 + right_extra) * px;
    vy0 = c.y0 + (c.bottom ? 84 : 50) * py;  // the last row's x label, descenders included, above the edge
    vy1 = c.y1 - 30 * py;
  }

  /// The data window of a panel: its limits, or the range of its curves with a margin.
  static void data_window(const Panel& p, double& xmin, double& xmax, double& ymin, double& ymax) {
    if (p.limits.size() == 4) {
      xmin = p.limits[0], xmax = p.limits[1], ymin = p.limits[2], ymax = p.limits[3];
    } else {
      std::vector<const std::vector<double>*> xs, ys;
      for (const auto& c : p.curves) {
        xs.push_back(&c.x);
        ys.push_back(&c.y);
      }
      range(xs, p.log_x ? 0.0 : 0.03, xmin, xmax);
      range(ys, 0.06, ymin, ymax);
    }
    if (p.log_x) {
      xmin = std::log10(xmin);
      xmax = std::log10(xmax);
    }
  }

  /// The corner of an inside legend: where its box hides the fewest curve points; when every corner
  /// would hide some, the y range grows upwards until the box fits above the curves.
  template <class Tx>
  static int legend_corner(const Panel& p, Tx tx, double xmin, double xmax, double ymin, double& ymax) {
    const long entries =
        std::count_if(p.curves.begin(), p.curves.end(), [](const Curve& c) { return !c.label.empty(); });
    const double box_w = 0.34, box_h = std::min(0.6, 0.03 + 0.085 * static_cast<double>(entries));
    long hidden = 0;
    int corner = emptiest_corner(p.curves, tx, xmin, xmax, ymin, ymax, box_w, box_h, hidden);
    if (hidden > 0 && p.limits.size() != 4 && !p.equal_aspect) {
      ymax = ymin + (ymax - ymin) / (1.0 - box_h - 0.02);
      corner = emptiest_corner(p.curves, tx, xmin, xmax, ymin, ymax, box_w, box_h, hidden);
    }
    return corner;
  }

  /// The curves of a panel: fills, lines and symbols, in the window set.
  template <class Tx>
  void draw_curves(const Panel& p, Tx tx) {
    for (const auto& c : p.curves) {
      std::vector<double> x(c.x.size());
      std::transform(c.x.begin(), c.x.end(), x.begin(), tx);
      const auto n = static_cast<PLINT>(std::min(x.size(), c.y.size()));
      if (n == 0) continue;
      color(c.color, c.alpha);
      if (c.fill && n >= 3) pls_.fill(n, x.data(), c.y.data());
      if (c.line_style > 0 && n >= 2) {
        pls_.lsty(c.line_style);
        pls_.width(c.width);
        pls_.line(n, x.data(), c.y.data());
        pls_.lsty(1);
      }
      if (!c.symbol.empty()) {
        pls_.schr(0, kScale * (c.symbol_scale));
        pls_.string(n, x.data(), c.y.data(), c.symbol.c_str());
        pls_.schr(0, kScale);
      }
    }
  }

  void draw(const Panel& p, const Cell& cell) {
    const bool has_legend =
        std::any_of(p.curves.begin(), p.curves.end(), [](const Curve& c) { return !c.label.empty(); });
    double vx0, vx1, vy0, vy1;
    viewport(cell, p.legend_outside && has_legend ? 250 : 0, vx0, vx1, vy0, vy1);
    double xmin, xmax, ymin, ymax;
    data_window(p, xmin, xmax, ymin, ymax);
    auto tx = [&](double x) { return p.log_x ? std::log10(x) : x; };
    const int corner = has_legend && !p.legend_outside ? legend_corner(p, tx, xmin, xmax, ymin, ymax) : 0;
    if (p.equal_aspect) {
      const double w = (vx1 - vx0) * fig_.width, h = (vy1 - vy0) * fig_.height;
      const double s = std::max((xmax - xmin) / w, (ymax - ymin) / h);
      const double cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
      xmin = cx - 0.5 * s * w, xmax = cx + 0.5 * s * w;
      ymin = cy - 0.5 * s * h, ymax = cy + 0.5 * s * h;
    }
    pls_.vpor(vx0, vx1, vy0, vy1);
    pls_.wind(xmin, xmax, ymin, ymax);
    pls_.col0(kGrey);
    pls_.width(0.5);
    pls_.box(p.log_x ? "ghl" : "g", 0, 0, "g", 0, 0);  // light grid first, under the curves
    draw_curves(p, tx);
    pls_.col0(kText);
    pls_.width(1.0);
    pls_.box(p.log_x ? "bcnstl" : "bcnst", 0, 0, "bcnstv", 0, 0);
    pls_.mtex("b", 3.0, 0.5, 0.5, p.xlabel.c_str());
    pls_.mtex("l", 4.5, 0.5, 0.5, p.ylabel.c_str());
    pls_.mtex("t", 1.0, 0.5, 0.5, p.title.c_str());
    if (has_legend) legend(p.curves, p.legend_outside, corner);
  }

  /// The corner of the axes (0 top right, 1 top left, 2 bottom right, 3 bottom left) whose legend
  /// box (box_w x box_h, fractions of the axes) covers the fewest curve points, and that count.
  template <class Tx>
  static int emptiest_corner(const std::vector<Curve>& curves, Tx tx, double xmin, double xmax, double ymin,
                             double ymax, double box_w, double box_h, long& hidden) {
    long count[4] = {0, 0, 0, 0};
    for (const auto& c : curves)
      for (size_t i = 0; i < std::min(c.x.size(), c.y.size()); ++i) {
        const double u = (tx(c.x[i]) - xmin) / (xmax - xmin), v = (c.y[i] - ymin) / (ymax - ymin);
        const bool right = u > 1.0 - box_w - 0.02, left = u < box_w + 0.02;
        const bool top = v > 1.0 - box_h - 0.02, bottom = v < box_h + 0.02;
        if (top && right) ++count[0];
        if (top && left) ++count[1];
        if (bottom && right) ++count[2];
        if (bottom && left) ++count[3];
      }
    const int best = static_cast<int>(std::min_element(count, count + 4) - count);
    hidden = count[best];
    return best;
  }

  void legend(const std::vector<Curve>& curves, bool outside, int corner = 0) {
    std::vector<PLINT> opt, text_colors, line_colors, line_styles, symbol_colors, symbol_numbers, box_i;
    std::vector<PLFLT> line_widths, symbol_scales, box_f;
    std::vector<const char*> text, symbols;
    for (const auto& c : curves) {
      if (c.label.empty()) continue;
      PLINT o = 0;
      if (c.line_style > 0) o |= PL_LEGEND_LINE;
      if (!c.symbol.empty()) o |= PL_LEGEND_SYMBOL;
      if (o == 0) o = PL_LEGEND_NONE;
      opt.push_back(o);
      const PLINT col = kFirst + (((c.color % kPaletteSize) + kPaletteSize) % kPaletteSize);
      text_colors.push_back(kText);
      line_colors.push_back(col);
      line_styles.push_back(std::max(1, c.line_style));
      line_widths.push_back(c.width);
      symbol_colors.push_back(col);
      symbol_scales.push_back(c.symbol_scale);
      symbol_numbers.push_back(1);
      symbols.push_back(c.symbol.empty() ? " " : c.symbol.c_str());
      text.push_back(c.label.c_str());
      box_i.push_back(0);
      box_f.push_back(0);
    }
    PLFLT w = 0, h = 0;
    const PLINT horizontal = corner == 1 || corner == 3 ? PL_POSITION_LEFT : PL_POSITION_RIGHT;
    const PLINT vertical = corner >= 2 ? PL_POSITION_BOTTOM : PL_POSITION_TOP;
    const PLINT pos =
        outside ? (PL_POSITION_RIGHT | PL_POSITION_OUTSIDE) : (horizontal | vertical | PL_POSITION_INSIDE);
    pls_.schr(0, kScale);
    pls_.legend(&w, &h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, pos, outside ? 0.02 : 0.01,
                outside ? 0.0 : 0.01, 0.06, 0, kText, 1, 0, 0, static_cast<PLINT>(text.size()), opt.data(),
                0.8, 0.8, 1.7, 0.0, text_colors.data(), text.data(), box_i.data(), box_i.data(), box_f.data(),
                box_f.data(), line_colors.data(), line_styles.data(), line_widths.data(),
                symbol_colors.data(), symbol_scales.data(), symbol_numbers.data(), symbols.data());
    pls_.schr(0, kScale);
  }

  /// tick: the major tick interval per axis (0: PLplot's choice, by the data range alone)
  void box3(const std::string& xl, const std::string& yl, const std::string& zl, double xtick = 0,
            double ytick = 0, double ztick = 0) {
    pls_.col0(kText);
    pls_.width(1.0);
    pls_.box3("bnstu", xl.c_str(), xtick, 0, "bnstu", yl.c_str(), ytick, 0, "bcdmnstuv", zl.c_str(), ztick,
              0);
  }

  void draw(const Panel3& p, const Cell& cell) {
    std::vector<const std::vector<double>*> xs, ys, zs;
    for (const auto& c : p.curves) {
      xs.push_back(&c.x);
      ys.push_back(&c.y);
      zs.push_back(&c.z);
    }
    double x0, x1, y0, y1, z0, z1;
    range(xs, 0.05, x0, x1);
    range(ys, 0.05, y0, y1);
    range(zs, 0.05, z0, z1);
    // equal scale on the three axes: the box sides are proportional to the data ranges
    const double d = std::max({x1 - x0, y1 - y0, z1 - z0});
    auto side = [&](double r) { return 1.2 * std::max(0.5, r / d); };  // a flat axis keeps room for its ticks
    pls_.vpor(cell.x0 + 0.01, cell.x1 - 0.01, cell.y0 + 0.02, cell.y1 - 0.05);
    pls_.wind(-1.0, 1.0, -0.9, 1.5);
    pls_.w3d(side(x1 - x0), side(y1 - y0), side(z1 - z0), x0, x1, y0, y1, z0, z1, p.altitude, p.azimuth);
    // PLplot picks the ticks by the data range alone; an axis drawn short gets a coarser interval (a
    // 1-2-5 step of at least half its range: two or three labels), or its labels run into each other
    auto tick = [&](double r) {
      if (side(r) >= 1.0) return 0.0;
      const double e = std::pow(10.0, std::floor(std::log10(0.5 * r)));
      for (double m : {1.0, 2.0, 5.0})
        if (m * e >= 0.5 * r) return m * e;
      return 10.0 * e;  // e <= r/2 < 10 e
    };
    box3(p.xlabel, p.ylabel, p.zlabel, tick(x1 - x0), tick(y1 - y0), tick(z1 - z0));
    for (const auto& c : p.curves) {
      const auto n = static_cast<PLINT>(std::min({c.x.size(), c.y.size(), c.z.size()}));
      if (n == 0) continue;
      color(c.color, c.alpha);
      if (c.line_style > 0 && n >= 2) {
        pls_.lsty(c.line_style);
        pls_.width(c.width);
        pls_.line3(n, c.x.data(), c.y.data(), c.z.data());
        pls_.lsty(1);
      }
      if (!c.symbol.empty()) {
        pls_.schr(0, kScale * (c.symbol_scale));
        pls_.string3(n, c.x.data(), c.y.data(), c.z.data(), c.symbol.c_str());
        pls_.schr(0, kScale);
      }
    }
    pls_.col0(kText);
    pls_.vpor(cell.x0, cell.x1, cell.y0, cell.y1 - 0.05);
    pls_.mtex("t", 1.0, 0.5, 0.5, p.title.c_str());
  }

  static void viridis(plstream& pls) {
    const PLFLT pos[] = {0.0, 0.25, 0.5, 0.75, 1.0};
    const PLFLT r[] = {68 / 255.0, 59 / 255.0, 33 / 255.0, 94 / 255.0, 253 / 255.0};
    const PLFLT g[] = {1 / 255.0, 82 / 255.0, 145 / 255.0, 201 / 255.0, 231 / 255.0};
    const PLFLT b[] = {84 / 255.0, 139 / 255.0, 140 / 255.0, 98 / 255.0, 37 / 255.0};
    pls.scmap1n(256);
    pls.scmap1l(true, 5, pos, r, g, b, nullptr);
  }

  void colorbar(const std::vector<PLFLT>& levels, const std::string& label, PLINT kind) {
    PLFLT w = 0, h = 0;
    PLINT label_opt = PL_COLORBAR_LABEL_RIGHT;
    const char* labels[] = {label.c_str()};
    const char* axis[] = {"bcvtm"};
    PLFLT ticks[] = {0.0};
    PLINT sub_ticks[] = {0};
    PLINT n_values[] = {static_cast<PLINT>(levels.size())};
    const PLFLT* values[] = {levels.data()};
    pls_.schr(0, kScale * (0.9));
    pls_.colorbar(&w, &h, kind, PL_POSITION_RIGHT | PL_POSITION_OUTSIDE, 0.02, 0.0, 0.035, 1.0, 0, kText, 1,
                  0, 0, 0, 0, 1, &label_opt, labels, 1, axis, ticks, sub_ticks, n_values, values);
    pls_.schr(0, kScale);
  }

  void draw(const HeatPanel& p, const Cell& cell) {
    const auto nx = static_cast<PLINT>(p.x.size()), ny = static_cast<PLINT>(p.y.size());
    if (nx < 2 || ny < 2 || p.z.size() != p.x.size() * p.y.size())
      throw InputError("heat map: the grid needs at least 2 x 2 points and one value per point");
    double zmin = p.zmin, zmax = p.zmax;
    if (!(zmax > zmin)) {
      zmin = *std::min_element(p.z.begin(), p.z.end());
      zmax = *std::max_element(p.z.begin(), p.z.end());
      if (!(zmax > zmin)) zmax = zmin + 1;
    }
    std::vector<PLFLT*> rows(static_cast<size_t>(nx));
    std::vector<PLFLT> z(p.z);
    for (PLINT i = 0; i < nx; ++i)
      rows[static_cast<size_t>(i)] = z.data() + static_cast<size_t>(i) * static_cast<size_t>(ny);
    std::vector<PLFLT> shade(static_cast<size_t>(p.levels + 1)), cont(static_cast<size_t>(p.contours));
    for (int k = 0; k <= p.levels; ++k) shade[static_cast<size_t>(k)] = zmin + (zmax - zmin) * k / p.levels;
    for (int k = 0; k < p.contours; ++k)
      cont[static_cast<size_t>(k)] = zmin + (zmax - zmin) * (k + 0.5) / p.contours;
    double vx0, vx1, vy0, vy1;
    viewport(cell, 120, vx0, vx1, vy0, vy1);
    pls_.vpor(vx0, vx1, vy0, vy1);
    const double xmin = p.x.front(), xmax = p.x.back(), ymin = p.y.front(), ymax = p.y.back();
    pls_.wind(xmin, xmax, ymin, ymax);
    viridis(pls_);
    pls_.shades(rows.data(), nx, ny, nullptr, xmin, xmax, ymin, ymax, shade.data(),
                static_cast<PLINT>(shade.size()), 1.0, 0, 0.0, plfill, true, nullptr, nullptr);
    std::vector<PLFLT> xg(p.x), yg(p.y);
    PLcGrid grid{xg.data(), yg.data(), nullptr, nx, ny, 0};
    pls_.col0(kText);
    pls_.width(0.8);
    pls_.cont(rows.data(), nx, ny, 1, nx, 1, ny, cont.data(), static_cast<PLINT>(cont.size()), pltr1, &grid);
    for (const auto& c : p.overlay) {
      color(c.color, c.alpha);
      const auto n = static_cast<PLINT>(std::min(c.x.size(), c.y.size()));
      if (!c.symbol.empty() && n > 0) {
        pls_.schr(0, kScale * (c.symbol_scale));
        pls_.string(n, c.x.data(), c.y.data(), c.symbol.c_str());
        pls_.schr(0, kScale);
      }
    }
    pls_.col0(kText);
    pls_.width(1.0);
    pls_.box("bcnst", 0, 0, "bcnstv", 0, 0);
    pls_.mtex("b", 3.0, 0.5, 0.5, p.xlabel.c_str());
    pls_.mtex("l", 4.5, 0.5, 0.5, p.ylabel.c_str());
    pls_.mtex("t", 1.0, 0.5, 0.5, p.title.c_str());
    if (std::any_of(p.overlay.begin(), p.overlay.end(), [](const Curve& c) { return !c.label.empty(); }))
      legend(p.overlay, false);
    colorbar(shade, p.zlabel, PL_COLORBAR_SHADE);
  }

  void draw(const CloudPanel& p, const Cell& cell) {
    double x0, x1, y0, y1, z0, z1, c0, c1;
    range({&p.x}, 0.0, x0, x1);
    range({&p.y}, 0.0, y0, y1);
    range({&p.z}, 0.0, z0, z1);
    range({&p.c}, 0.0, c0, c1);
    pls_.vpor(cell.x0 + 0.01, cell.x1 - 0.13, cell.y0 + 0.02, cell.y1 - 0.05);
    pls_.wind(-1.0, 1.0, -0.9, 1.5);
    pls_.w3d(1.2, 1.2, 1.2, x0, x1, y0, y1, z0, z1, p.altitude, p.azimuth);
    box3(p.xlabel, p.ylabel, p.zlabel);
    viridis(pls_);
    // 32 colour bins, one call per bin; points drawn from low to high values so that the high ones
    // (the interesting ones) are on top
    constexpr int bins = 32;
    std::vector<std::vector<size_t>> members(bins);
    for (size_t k = 0; k < p.c.size() && k < p.x.size() && k < p.y.size() && k < p.z.size(); ++k) {
      const double f = (p.c[k] - c0) / (c1 - c0);
      members[static_cast<size_t>(std::clamp(static_cast<int>(f * bins), 0, bins - 1))].push_back(k);
    }
    for (int b = 0; b < bins; ++b) {
      const auto& m = members[static_cast<size_t>(b)];
      if (m.empty()) continue;
      std::vector<PLFLT> x, y, z;
      for (size_t k : m) {
        x.push_back(p.x[k]);
        y.push_back(p.y[k]);
        z.push_back(p.z[k]);
      }
      pls_.col1((b + 0.5) / bins);
      pls_.schr(0, kScale * (0.55));
      pls_.string3(static_cast<PLINT>(x.size()), x.data(), y.data(), z.data(), "●");
    }
    pls_.schr(0, kScale);
    pls_.col0(kText);
    pls_.vpor(cell.x0, cell.x1 - 0.13, cell.y0, cell.y1 - 0.05);
    pls_.mtex("t", 1.0, 0.5, 0.5, p.title.c_str());
    pls_.vpor(cell.x1 - 0.12, cell.x1 - 0.11, cell.y0 + 0.12, cell.y1 - 0.12);
    pls_.wind(0, 1, c0, c1);
    std::vector<PLFLT> levels(33);
    for (size_t k = 0; k < levels.size(); ++k) levels[k] = c0 + (c1 - c0) * static_cast<double>(k) / 32.0;
    colorbar(levels, p.clabel, PL_COLORBAR_GRADIENT);
  }
};

/// Draws one figure into `path`; runs in the child process.
void render_one(const Figure& fig, const std::string& path, Format format) {
  plstream pls;
  pls.sdev(device(format));
  pls.sfnam(path.c_str());
  pls.spage(0, 0, fig.width, fig.height, 0, 0);
  pls.scmap0n(16);
  pls.scolbg(255, 255, 255);
  pls.scol0(kText, 0, 0, 0);
  for (int i = 0; i < kPaletteSize; ++i) {
    const auto c = palette(i);
    pls.scol0(kFirst + i, c[0], c[1], c[2]);
  }
  pls.scol0(kGrey, 225, 225, 225);
  pls.setopt("bg", "FFFFFF");
  pls.init();
  pls.schr(0, kScale);
  Renderer(pls, fig).draw();
}

bool driver_present(const char* name) {
  // plgDevs fills caller-provided arrays of at most n entries
  std::vector<const char*> menu_v(256, nullptr), devs_v(256, nullptr);
  const char** menu = menu_v.data();
  const char** devs = devs_v.data();
  int n = static_cast<int>(devs_v.size());
  plgDevs(&menu, &devs, &n);
  bool found = false;
  for (int i = 0; i < n; ++i)
    if (devs[i] && std::string(devs[i]) == name) found = true;
  return found;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The drawing process: PLplot's chatter goes to `log`, never to our stdout (exit() from PLplot is
/// fine here); before each figure "@@figure NAME", on an error of ours "@@error WHY". Never returns.
[[noreturn]] void draw_in_child(const std::vector<Figure>& figures, const std::vector<std::string>& names,
                                const std::filesystem::path& tmp, const std::string& log, Format format) {
  const int null_fd = ::open("/dev/null", O_WRONLY);
  const int log_fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (null_fd < 0 || log_fd < 0) ::_exit(4);
  ::dup2(null_fd, 1);
  ::dup2(log_fd, 2);
  try {
    if (!driver_present(device(format))) {
      std::fprintf(stderr, "@@error PLplot has no '%s' driver (install plplot-driver-cairo)\n",
                   device(format));
      ::_exit(5);
    }
    for (size_t k = 0; k < figures.size(); ++k) {
      const std::string path = (tmp / names[k]).string();
      std::fprintf(stderr, "@@figure %s\n", names[k].c_str());
      std::fflush(stderr);
      render_one(figures[k], path, format);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "@@error %s\n", e.what());
    std::fflush(stderr);
    ::_exit(6);
  }
  std::fflush(stderr);
  ::_exit(0);
}

/// Runs draw_in_child in a forked process and returns its wait status.
int draw_in_process(const std::vector<Figure>& figures, const std::vector<std::string>& names,
                    const std::filesystem::path& tmp, const std::string& log, Format format) {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw InputError("--plot: cannot start the drawing process (fork failed)");
  if (pid == 0) draw_in_child(figures, names, tmp, log, format);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

/// What the drawing process said in its log: the figure it was drawing, an error of ours, PLplot's
/// own first message.
struct ChildReport {
  std::string current, error, plplot_message;
};

ChildReport read_report(const std::string& log) {
  ChildReport r;
  std::istringstream in(read_text(log));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("@@figure ", 0) == 0)
      r.current = line.substr(9);
    else if (line.rfind("@@error ", 0) == 0)
      r.error = line.substr(8);
    else if (!line.empty() && line.find_first_not_of(" *") != std::string::npos && r.plplot_message.empty())
      r.plplot_message = line;
    if (line.find("PLPLOT ERROR") != std::string::npos || line.find("ABORTING") != std::string::npos) {
      if (r.error.empty()) r.error = "PLplot: " + line;
    }
  }
  return r;
}

/// InputError naming the figure being drawn and why, unless the process drew everything.
void check_drawn(int status, const ChildReport& r, const std::string& dir) {
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && r.error.empty()) return;
  const std::string file = r.current.empty() ? dir : (std::filesystem::path(dir) / r.current).string();
  std::string why = !r.error.empty()            ? r.error
                    : !r.plplot_message.empty() ? "PLplot: " + r.plplot_message
                                                : "";
  if (why.empty())
    why = WIFSIGNALED(status) ? str("the drawing process died (signal ", WTERMSIG(status), ")")
                              : str("the drawing process failed (exit ", WEXITSTATUS(status), ")");
  throw InputError(str("--plot: cannot draw ", file, ": ", why));
}

/// Checks that every figure exists in the scratch folder (PLplot may exit 0 without a file).
void check_written(const StagedFiles& staged) {
  namespace fs = std::filesystem;
  for (const auto& n : staged.names()) {
    std::error_code ec;
    const fs::path from = staged.scratch() / n;
    if (!fs::is_regular_file(from, ec) || fs::file_size(from, ec) == 0)
      throw InputError(
          str("--plot: cannot draw ", (fs::path(staged.dir()) / n).string(), ": PLplot wrote no file"));
  }
}

}  // namespace

StagedFiles draw(const std::vector<Figure>& figures, const std::string& dir, Format format) {
  StagedFiles staged(dir, "--plot");
  const std::string log = (staged.scratch() / "plplot.log").string();
  std::vector<std::string> names;
  for (const auto& f : figures) names.push_back(f.name + "." + extension(format));
  const int status = draw_in_process(figures, names, staged.scratch(), log, format);
  check_drawn(status, read_report(log), dir);
  for (const auto& n : names) staged.add(n);
  check_written(staged);
  return staged;
}

#else  // built without PLplot

StagedFiles draw(const std::vector<Figure>&, const std::string&, Format) {
  require_available("--plot");
  return {};
}

#endif

std::vector<std::string> render(const std::vector<Figure>& figures, const std::string& dir, Format format) {
  StagedFiles staged = draw(figures, dir, format);
  std::vector<std::string> written = staged.targets();
  staged.commit();
  return written;
}

}  // namespace ffsr::cli::plot
