// Figures (--plot): the plotting module and the pictures of the command, each picture decoded (PNG)
// or parsed (SVG) and checked against independent computations.
#include "cli/figures/figure_tools.hpp"
#include "cli/figures/figures.hpp"
#include "cli/figures/plot.hpp"
#include "support/image_check.hpp"
#include "support/paper.hpp"
#include "support/run_command.hpp"

#include "ffsr/parsers/urdf.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

// Figures (--plot): the plotting module and the pictures of the command. Every picture made here
// is decoded (PNG: size from IHDR, more than one colour, the long dark lines of the axes box) or
// parsed (SVG as XML). The drawings are checked against independent computations: the arm drawn at
// T ends where the planner's end-effector is, the attitude-drift curve ends at the planner's drift,
// the map's maximum sits at the stretched arm (Section 5.1), xi from the closed form against the
// exact peak. Bad inputs: a missing plot folder and an unknown format, one error line each.

namespace test_plot {

namespace {

namespace fs = std::filesystem;
using namespace ffsr;
using namespace ffsr::cli;
using ffsr::test::run_command;
using ffsr::test::TempDir;

const std::string kCli = FFSR_CLI;

/// A valid PNG of the expected size with content: many colours and the axes' straight lines.
void check_png(const std::string& path, uint32_t w, uint32_t h, size_t min_colors = 2) {
  INFO(path);
  const auto img = ffsr::test::decode_png(path);
  CHECK(img.width == w);
  CHECK(img.height == h);
  CHECK(ffsr::test::distinct_colors(img) >= min_colors);
  CHECK(ffsr::test::longest_dark_line(img, true) >= std::min(w, h) / 5);  // an axis box side
  CHECK(ffsr::test::longest_dark_line(img, false) >= std::min(w, h) / 5);
}

void check_svg(const std::string& path) {
  INFO(path);
  std::string root;
  const int paths = ffsr::test::svg_count(path, "path", root);
  CHECK(root == "svg");
  CHECK(paths > 20);  // axes, ticks, curves and glyphs are paths in cairo's SVG
}

/// The paper's 3-DOF robot and target (robots/paper_3dof.toml).
struct Paper3 {
  Model model = model_from_urdf_file(ffsr::test::kRobots + "paper_3dof.urdf", "ee");
  Target target;
  Paper3() {
    target.position = Vector3(2.75, 1.45, 0);
    target.angular_velocity = Vector3(0, 0, 2 * M_PI / 180);
  }
  /// The capture from joint angles (0, 150, -100) deg.
  CaptureProblem problem() const {
    CaptureProblem pb;
    pb.model = &model;
    pb.frame = model.end_effector();
    pb.theta = ffsr::test::deg({0, 150, -100});
    pb.target = target;
    return pb;
  }
  /// The planar position task.
  static CaptureTask task() {
    CaptureTask t;
    t.axes = {true, true, false};
    return t;
  }
  /// T = 180 s in steps of 0.2 s, the series recorded.
  static CaptureOptions options() {
    CaptureOptions o;
    o.duration = 180;
    o.step = 0.2;
    o.record_series = true;
    return o;
  }
};

/// M_ie over a grid of joint angles (deg), last axis fastest, evaluated directly with Eq. 14.
figures::Grid mie_grid(const Paper3& p, const std::vector<std::vector<double>>& axes) {
  figures::Grid g;
  g.axes = axes;
  for (size_t d = 0; d < axes.size(); ++d) g.axis_labels.push_back("θ" + std::to_string(d + 1) + " (deg)");
  Data data(p.model);
  const BasePose base;
  Eigen::VectorXd th = Eigen::VectorXd::Zero(3);
  const size_t n0 = axes[0].size(), n1 = axes[1].size(), n2 = axes.size() > 2 ? axes[2].size() : 1;
  for (size_t i = 0; i < n0; ++i)
    for (size_t j = 0; j < n1; ++j)
      for (size_t k = 0; k < n2; ++k) {
        th << axes[0][i], axes[1][j], axes.size() > 2 ? axes[2][k] : 0.0;
        g.values.push_back(integrated_effective_mass(p.model, data, base, th * (M_PI / 180),
                                                     p.model.end_effector(), p.target));
      }
  return g;
}

std::vector<double> range_deg(double a, double b, double step) {
  std::vector<double> v;
  for (double x = a; x <= b + 1e-9; x += step) v.push_back(x);
  return v;
}

}  // namespace

TEST_CASE("plot: format names and the folder check", "[plot]") {
  CHECK(plot::parse_format("svg", "--plot-format") == plot::Format::Svg);
  CHECK_THROWS_WITH(plot::parse_format("jpeg", "--plot-format"),
                    Catch::StartsWith("--plot-format: unknown format 'jpeg'; expected png, svg or pdf"));
  CHECK_THROWS_WITH(plot::check_folder("/nonexistent/ffsr", "--plot"),
                    Catch::Contains("--plot: folder '/nonexistent/ffsr' does not exist"));
  CHECK(plot::available());
}

TEST_CASE("map plots: 3-DOF M_ie slices and heat map and 3-D view with the maximum at the stretched arm",
          "[plot][paper]") {
  const Paper3 p;
  // the ranges of Figure 8 (theta1 in [-90, 90], theta2 and theta3 in [-120, 120] deg) at 10 deg;
  // Eq. 14 evaluated here
  const auto a1 = range_deg(-90, 90, 10), a2 = range_deg(-120, 120, 10);
  const figures::Grid g3 = mie_grid(p, {a1, a2, a2});
  const size_t imax = size_t(std::max_element(g3.values.begin(), g3.values.end()) - g3.values.begin());
  const size_t n = a2.size();
  // Section 5.1: the largest M_ie over the whole grid at theta = [0, 0, 0] deg
  CHECK(a1[imax / (n * n)] == 0.0);
  CHECK(a2[imax / n % n] == 0.0);
  CHECK(a2[imax % n] == 0.0);
  const plot::Figure slices = figures::map_slices(g3, {0, 0, 0}, "slices", "");
  CHECK_THAT(slices.title, Catch::Contains("at [0.0, 0.0, 0.0] deg"));
  REQUIRE(slices.panels.size() == 3);
  // each slice goes through [0, 0, 0]: its marked maximum is the grid maximum, at (0, 0)
  for (const auto& panel : slices.panels) {
    const auto& h = std::get<plot::HeatPanel>(panel);
    CHECK(h.overlay.at(0).x.at(0) == 0.0);
    CHECK(h.overlay.at(0).y.at(0) == 0.0);
    CHECK(*std::max_element(h.z.begin(), h.z.end()) == g3.values[imax]);
  }
  // two varied joints (theta1 = 0): a heat map with its maximum marked
  const figures::Grid g2 = mie_grid(p, {range_deg(-120, 120, 5), range_deg(-120, 120, 5)});
  const plot::Figure heat = figures::map_heat(g2, "heat", "");
  const auto& hp = std::get<plot::HeatPanel>(heat.panels.at(0));
  CHECK(hp.overlay.at(0).x.at(0) == 0.0);
  CHECK(hp.overlay.at(0).y.at(0) == 0.0);

  TempDir dir;
  const auto png =
      plot::render({heat, slices, figures::map_cloud(g3, "cloud", "")}, dir.str(), plot::Format::Png);
  REQUIRE(png.size() == 3);
  check_png(dir / "heat.png", 1000, 700, 16);  // the colour levels
  check_png(dir / "slices.png", 1400, 420, 16);
  check_png(dir / "cloud.png", 1000, 700, 16);
  const auto svg = plot::render({slices}, dir.str(), plot::Format::Svg);
  check_svg(dir / "slices.svg");
  CHECK(dir.entries() == std::vector<std::string>{"cloud.png", "heat.png", "slices.png", "slices.svg"});

  figures::Grid bad = g2;
  bad.values.pop_back();
  CHECK_THROWS_AS(figures::map_heat(bad, "x", ""), InputError);
}

TEST_CASE(
    "capture figures: the drawn arm at T meets the planner's end-effector and the drift curve its drift",
    "[plot]") {
  const Paper3 p;
  const CaptureProblem pb = p.problem();
  const CaptureTask task = Paper3::task();
  CaptureOptions opt = Paper3::options();
  const CaptureResult plain = plan_capture(pb, task, opt);
  opt.gain = -0.01;
  const CaptureResult optimized = plan_capture(pb, task, opt);
  const auto figs = figures::capture(p.model, pb.frame, pb.target, opt.duration,
                                     {{"plain", &plain, task}, {"optimized", &optimized, task}});
  REQUIRE(figs.size() == 4);  // one drawing per run, histories, joints
  for (size_t r = 0; r < 2; ++r) {
    const CaptureResult& res = r == 0 ? plain : optimized;
    REQUIRE(figs[r].panels.size() == 1);  // planar robot: one view, in its plane
    const auto& panel = std::get<plot::Panel>(figs[r].panels[0]);
    CHECK(panel.equal_aspect);
    // the last (opaque) line of the arm's colour before its joint dots is the link to the end-effector
    const plot::Curve* ee_link = nullptr;
    for (const auto& c : panel.curves)
      if (c.color == int(r) && c.alpha == 1.0 && c.line_style > 0 && c.symbol.empty()) ee_link = &c;
    REQUIRE(ee_link);
    CHECK(ee_link->x.back() == Approx(res.end_effector.x()).margin(1e-9));
    CHECK(ee_link->y.back() == Approx(res.end_effector.y()).margin(1e-9));
    // the target's contact point is the planner's capture point
    bool found = false;
    for (const auto& c : panel.curves)
      if (c.label.rfind("target at T", 0) == 0 && !c.symbol.empty()) {
        found = true;
        CHECK(c.x.at(0) == Approx(res.capture_point.x()).margin(1e-12));
        CHECK(c.y.at(0) == Approx(res.capture_point.y()).margin(1e-12));
      }
    CHECK(found);
  }
  // histories: M_ie, F_max, attitude drift, sigma_min; the drift at T is the planner's
  const auto& drift = std::get<plot::Panel>(figs[2].panels.at(2));
  CHECK(drift.curves.at(0).y.back() == Approx(plain.base_attitude_drift * 180 / M_PI).epsilon(1e-9));
  CHECK(drift.curves.at(1).y.back() == Approx(optimized.base_attitude_drift * 180 / M_PI).epsilon(1e-9));
  const auto& sigma = std::get<plot::Panel>(figs[2].panels.at(3));
  for (size_t r = 0; r < 2; ++r) {
    const double smin = *std::min_element(sigma.curves[r].y.begin(), sigma.curves[r].y.end());
    // the planner also sees the RK4 stages, so its minimum is at most the recorded samples' one
    CHECK(smin >= (r == 0 ? plain : optimized).min_singular_value - 1e-12);
    CHECK(smin == Approx((r == 0 ? plain : optimized).min_singular_value).epsilon(0.01));
  }
  TempDir dir;
  plot::render(figs, dir.str(), plot::Format::Png);
  for (const char* f : {"capture_plain.png", "capture_optimized.png", "histories.png", "joints.png"})
    check_png(dir / f, 1000, 700);
}

/// The distance in the x-y plane from (x, y) to the segment a-b projected on it.
double planar_segment_distance(double x, double y, const Vector3& a, const Vector3& b) {
  const Eigen::Vector2d p(x, y), a2 = a.head<2>(), d = b.head<2>() - a2;
  const double t = d.squaredNorm() > 0 ? std::clamp((p - a2).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - a2 - t * d).norm();
}

TEST_CASE("capture figures with shapes: the outlines lie on the shapes, the closest pair is marked",
          "[plot]") {
  const Paper3 p;
  const CaptureProblem pb = p.problem();
  const CaptureTask task = Paper3::task();
  CaptureOptions opt = Paper3::options();
  const CaptureResult run = plan_capture(pb, task, opt);
  const double r = 0.05;
  const Vector3 bus(0.6, 0.5, 0.4), target_size(0.3, 0.4, 0.5);
  figures::SceneShapes shapes;
  shapes.bodies = robot_geometry(p.model, {}, {r}, {bus.x(), bus.y(), bus.z()}).shapes;
  shapes.target = Shape::box(target_size, Pose{Vector3(0.02, -0.03, 0), Matrix3::Identity()});
  ClearanceReport rep;  // a closest pair at t = 90 s (the marker is drawn from the report as given)
  rep.overall.distance = 0.1234;
  rep.overall.pair = "link2 - target";
  rep.overall.time = 90;
  rep.overall.p_a = Vector3(2.1, 1.2, 0);
  rep.overall.p_b = Vector3(2.2, 1.25, 0);
  figures::CaptureRun cr{"global", &run, task};
  cr.clearance = &rep;
  const auto figs = figures::capture(p.model, pb.frame, pb.target, opt.duration, {cr}, &shapes);
  const auto& panel = std::get<plot::Panel>(figs.at(0).panels.at(0));

  // the bodies at T, independently: the bus's corners and the links' centre lines (joint origins)
  Data d(p.model);
  forward_kinematics(p.model, d, run.series.back().base, run.series.back().theta);
  std::vector<std::pair<Vector3, Vector3>> axes;  // each moving body's segment to its child / end-effector
  for (int b = 1; b < p.model.nb(); ++b) {
    const bool has_child = b + 1 < p.model.nb();
    axes.emplace_back(d.p[size_t(b)], has_child ? d.p[size_t(b + 1)] : run.end_effector);
  }
  int shape_curves = 0, bus_curves = 0, capsule_curves = 0, faint = 0;
  for (const plot::Curve& c : panel.curves) {
    if (c.alpha == 0.3) ++faint;
    if (c.alpha != 0.7) continue;
    ++shape_curves;
    // a bus edge: every point on the box's surface, two coordinates at their half side (an edge)
    bool on_bus = true;
    for (size_t i = 0; i < c.x.size(); ++i) {
      const Vector3 local = d.R[0].transpose() * (Vector3(c.x[i], c.y[i], 0) - d.p[0]);
      on_bus = on_bus && std::abs(local.x()) <= 0.5 * bus.x() + 1e-9 &&
               std::abs(local.y()) <= 0.5 * bus.y() + 1e-9 &&
               (std::abs(std::abs(local.x()) - 0.5 * bus.x()) < 1e-9 ||
                std::abs(std::abs(local.y()) - 0.5 * bus.y()) < 1e-9);
    }
    if (on_bus) {
      ++bus_curves;
      continue;
    }
    // a capsule's silhouette: within r of one link's axis, and r from it at its farthest point
    bool on_capsule = false;
    for (const auto& [a, b] : axes) {
      double far = 0;
      bool inside = true;
      for (size_t i = 0; i < c.x.size(); ++i) {
        const double dist = planar_segment_distance(c.x[i], c.y[i], a, b);
        far = std::max(far, dist);
        inside = inside && dist <= r + 1e-9;
      }
      on_capsule = on_capsule || (inside && std::abs(far - r) < 1e-9);
    }
    CHECK(on_capsule);
    capsule_curves += on_capsule;
  }
  CHECK(bus_curves == 6);  // its two faces as closed lines and four side edges, seen from above
  CHECK(capsule_curves == 4 * int(axes.size()));  // two end circles and two sides per link
  CHECK(shape_curves == bus_curves + capsule_curves);
  CHECK(faint == shape_curves + 6);  // at t = 90 s: the same shapes and the target's box

  // the target's box at T: its lines (before the normal's arrow) on its edges, in the target frame
  const Target tT = propagate_target(p.target, opt.duration);
  std::vector<const plot::Curve*> target_lines;
  for (const plot::Curve& c : panel.curves)
    if (c.color == 3 && c.symbol.empty()) target_lines.push_back(&c);
  REQUIRE(target_lines.size() == 6 + 2);
  for (size_t k = 0; k < 6; ++k)
    for (size_t i = 0; i < target_lines[k]->x.size(); ++i) {
      const Vector3 local =
          tT.rotation().transpose() *
              (Vector3(target_lines[k]->x[i], target_lines[k]->y[i], tT.position.z()) - tT.position) -
          Vector3(0.02, -0.03, 0);
      const Eigen::Array2d rel = local.head<2>().cwiseAbs().array() / (0.5 * target_size.head<2>().array());
      CHECK(rel.maxCoeff() == Approx(1.0).epsilon(1e-9));
    }
  // the closest pair: its nearest points joined, the legend naming the pair, distance and time
  const plot::Curve* marker = nullptr;
  for (const plot::Curve& c : panel.curves)
    if (c.label == "closest: 0.123 m") marker = &c;
  REQUIRE(marker);
  CHECK(panel.title == "the arm at 8 instants; closest: link2 - target at t = 90.0 s");
  CHECK(marker->x == std::vector<double>{2.1, 2.2});
  CHECK(marker->y == std::vector<double>{1.2, 1.25});
  TempDir dir;
  plot::render(figs, dir.str(), plot::Format::Png);
  check_png(dir / "capture_global.png", 1000, 700);
}

TEST_CASE("main job with --plot: the 3-DOF scenario's figures as PNG and SVG", "[plot][cli]") {
  TempDir dir;
  fs::create_directory(dir / "png");
  fs::create_directory(dir / "svg");
  auto r = run_command({kCli, "--plot", dir / "png", "--quiet"});
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(r.out.find("With optimization") != std::string::npos);
  for (const char* f : {"capture_plain.png", "capture_optimized.png", "histories.png", "joints.png"})
    check_png(dir / (std::string("png/") + f), 1000, 700);
  r = run_command({kCli, "--plot", dir / "svg", "--plot-format", "svg", "--quiet"});
  REQUIRE(r.exit_code == 0);
  for (const char* f : {"capture_plain.svg", "capture_optimized.svg", "histories.svg", "joints.svg"})
    check_svg(dir / (std::string("svg/") + f));
}

TEST_CASE("contact --plot (Figure 3) and xi (Figures 4-6)", "[plot][cli]") {
  TempDir dir;
  const std::string urdf = ffsr::test::kRobots + "paper_3dof.urdf";
  auto r = run_command(
      {kCli, "contact", "--urdf", urdf, "--joints-deg=0,90,-90", "--model", "all", "--plot", dir.str()});
  REQUIRE(r.exit_code == 0);
  check_png(dir / "contact.png", 1000, 700, 8);
  r = run_command({kCli, "xi", "--points", "5", "--csv", dir / "xi.csv", "--plot", dir.str()});
  REQUIRE(r.exit_code == 0);
  for (const char* f : {"xi_stiffness.png", "xi_approach_speed.png", "xi_restitution.png"})
    check_png(dir / f, 1000, 700, 8);
  // the CSV: xi does not depend on K nor on delta_dot^- (Figures 4 and 5), and equals
  // 1 - F'_max / F_max from the closed form against the exact peak of Eq. 16 (M_ie = 1 kg)
  std::ifstream in(dir / "xi.csv");
  std::string line;
  std::getline(in, line);
  CHECK(line == "study,parameter,law,xi_percent");
  std::map<std::string, std::vector<double>> by_study_law;
  int rows = 0;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string study, x, law, xi;
    std::getline(s, study, ',');
    std::getline(s, x, ',');
    std::getline(s, law, ',');
    std::getline(s, xi, ',');
    by_study_law[study + "/" + law].push_back(std::stod(xi));
    ContactParams cp;
    double v = 0.2;
    if (study == "stiffness") cp.K = std::stod(x);
    if (study == "approach_speed") v = std::stod(x);
    if (study == "restitution") cp.c_r = std::stod(x);
    const AnyContactLaw l = make_contact_law(law, cp, v);
    const double expected = 100.0 * (1.0 - max_force_closed_form(l, 1.0) / max_force_exact(l, 1.0));
    CHECK(std::stod(xi) == Approx(expected).margin(1e-9));
    ++rows;
  }
  CHECK(rows == 3 * 5 * 8);
  for (const auto& [key, xs] : by_study_law)
    if (key.rfind("restitution", 0) != 0)
      for (double x : xs) CHECK(x == Approx(xs.front()).margin(1e-9));
}

