// src/cli/figures/plot.hpp -- figures: a small description of what to draw (panels of curves, 3-D curves,
// heat maps, 3-D point clouds) and a renderer that hands it to PLplot.
#pragma once

#include "support/staging.hpp"

#include <array>
#include <string>
#include <variant>
#include <vector>

// The description is plain data, built by figures.cpp from the same result structs the JSON and CSV
// are written from, so a picture and the numbers never disagree. PLplot draws the axes, ticks,
// legends and colour bars. Rendering runs in a forked child process: PLplot may print to stdout or
// stderr and calls exit() on some errors; the child's stdout goes to /dev/null, its stderr is
// captured, and a failure becomes one InputError naming the file. All figures of a call are drawn
// into a scratch folder inside DIR first (StagedFiles, support/staging.hpp); the subcommands hand it
// to their Outputs, which moves the figures into DIR together with the JSON and the CSV, only when
// every output of the run was produced.
//
// Built without PLplot (FFSR_WITH_PLOT=OFF), available() is false and require_available() throws
// the one-line error every --plot gives.

namespace ffsr::cli::plot {

enum class Format { Png, Svg, Pdf };

/// True when this build draws figures (PLplot found at configure time).
bool available();
/// Throws InputError "<flag>: this ffsr-optimize was built without plotting ..." unless available().
void require_available(const std::string& flag);
/// "png", "svg" or "pdf"; InputError naming `flag` otherwise.
Format parse_format(const std::string& text, const std::string& flag);
const char* extension(Format f);
/// Checks that `dir` is an existing folder; InputError naming `flag` and the folder otherwise.
void check_folder(const std::string& dir, const std::string& flag);
/// The checks of a subcommand's --plot DIR and --plot-format FORMAT before any work: the format
/// always; when `dir` is not empty, that this build draws and that the folder exists. Returns the format.
Format check_request(const std::string& dir, const std::string& format);

/// The colour-blind-safe palette of Okabe and Ito (2008), in the order used for runs and laws:
/// blue, vermillion, bluish green, reddish purple, orange, sky blue, black -- and wine (Tol's muted
/// scheme) in place of Okabe-Ito's yellow, which is unreadable as a thin line on white.
constexpr int kPaletteSize = 8;
std::array<int, 3> palette(int i);

/// A curve or a set of markers in a 2-D panel.
struct Curve {
  std::string label;  ///< legend entry; empty: not in the legend
  std::vector<double> x, y;
  int color = 0;       ///< palette index
  int line_style = 1;  ///< PLplot line style 1..8 (1 solid, 2 short dashes, ...); 0: no line
  double width = 2.0;
  std::string symbol;  ///< glyph drawn at every point (e.g. "●", "*"); empty: none
  double symbol_scale = 1.0;
  double alpha = 1.0;  ///< opacity (1 opaque), for fading drawings
  bool fill = false;   ///< draw the closed polygon filled (with alpha)
};

/// Axes with curves. Limits empty: from the data (with a 5 % margin).
struct Panel {
  std::string title, xlabel, ylabel;
  std::vector<Curve> curves;
  bool equal_aspect = false;  ///< one metre is as long on both axes (drawings of the robot)
  bool log_x = false;
  std::vector<double> limits;   ///< {xmin, xmax, ymin, ymax} or empty
  bool legend_outside = false;  ///< legend to the right of the axes instead of inside
};

/// A curve in 3-D, drawn in an oblique projection with PLplot's 3-D box.
struct Curve3 {
  std::string label;
  std::vector<double> x, y, z;
  int color = 0;
  int line_style = 1;
  double width = 2.0;
  std::string symbol;
  double symbol_scale = 1.0;
  double alpha = 1.0;
};

struct Panel3 {
  std::string title, xlabel, ylabel, zlabel;
  std::vector<Curve3> curves;
  double altitude = 30, azimuth = 35;  ///< viewing angles, deg
};

/// Values on a rectangular 2-D grid: z[i * y.size() + j] at (x[i], y[j]). Filled colour levels,
/// contour lines and a colour bar (viridis, colour-blind safe).
struct HeatPanel {
  std::string title, xlabel, ylabel, zlabel;
  std::vector<double> x, y, z;
  int levels = 20;             ///< colour levels
  int contours = 10;           ///< contour lines
  std::vector<Curve> overlay;  ///< markers on top (for example the maximum)
  double zmin = 0, zmax = 0;   ///< colour range; equal: from the data
};

/// Coloured points in 3-D (the grid of Figure 8): c[k] gives the colour of (x[k], y[k], z[k]).
struct CloudPanel {
  std::string title, xlabel, ylabel, zlabel, clabel;
  std::vector<double> x, y, z, c;
  double altitude = 25, azimuth = 40;
};

using AnyPanel = std::variant<Panel, Panel3, HeatPanel, CloudPanel>;

/// One file: panels laid out in `rows` x `cols`, in reading order.
struct Figure {
  std::string name;   ///< file stem, e.g. "capture_plain"
  std::string title;  ///< page title above the panels (may be empty)
  int rows = 1, cols = 1;
  int width = 1000, height = 700;  ///< pixels (png), points (svg, pdf)
  std::vector<AnyPanel> panels;
};

/// Draws every figure as <name>.<ext> into a scratch folder inside `dir`, staged to be moved into
/// `dir` by Outputs::stage and Outputs::write (or by StagedFiles::commit). InputError naming the
/// folder or the file when something fails (the folder is left as it was).
StagedFiles draw(const std::vector<Figure>& figures, const std::string& dir, Format format);
/// draw, then the figures moved into `dir` at once: all or nothing. Returns the paths written.
std::vector<std::string> render(const std::vector<Figure>& figures, const std::string& dir, Format format);

}  // namespace ffsr::cli::plot