TEST_CASE("map --plot: one, two and three varied joints -- the CSV beside the pictures", "[plot][cli][map]") {
  TempDir dir;
  const std::string urdf = ffsr::test::kRobots + "paper_3dof.urdf";
  const std::vector<std::string> base{kCli, "map", "--urdf", urdf, "--joints-deg", "0,0,0", "--quiet"};
  auto map = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return run_command(a);
  };
  // three joints: the slices through theta = 0 (Figure 9) and the 3-D view (Figure 8)
  auto r = map({"--vary", "1,2,3", "--step-deg", "10", "--csv", dir / "m3.csv", "--plot", dir.str()});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  check_png(dir / "map_slices.png", 1400, 420, 16);
  check_png(dir / "map_cloud.png", 1000, 700, 16);
  CHECK(r.out.find("wrote " + (dir / "map_slices.png")) != std::string::npos);
  // two joints: the heat map (Figure 9), as SVG
  r = map({"--vary", "2,3", "--step-deg", "5", "--csv", dir / "m2.csv", "--plot", dir.str(), "--plot-format",
           "svg"});
  REQUIRE(r.exit_code == 0);
  check_svg(dir / "map.svg");
  // one joint: M_ie against the angle
  TempDir one;
  r = map({"--vary", "3", "--step-deg", "1", "--csv", one / "m1.csv", "--plot", one.str()});
  REQUIRE(r.exit_code == 0);
  check_png(one / "map.png", 1000, 700);
  CHECK(fs::exists(one / "m1.csv"));
}

TEST_CASE("map --plot bad inputs: one error line naming the flag, no CSV and no picture",
          "[plot][cli][map][errors]") {
  const std::string urdf3 = ffsr::test::kRobots + "paper_3dof.urdf";
  const std::string urdf7 = ffsr::test::kRobots + "paper_7dof.urdf";
  struct Case {
    std::vector<std::string> extra;
    std::string urdf, joints, message;
  };
  const std::vector<Case> cases = {
      {{"--vary", "1,2,3", "--shard", "1/3", "--plot", "."},
       urdf3,
       "0,0,0",
       "--plot: a shard holds part of the grid"},
      {{"--vary", "1,2,3,4", "--step-deg", "90", "--plot", "."},
       urdf7,
       "0,0,0,0,0,0,0",
       "--plot: pictures are drawn for 1 to 3"},
      {{"--vary", "1,2,3", "--step-deg", "10", "--slice-deg", "0,0", "--plot", "."},
       urdf3,
       "0,0,0",
       "--slice-deg"},
      {{"--vary", "1,2", "--slice-deg", "0,0", "--plot", "."},
       urdf3,
       "0,0,0",
       "--slice-deg: slices are drawn for three"},
      {{"--vary", "1,2", "--plot", "no_such_folder"},
       urdf3,
       "0,0,0",
       "--plot: folder 'no_such_folder' does not exist"},
      {{"--vary", "1,2", "--plot", ".", "--plot-format", "gif"},
       urdf3,
       "0,0,0",
       "--plot-format: unknown format 'gif'"},
      {{"--vary", "1,2,3", "--step-deg", "0.5", "--plot", "."},
       urdf3,
       "0,0,0",
       "--plot: the grid has 373248000 points"},
  };
  for (const auto& c : cases) {
    TempDir dir;
    std::vector<std::string> a{kCli,     "map",   "--urdf", c.urdf,   "--joints-deg",
                               c.joints, "--csv", "m.csv",  "--quiet"};
    a.insert(a.end(), c.extra.begin(), c.extra.end());
    const auto r = run_command(a, dir.str());
    INFO(c.message << "\n" << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.rfind("ffsr-optimize: error: " + c.message, 0) == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(dir.entries().empty());
  }
}

TEST_CASE("closed-loop --plot: the closed loop beside its plan, the JSON's numbers on the picture's curves",
          "[plot][cli][controller]") {
  TempDir dir;
  // the built-in 3-DOF scenario, the paper's plan, the exact target, 20 Hz control
  const auto r = run_command({kCli, "closed-loop", "--control-rate", "20", "--estimate-rate", "1", "--plot",
                              dir.str(), "--json", dir / "cl.json", "--quiet"});
  REQUIRE(r.exit_code == 0);
  check_png(dir / "closed_loop.png", 1200, 900, 8);
  std::ifstream in(dir / "cl.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["closed_loop"]["capture_error"].get<double>() < 1e-4);        // the exact target: tracked
  CHECK(j["closed_loop"]["max_torque"].get<double>() <= 100.0 + 1e-9);  // the default torque limit
}

TEST_CASE("closed-loop figure: one curve per joint and run, the limit lines, equal lengths required",
          "[plot]") {
  CaptureResult open;
  for (int i = 0; i <= 4; ++i) {
    CaptureSample x;
    x.t = i;
    x.theta = Eigen::Vector2d(0.1 * i, -0.1 * i);
    open.series.push_back(x);
  }
  figures::ClosedLoopSeries s;
  s.joint_names = {"a", "b"};
  s.torque_limit = 50;
  s.open_loop = &open;
  for (int i = 0; i <= 8; ++i) {
    s.t.push_back(0.5 * i);
    s.theta.push_back(Eigen::Vector2d(0.05 * i, -0.05 * i));
    s.lag.push_back(Eigen::Vector2d(1e-3, -1e-3));
    s.torque.push_back(Eigen::Vector2d(10.0, -60.0));
    s.reference_error.push_back(2e-3);
  }
  const plot::Figure f = figures::closed_loop(s);
  REQUIRE(f.panels.size() == 4);
  const auto& angles = std::get<plot::Panel>(f.panels[0]);
  CHECK(angles.curves.size() == 4);  // closed loop and plan per joint
  CHECK(angles.curves[0].y.back() == Approx(0.4 * 180 / M_PI));
  CHECK(angles.curves[1].x.size() == 5);
  CHECK(std::get<plot::Panel>(f.panels[1]).curves.front().y.front() == Approx(2.0));  // mm
  CHECK(std::get<plot::Panel>(f.panels[2]).curves.size() == 4);  // two joints, +limit, -limit (60 > 0.3 x 50)
  s.reference_error.assign(s.t.size(), 2e-6);                    // small errors in micrometres
  CHECK(std::get<plot::Panel>(figures::closed_loop(s).panels[1]).curves.front().y.front() == Approx(2.0));
  s.torque.assign(s.t.size(), Eigen::Vector2d(1.0, -1.0));  // far below the limit: no limit lines
  CHECK(std::get<plot::Panel>(figures::closed_loop(s).panels[2]).curves.size() == 2);
  CHECK(std::get<plot::Panel>(f.panels[3]).curves[1].y.front() == Approx(-1e-3 * 180 / M_PI));  // deg/s
  s.torque.pop_back();
  CHECK_THROWS_AS(figures::closed_loop(s), InputError);
}

/// Two runs of a 2-joint stack: rates decaying as exp(-t), torques near joint 2's limit only.
figures::DetumbleSeries detumble_series(bool wheels) {
  figures::DetumbleSeries s;
  s.joint_names = {"a", "b"};
  s.torque_limit = {100, 10};
  s.rest_rate = 0.01;
  s.wheel_bound = wheels ? 5 : 0;
  s.stack_rate = wheels;
  for (int r = 0; r < 2; ++r) {
    figures::DetumbleSeries::Run run;
    run.label = r == 0 ? "plain" : "global";
    run.color = 2 * r;
    for (int i = 0; i <= 10; ++i) {
      const double t = 0.5 * i, e = std::exp(-t);
      run.t.push_back(t);
      run.rate.push_back(Eigen::Vector2d(0.1 * e, -0.2 * e));
      run.torque.push_back(Eigen::Vector2d(1.0 * e, -8.0 * e));
      run.joint_rate.push_back(0.2 * e);
      run.relative_rate.push_back(0.1 * e);
      run.stack_rate.push_back(0.05 * e);
      run.force.push_back(3 * e);
      run.moment.push_back(2 * e);
      run.attitude.push_back(0.01 * t);
      run.energy.push_back(e * e);
      run.wheel.push_back(Eigen::Vector3d(1, -2, 3) * (1 - e));
    }
    s.runs.push_back(run);
  }
  return s;
}

TEST_CASE("detumble figure: joints by colour and runs by style, the threshold, the limits near, the wheels",
          "[plot][detumble]") {
  auto s = detumble_series(false);
  const plot::Figure f = figures::detumble(s);
  CHECK(f.name == "detumble");
  REQUIRE(f.panels.size() == 6);
  const auto& rates = std::get<plot::Panel>(f.panels[0]);
  REQUIRE(rates.curves.size() == 2 * 2 + 2);              // joint x run, then the runs' styles in black
  CHECK(rates.curves[1].color == rates.curves[0].color);  // joint a, both runs: one colour
  CHECK(rates.curves[1].line_style != rates.curves[0].line_style);  // ... two styles
  CHECK(rates.curves[2].y.front() == Approx(-0.2 * 180 / M_PI));    // deg/s
  CHECK(rates.curves[0].label == "a");
  CHECK(rates.curves[1].label.empty());
  CHECK(rates.curves[5].label == "global");
  CHECK(rates.curves[5].line_style == 2);
  const auto& rest = std::get<plot::Panel>(f.panels[1]);
  const plot::Curve& threshold = rest.curves.back();
  CHECK(threshold.label == "rest threshold");
  CHECK(threshold.y == std::vector<double>{0.01 * 180 / M_PI, 0.01 * 180 / M_PI});
  CHECK(rest.curves.front().color == 0);  // runs by colour: the plain run's
  CHECK(rest.curves[2].color == 2);
  // joint b's torque peaks at 80 % of its 10 N m limit: its lines; joint a's at 1 % of 100: none
  const auto& torque = std::get<plot::Panel>(f.panels[2]);
  long limits = 0;
  for (const auto& c : torque.curves) {
    limits += c.color == figures::tools::kBlack;
    CHECK(c.y.front() != Approx(100.0));
  }
  CHECK(limits == 2);
  CHECK(torque.curves[4].label == "limit ±10 N m (joint 2)");
  CHECK(std::get<plot::Panel>(f.panels[3]).curves.front().y.front() == Approx(3.0));  // N
  CHECK(std::get<plot::Panel>(f.panels[4]).curves.front().y.back() == Approx(0.05 * 180 / M_PI));
  CHECK(std::get<plot::Panel>(f.panels[5]).ylabel == "energy (J)");

  const plot::Figure w = figures::detumble(detumble_series(true));
  const auto& wheels = std::get<plot::Panel>(w.panels[5]);
  CHECK(wheels.curves.back().label == "bound");
  CHECK(wheels.curves.back().y.front() == 5.0);
  CHECK(wheels.curves[1].y.back() == Approx(2 * (1 - std::exp(-5.0))));          // |h_y| of the plain run
  CHECK(std::get<plot::Panel>(w.panels[1]).curves.size() == 3 * 2 + 2 + 3 + 1);  // 3 rates, keys, threshold

  s.runs[1].torque.pop_back();
  CHECK_THROWS_WITH(figures::detumble(s), Catch::Contains("run 'global'"));
  s = detumble_series(false);
  s.torque_limit.pop_back();
  CHECK_THROWS_AS(figures::detumble(s), InputError);
}

TEST_CASE("detumble --plot: the post-capture runs of the three captures in one figure",
          "[plot][cli][detumble]") {
  TempDir dir;
  const auto r = run_command({kCli, "detumble", "--run", "all", "--joint-torque-limit", "20", "--plot",
                              dir.str(), "--json", dir / "d.json", "--quiet"});
  REQUIRE(r.exit_code == 0);
  check_png(dir / "detumble.png", 1200, 1250, 8);
  std::ifstream in(dir / "d.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["runs"].size() == 3);
  // SVG, from the scenario's configuration of the 7-DOF detumble scenario
  fs::create_directory(dir / "svg");
  const auto s = run_command({kCli, "detumble", "--config", ffsr::test::kRobots + "paper_7dof_detumble.toml",
                              "--plot", dir / "svg", "--plot-format", "svg", "--quiet"});
  REQUIRE(s.exit_code == 0);
  check_svg(dir / "svg/detumble.svg");
}

TEST_CASE("pareto figure: the front, its ends and knee, the runs near it beside it and every run below",
          "[plot][pareto]") {
  figures::ParetoSeries s;
  s.mass = {1.0, 1.1, 1.2, 1.4};
  s.rate = {4e-3, 2e-3, 1e-3, 0.0};
  s.knee = 2;
  s.runs = {{"near", 1.05, 3e-3}, {"far", 9.0, 5e-2}};
  const plot::Figure f = figures::pareto(s);
  CHECK(f.name == "pareto");
  REQUIRE(f.panels.size() == 2);
  const auto& front = std::get<plot::Panel>(f.panels[0]);
  const auto& wide = std::get<plot::Panel>(f.panels[1]);
  // front, the two ends, the knee, then the runs: only the near one beside the front; below, the
  // front as one line and every run
  REQUIRE(front.curves.size() == 5);
  REQUIRE(wide.curves.size() == 3);
  CHECK(wide.curves[0].x == s.mass);
  CHECK(front.curves[0].x == s.mass);
  CHECK(front.curves[0].y == s.rate);
  CHECK(front.curves[1].x == std::vector<double>{1.0});
  CHECK(front.curves[2].y == std::vector<double>{0.0});
  CHECK(front.curves[3].x == std::vector<double>{1.2});
  CHECK(front.curves[3].label.rfind("knee: 1.2000 kg, 1.00e-03 deg/s", 0) == 0);
  CHECK(front.curves[4].label.rfind("near: 1.0500 kg", 0) == 0);
  CHECK(wide.curves[1].label.rfind("near: 1.0500 kg", 0) == 0);
  CHECK(wide.curves[2].label.rfind("far: 9.0000 kg, 5.00e-02 deg/s", 0) == 0);
  for (const auto& c : front.curves) CHECK(c.label.find("far") == std::string::npos);

  s.runs.pop_back();  // every run near the front: one panel
  CHECK(figures::pareto(s).panels.size() == 1);
  // a post-capture axis (pareto --axis): its label, its name and unit in the legend
  figures::ParetoSeries t = s;
  t.rate = {4.6, 4.4, 4.0, 3.9};
  t.y_label = "post-capture time-to-rest (s)";
  t.y_name = "time-to-rest";
  t.y_unit = "s";
  const plot::Figure g = figures::pareto(t);
  const auto& tp = std::get<plot::Panel>(g.panels[0]);
  CHECK(tp.ylabel == "post-capture time-to-rest (s)");
  CHECK(tp.curves[2].label == "least time-to-rest: 1.4000 kg, 3.900 s");
  CHECK(tp.curves[3].label == "knee: 1.2000 kg, 4.000 s");
  s.runs.push_back({"a quarter beyond the front's rate", 1.2, 5.01e-3});
  CHECK(figures::pareto(s).panels.size() == 2);

  auto bad = s;
  bad.knee = 4;
  CHECK_THROWS_WITH(figures::pareto(bad), Catch::Contains("knee index 4"));
  bad = s;
  bad.rate.pop_back();
  CHECK_THROWS_AS(figures::pareto(bad), InputError);
  bad = s;
  bad.mass = {};
  bad.rate = {};
  CHECK_THROWS_AS(figures::pareto(bad), InputError);
  bad = s;
  bad.rate[1] = std::nan("");
  CHECK_THROWS_WITH(figures::pareto(bad), Catch::Contains("front point 1"));
  bad = s;
  bad.runs[0].mass = -1;
  CHECK_THROWS_WITH(figures::pareto(bad), Catch::Contains("near"));
}

TEST_CASE("pareto --plot: the 7-DOF front with its knee and the three runs drawn, the JSON beside it",
          "[plot][cli][pareto]") {
  TempDir dir;
  const auto r = run_command({kCli, "pareto", "--config", ffsr::test::kRobots + "paper_7dof_position.toml",
                              "--plot", dir.str(), "--json", dir / "front.json"});
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(r.out.find("wrote " + (dir / "pareto.png")) != std::string::npos);
  // the plain run (17 kg) is far from the front (1.28 to 1.31 kg): two panels, one above the other
  check_png(dir / "pareto.png", 1200, 1100, 8);
  const auto img = ffsr::test::decode_png(dir / "pareto.png");
  // the knee (vermillion) and the three runs (green, purple, orange) are drawn as filled markers
  for (int colour : {1, 2, 3, 4}) {
    const auto c = plot::palette(colour);
    const uint32_t want = uint32_t(c[0]) << 16 | uint32_t(c[1]) << 8 | uint32_t(c[2]);
    long pixels = 0;
    for (uint32_t y = 0; y < img.height; ++y)
      for (uint32_t x = 0; x < img.width; ++x) pixels += img.rgb(x, y) == want;
    INFO("palette colour " << colour);
    CHECK(pixels >= 30);
  }
  std::ifstream in(dir / "front.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["front"].size() >= 20);
  CHECK(j["runs"]["baseline"]["integrated_effective_mass"].get<double>() > 10.0);

  // SVG of the built-in 3-DOF scenario
  fs::create_directory(dir / "svg");
  const auto s = run_command({kCli, "pareto", "--plot", dir / "svg", "--plot-format", "svg"});
  REQUIRE(s.exit_code == 0);
  check_svg(dir / "svg/pareto.svg");
}

TEST_CASE("plot bad inputs: a missing folder or an unknown format give one error line and no output",
          "[plot][cli]") {
  TempDir dir;
  const std::string missing = dir / "no_such_folder";
  const std::string urdf = ffsr::test::kRobots + "paper_3dof.urdf";
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{kCli, "--plot", missing, "--quiet"}, "--plot: folder '" + missing + "' does not exist"},
      {{kCli, "--plot", dir.str(), "--plot-format", "gif", "--quiet"}, "--plot-format: unknown format 'gif'"},
      {{kCli, "contact", "--urdf", urdf, "--joints-deg=0,90,-90", "--plot", missing},
       "--plot: folder '" + missing},
      {{kCli, "contact", "--urdf", urdf, "--joints-deg=0,90,-90", "--plot", dir.str(), "--plot-format",
        "bmp"},
       "--plot-format: unknown format 'bmp'"},
      {{kCli, "xi", "--plot", missing}, "--plot: folder '" + missing},
      {{kCli, "closed-loop", "--plot", missing, "--quiet"}, "--plot: folder '" + missing},
      {{kCli, "pareto", "--plot", missing, "--json", dir / "front.json"}, "--plot: folder '" + missing},
      {{kCli, "pareto", "--plot", dir.str(), "--plot-format", "gif"}, "--plot-format: unknown format 'gif'"},
      {{kCli, "detumble", "--joint-torque-limit", "20", "--plot", missing}, "--plot: folder '" + missing},
      {{kCli, "detumble", "--joint-torque-limit", "20", "--plot", dir.str(), "--plot-format", "gif"},
       "--plot-format: unknown format 'gif'"},
      {{kCli, "xi", "--points", "1"}, "--points: expected 2 to 100000, got 1"},
  };
  for (const auto& c : cases) {
    INFO(c.args.back());
    const auto r = run_command(c.args);
    CHECK(r.exit_code == 2);
    CHECK(r.out.empty());
    CHECK(r.err.rfind("ffsr-optimize: error: " + c.message, 0) == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  }
  CHECK(dir.entries().empty());  // nothing written, no temporary folder left
}

}  // namespace test_plot
