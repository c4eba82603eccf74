// src/cli/figures/capture.cpp -- the capture figures of figures.hpp: the arm along its runs, the
// histories and the joint angles (no PLplot here: plain data).
#include "figures/figure_tools.hpp"
#include "figures/figures.hpp"

#include "ffsr/algorithm/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

namespace ffsr::cli::figures {
namespace {

using namespace tools;  // str, Curve, Panel, fixed, labelled, kBlack

constexpr int kInstants = 8;
constexpr int kTargetColor = 3;           // reddish purple: runs use 0, 1, 2
constexpr int kReconfigurationColor = 4;  // orange: the end-effector's path in a reconfiguration
constexpr int kClosestColor = 7;          // wine: the closest pair

/// Points of one drawing in the inertial frame: polylines (each a list of 3-D points) and dots.
struct Drawing {
  std::vector<std::vector<Vector3>> lines;
  std::vector<Vector3> dots;
};

/// Adds the outline of a box (centre c, axes the columns of R, half sides h) to a drawing: the
/// rectangle in its x-y plane when `planar`, else its twelve edges.
void add_box(Drawing& d, const Vector3& c, const Matrix3& R, const Vector3& h, bool planar) {
  auto corner = [&](double a, double b, double z) {
    return Vector3(c + R * Vector3(a * h.x(), b * h.y(), z * h.z()));
  };
  auto square = [&](double z) {
    return std::vector<Vector3>{corner(-1, -1, z), corner(1, -1, z), corner(1, 1, z), corner(-1, 1, z),
                                corner(-1, -1, z)};
  };
  if (planar) {
    d.lines.push_back(square(0));
    return;
  }
  for (int z : {-1, 1}) d.lines.push_back(square(z));
  for (int a : {-1, 1})
    for (int b : {-1, 1}) d.lines.push_back({corner(a, b, -1), corner(a, b, 1)});
}

/// The arc c + r (cos a e1 + sin a e2), a from `from` to `to` (a full circle: 48 segments).
std::vector<Vector3> arc(const Vector3& c, const Vector3& e1, const Vector3& e2, double r, double from = 0,
                         double to = 2 * M_PI) {
  const int n = std::max(2, static_cast<int>(std::ceil(48 * (to - from) / (2 * M_PI))));
  std::vector<Vector3> pts;
  for (int i = 0; i <= n; ++i) {
    const double a = from + (to - from) * double(i) / double(n);
    pts.push_back(c + r * (std::cos(a) * e1 + std::sin(a) * e2));
  }
  return pts;
}

/// A collision shape's outlines: `top` as seen along z (its silhouette, for the x-y views) and
/// `oblique` as a wireframe (for the 3-D view).
struct ShapeDrawing {
  Drawing top, oblique;
};

/// Adds shape `s` at world pose P (the carrying frame's pose times s.pose) to both outlines.
void add_shape(ShapeDrawing& d, const Shape& s, const Pose& P) {
  const Vector3 c = P.p, ex = Vector3::UnitX(), ey = Vector3::UnitY(), ez = Vector3::UnitZ();
  if (s.kind == Shape::Kind::Box) {
    add_box(d.top, c, P.R, 0.5 * s.size, false);
    add_box(d.oblique, c, P.R, 0.5 * s.size, false);
    return;
  }
  if (s.kind == Shape::Kind::Sphere) {
    d.top.lines.push_back(arc(c, ex, ey, s.radius));
    for (const auto& [e1, e2] : {std::pair{ex, ey}, std::pair{ey, ez}, std::pair{ez, ex}})
      d.oblique.lines.push_back(arc(c, e1, e2, s.radius));
    return;
  }
  // cylinder or capsule: the axis a (local z) from e0 to e1
  const bool capsule = s.kind == Shape::Kind::Capsule;
  const double r = s.radius;
  const Vector3 a = P.R.col(2), e0 = c - 0.5 * s.length * a, e1 = c + 0.5 * s.length * a;
  const Vector3 u = a.unitOrthogonal(), v = a.cross(u);
  for (const Vector3& e : {e0, e1}) d.oblique.lines.push_back(arc(e, u, v, r));
  for (const Vector3& w : {u, Vector3(-u), v, Vector3(-v)})
    d.oblique.lines.push_back({e0 + r * w, e1 + r * w});
  if (capsule)  // the caps: two half circles over each end
    for (const Vector3& w : {u, v}) {
      d.oblique.lines.push_back(arc(e1, a, w, r, -M_PI / 2, M_PI / 2));
      d.oblique.lines.push_back(arc(e0, Vector3(-a), w, r, -M_PI / 2, M_PI / 2));
    }
  // silhouette along z: a capsule's end circles in the x-y plane, a cylinder's end circles (ellipses
  // seen from above), and the two sides r from the axis, horizontal and normal to it
  for (const Vector3& e : {e0, e1}) d.top.lines.push_back(capsule ? arc(e, ex, ey, r) : arc(e, u, v, r));
  const Vector3 side = ez.cross(a);
  if (side.norm() > 1e-9)
    for (double k : {-1.0, 1.0}) {
      const Vector3 w = k * r * side.normalized();
      d.top.lines.push_back({e0 + w, e1 + w});
    }
}

/// The shapes of every body at the kinematics of `data` (forward_kinematics run).
ShapeDrawing body_shapes(const SceneShapes& shapes, const Data& data) {
  ShapeDrawing d;
  for (size_t b = 0; b < shapes.bodies.size() && b < data.p.size(); ++b)
    for (const Shape& s : shapes.bodies[b]) add_shape(d, s, Pose{data.p[b], data.R[b]} * s.pose);
  return d;
}

/// The robot at one recorded state: the base as a box around its frame origin (half side: the
/// farthest joint mounted on it, so the mounts sit on the box; none when `base_box` is false: the
/// bus's own shape is drawn), the links as segments between joint origins and to the end-effector,
/// the joints as dots.
Drawing robot_drawing(const Model& model, Data& data, int frame, const CaptureSample& s, bool planar,
                      bool base_box) {
  forward_kinematics(model, data, s.base, s.theta);
  Drawing d;
  double half = 0.05;
  for (int i = 1; i < model.nb(); ++i)
    if (model.body(i).parent == 0) half = std::max(half, model.body(i).tree.p.cwiseAbs().maxCoeff());
  if (base_box) add_box(d, data.p[0], data.R[0], Vector3::Constant(half), planar);
  for (int i = 1; i < model.nb(); ++i) {
    const int parent = model.body(i).parent;
    if (parent > 0) d.lines.push_back({data.p[static_cast<size_t>(parent)], data.p[static_cast<size_t>(i)]});
    d.dots.push_back(data.p[static_cast<size_t>(i)]);
  }
  const Frame& f = model.frame(frame);
  d.lines.push_back({data.p[static_cast<size_t>(f.body)], frame_pose(model, data, frame).p});
  return d;
}

/// The target at T: its shape when the scenario has one, else a schematic box (a square, or a cube,
/// of half side max |r_tp|, so that the contact point lies on its surface); the contact point and an
/// arrow along the contact normal.
ShapeDrawing target_drawing(const Target& t, bool planar, double arrow, const std::optional<Shape>& shape) {
  ShapeDrawing d;
  if (shape) {
    add_shape(d, *shape, Pose{t.position, t.rotation()} * shape->pose);
  } else {
    const double h = std::max(0.1, t.contact_offset.cwiseAbs().maxCoeff());
    add_box(d.top, t.position, t.rotation(), Vector3::Constant(h), planar);
    add_box(d.oblique, t.position, t.rotation(), Vector3::Constant(h), planar);
  }
  const Vector3 cp = t.contact_point(), u = t.normal_world();
  // the normal points from the end-effector into the target: draw it arriving at the contact point
  const Vector3 tail = cp - arrow * u;
  Vector3 side = u.cross(Vector3::UnitZ());
  if (side.norm() < 1e-6) side = u.cross(Vector3::UnitX());
  side.normalize();
  for (Drawing* v : {&d.top, &d.oblique}) {
    v->lines.push_back({tail, cp});
    v->lines.push_back(
        {cp - 0.25 * arrow * u + 0.12 * arrow * side, cp, cp - 0.25 * arrow * u - 0.12 * arrow * side});
    v->dots.push_back(cp);
  }
  return d;
}

/// Indices of about kInstants samples evenly spread over the series, first and last included.
std::vector<size_t> instants(size_t n) {
  std::vector<size_t> k;
  if (n == 0) return k;
  const int m = static_cast<int>(std::min<size_t>(kInstants, n));
  for (int i = 0; i < m; ++i)
    k.push_back(m == 1 ? 0 : static_cast<size_t>(std::llround(double(i) * double(n - 1) / double(m - 1))));
  return k;
}

/// A drawing as curves: each line in `color`, `alpha` and `width`, then, when `dot` is set, the
/// dots as one curve of that symbol. put(curve, point) appends a point in the panel's coordinates.
template <class C, class Put>
std::vector<C> drawing_curves(const Drawing& d, int color, double alpha, double width, const std::string& dot,
                              double dot_scale, Put put) {
  std::vector<C> out;
  for (const auto& l : d.lines) {
    C c;
    c.color = color;
    c.alpha = alpha;
    c.width = width;
    for (const auto& v : l) put(c, v);
    out.push_back(std::move(c));
  }
  if (!d.dots.empty() && !dot.empty()) {
    C c;
    c.color = color;
    c.alpha = alpha;
    c.line_style = 0;
    c.symbol = dot;
    c.symbol_scale = dot_scale;
    for (const auto& v : d.dots) put(c, v);
    out.push_back(std::move(c));
  }
  return out;
}

/// Adds a drawing to a 2-D panel (axes a, b of the inertial frame); `label` goes to the dots, or
/// to the first line when there are none.
void add(Panel& p, const Drawing& d, int a, int b, int color, double alpha, double width,
         const std::string& label, const std::string& dot, double dot_scale) {
  auto curves =
      drawing_curves<Curve>(d, color, alpha, width, dot, dot_scale, [&](Curve& c, const Vector3& v) {
        c.x.push_back(v(a));
        c.y.push_back(v(b));
      });
  if (dot.empty()) {
    if (!curves.empty()) curves.front().label = label;
  } else if (!d.dots.empty()) {
    curves.back().label = label;
  }
  for (auto& c : curves) p.curves.push_back(std::move(c));
}

/// Adds a drawing to a 3-D panel.
void add(Panel3& p, const Drawing& d, int color, double alpha, double width, const std::string& dot,
         double dot_scale) {
  auto curves =
      drawing_curves<Curve3>(d, color, alpha, width, dot, dot_scale, [](Curve3& c, const Vector3& v) {
        c.x.push_back(v.x());
        c.y.push_back(v.y());
        c.z.push_back(v.z());
      });
  for (auto& c : curves) p.curves.push_back(std::move(c));
}

/// Smallest singular value of the task rows of J_f at a recorded state (as the planner computes it).
double task_singular_value(const Model& model, Data& data, int frame, const CaptureSample& s,
                           const CaptureTask& task) {
  const Eigen::MatrixXd& Jf = generalized_jacobian(model, data, s.base, s.theta, frame);
  Eigen::MatrixXd Jt(task.rows(), model.n());
  int r = 0;
  if (task.kind == CaptureTask::Kind::Pose) {
    Jt = Jf;
  } else {
    for (int k = 0; k < 3; ++k)
      if (task.axes[static_cast<size_t>(k)]) Jt.row(r++) = Jf.row(k);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Jt);
  return svd.singularValues().minCoeff();
}

/// Rotation angle between two unit quaternions, deg.
double angle_deg(const Quaternion& a, const Quaternion& b) {
  return Eigen::AngleAxisd(a.normalized().conjugate() * b.normalized()).angle() * 180.0 / M_PI;
}

/// True when every joint of every recorded state lies in the plane z = z0 (the contact point's).
bool planar_motion(const Model& model, Data& data, double z0, const std::vector<CaptureRun>& runs) {
  bool planar = true;
  for (const auto& run : runs)
    for (const auto& s : run.result->series) {
      forward_kinematics(model, data, s.base, s.theta);
      for (int i = 0; i < model.nb() && planar; ++i)
        planar = std::abs(data.p[static_cast<size_t>(i)].z() - z0) < 1e-6;
    }
  return planar;
}

/// The drawings of one run: the arm at the instants, the end-effector path, the target at T; with
/// shapes, the bodies' shapes at T and the closest pair along the path (nearest points joined,
/// with every shape at that instant when it is not T).
struct RunDrawings {
  std::vector<Drawing> arms;
  Drawing path;
  ShapeDrawing target;
  Drawing reconfiguration_path;  ///< the end-effector during a reconfiguration (empty: none)
  ShapeDrawing shapes;           ///< the bus's and the links' shapes at T (empty: no shapes)
  Drawing closest;               ///< the closest pair's nearest points joined (empty: none)
  ShapeDrawing closest_shapes;   ///< every shape at the closest pair's instant (empty: at T)
  std::string closest_note;      ///< "closest: link3 - target at t = 177.8 s" (empty: none)
  double closest_distance = 0;   ///< m
  int color = 0;
  double duration = 0;
  bool planar = true;
  /// Opacity of the i-th arm: faint early, dark late.
  double alpha(size_t i) const {
    return arms.size() < 2 ? 1.0 : 0.2 + 0.8 * double(i) / double(arms.size() - 1);
  }
};

RunDrawings run_drawings(const Model& model, Data& data, int frame, const CaptureResult& res,
                         const ShapeDrawing& target, bool planar, long reconfiguration_samples,
                         bool base_box) {
  RunDrawings d;
  for (size_t k : instants(res.series.size()))
    d.arms.push_back(robot_drawing(model, data, frame, res.series[k], planar, base_box));
  d.target = target;
  d.planar = planar;
  d.path.lines.emplace_back();
  const size_t k = static_cast<size_t>(std::max(0L, reconfiguration_samples));
  if (k > 0) d.reconfiguration_path.lines.emplace_back();
  for (size_t i = 0; i < res.series.size(); ++i) {
    if (i < k) d.reconfiguration_path.lines.back().push_back(res.series[i].end_effector);
    if (i + 1 >= k) d.path.lines.back().push_back(res.series[i].end_effector);  // joined at t_r
  }
  return d;
}

/// Adds the shapes of a run to its drawings: the bodies at T and, from the clearance report, the
/// closest pair (and every shape at its instant, the recorded state nearest to it, when not T).
void add_run_shapes(RunDrawings& d, const Model& model, Data& data, const CaptureResult& res,
                    const SceneShapes& shapes, const Target& target_at_start,
                    const ClearanceReport* clearance) {
  if (res.series.empty()) return;
  forward_kinematics(model, data, res.series.back().base, res.series.back().theta);
  d.shapes = body_shapes(shapes, data);
  if (!clearance || !std::isfinite(clearance->overall.distance)) return;
  const ClearanceReport::Entry& c = clearance->overall;
  d.closest.lines.push_back({c.p_a, c.p_b});
  d.closest.dots = {c.p_a, c.p_b};
  d.closest_note = str("closest: ", c.pair, " at t = ", fixed(c.time, 1), " s");
  d.closest_distance = c.distance;
  const auto nearest = std::min_element(
      res.series.begin(), res.series.end(),
      [&](const auto& a, const auto& b) { return std::abs(a.t - c.time) < std::abs(b.t - c.time); });
  if (&*nearest == &res.series.back()) return;
  forward_kinematics(model, data, nearest->base, nearest->theta);
  d.closest_shapes = body_shapes(shapes, data);
  if (shapes.target) {
    const Target t = propagate_target(target_at_start, c.time);
    add_shape(d.closest_shapes, *shapes.target, Pose{t.position, t.rotation()} * shapes.target->pose);
  }
}

/// The x-y view: the arms (the first dashed with open joints), the path, the target.
void top_view(Panel& p, const RunDrawings& d) {
  p.equal_aspect = true;
  p.legend_outside = true;
  p.xlabel = "x (m)";
  p.ylabel = "y (m)";
  for (size_t i = 0; i < d.arms.size(); ++i) {
    const bool last = i + 1 == d.arms.size();
    const size_t first_curve = p.curves.size();
    add(p, d.arms[i], 0, 1, d.color, d.alpha(i), 2.0,
        i == 0 ? "arm at t = 0"
        : last ? str("arm at T = ", fixed(d.duration, 0), " s")
               : "",
        i == 0 ? "○" : "●", i == 0 ? 0.9 : 0.7);
    if (i == 0)  // dashed, open joints: told from the arm at T, which has the same colour
      for (size_t c = first_curve; c < p.curves.size(); ++c)
        if (p.curves[c].line_style == 1) p.curves[c].line_style = 3;
  }
  if (!d.reconfiguration_path.lines.empty()) {
    add(p, d.reconfiguration_path, 0, 1, kReconfigurationColor, 1.0, 1.5, "end-effector, reconfiguration", "",
        1.0);
    p.curves.back().line_style = 4;
  }
  add(p, d.path, 0, 1, kBlack, 1.0, 1.0,
      d.reconfiguration_path.lines.empty() ? "end-effector path" : "end-effector, approach", "", 1.0);
  p.curves.back().line_style = 2;
  add(p, d.closest_shapes.top, 0, 1, d.color, 0.3, 1.0, "", "", 1.0);
  add(p, d.shapes.top, 0, 1, d.color, 0.7, 1.0, "shapes at T", "", 1.0);
  add(p, d.target.top, 0, 1, kTargetColor, 1.0, 1.5, "target at T, normal", "●", 0.9);
  add(p, d.closest, 0, 1, kClosestColor, 1.0, 2.5, str("closest: ", fixed(d.closest_distance, 3), " m"), "■",
      0.8);
}

/// The oblique 3-D view of a spatial run.
Panel3 oblique_view(const RunDrawings& d) {
  Panel3 q;
  q.title = str("oblique view, the arm at ", d.arms.size(), " instants (faint: early)");
  q.xlabel = "x (m)";
  q.ylabel = "y (m)";
  q.zlabel = "z (m)";
  for (size_t i = 0; i < d.arms.size(); ++i) add(q, d.arms[i], d.color, d.alpha(i), 2.0, "●", 0.6);
  if (!d.reconfiguration_path.lines.empty()) {
    add(q, d.reconfiguration_path, kReconfigurationColor, 1.0, 1.5, "", 1.0);
    q.curves.back().line_style = 4;
  }
  add(q, d.path, kBlack, 1.0, 1.0, "", 1.0);
  q.curves.back().line_style = 2;
  add(q, d.closest_shapes.oblique, d.color, 0.3, 1.0, "", 1.0);
  add(q, d.shapes.oblique, d.color, 0.7, 1.0, "", 1.0);
  add(q, d.target.oblique, kTargetColor, 1.0, 1.5, "●", 0.8);
  add(q, d.closest, kClosestColor, 1.0, 2.5, "■", 0.8);
  return q;
}

/// Figures 10, 11, 13-15 for one run: the top view alone (planar), or the oblique and top views.
plot::Figure capture_figure(const std::string& label, const CaptureResult& res, const RunDrawings& d) {
  plot::Figure fig;
  fig.name = "capture_" + label;
  fig.title = str("Capture process, ", label, " run: M_ie = ", fixed(res.M_ie, 3),
                  " kg, F#dmax#u = ", fixed(res.f_max_closed_form / 1e3, 2),
                  " kN at T = ", fixed(d.duration, 0), " s");
  Panel p;
  top_view(p, d);
  if (d.planar) {
    p.title = d.closest_note.empty()
                  ? str("the arm at ", d.arms.size(), " instants (faint: early, dark: late)")
                  : str("the arm at ", d.arms.size(), " instants; ", d.closest_note);
  } else {
    fig.cols = 2;
    fig.panels.emplace_back(oblique_view(d));
    // with a closest pair the note alone (the x-y axes say which view it is): "top view; " before a
    // long pair name ran past the panel's edge
    p.title = d.closest_note.empty() ? std::string("top view (x-y)") : d.closest_note;
    p.legend_outside = false;
  }
  fig.panels.emplace_back(std::move(p));
  return fig;
}

/// "histories": M_ie, closed-form F_max, base attitude drift and the task's smallest singular value
/// against time, all runs on shared axes.
plot::Figure histories(const Model& model, Data& data, int frame, const std::vector<CaptureRun>& runs) {
  plot::Figure h;
  h.name = "histories";
  h.title = "Capture process: time histories (target at T)";
  h.rows = 2;
  h.cols = 2;
  const bool any_pose = std::any_of(
      runs.begin(), runs.end(), [](const CaptureRun& r) { return r.task.kind == CaptureTask::Kind::Pose; });
  const std::string t = "time t (s)";
  Panel mie = labelled("integrated effective mass (Eq. 14)", t, "M#die#u (kg)"),
        fmax = labelled("closed-form maximum contact force (Eq. 24)", t, "F#dmax#u (kN)"),
        drift = labelled("base attitude drift", t, "rotation from t = 0 (deg)"),
        sigma = labelled("smallest singular value of the task Jacobian", t,
                         any_pose ? "σ#dmin#u of J#dt#u (m/rad, rad/rad)" : "σ#dmin#u of J#dt#u (m/rad)");
  for (size_t r = 0; r < runs.size(); ++r) {
    const CaptureResult& res = *runs[r].result;
    Curve cm, cf, cd, cs;
    for (Curve* c : {&cm, &cf, &cd, &cs}) {
      c->label = runs[r].label;
      c->color = static_cast<int>(r);
      c->line_style = static_cast<int>(r % 3) + 1;
    }
    for (const auto& s : res.series) {
      for (Curve* c : {&cm, &cf, &cd, &cs}) c->x.push_back(s.t);
      cm.y.push_back(s.M_ie);
      cf.y.push_back(s.f_max_estimate / 1e3);
      cd.y.push_back(angle_deg(res.series.front().base.orientation, s.base.orientation));
      cs.y.push_back(task_singular_value(model, data, frame, s, runs[r].task));
    }
    mie.curves.push_back(cm);
    fmax.curves.push_back(cf);
    drift.curves.push_back(cd);
    sigma.curves.push_back(cs);
  }
  for (Panel* p : {&mie, &fmax, &drift, &sigma}) h.panels.emplace_back(std::move(*p));
  return h;
}

/// The joint angles of one run, deg; the legend (joint names) on the last run only. Widens
/// [jmin, jmax] to the angles drawn.
Panel joint_panel(const Model& model, const CaptureRun& run, bool last, double& jmin, double& jmax) {
  Panel jp = labelled(run.label + " run", "time t (s)", "joint angle (deg)");
  jp.legend_outside = last;
  const auto names = model.joint_names();
  for (int j = 0; j < model.n(); ++j) {
    Curve c;
    c.label = last ? names[static_cast<size_t>(j)] : "";
    c.color = j;
    c.line_style = j / plot::kPaletteSize + 1;
    for (const auto& s : run.result->series) {
      c.x.push_back(s.t);
      c.y.push_back(s.theta(j) * 180.0 / M_PI);
      jmin = std::min(jmin, c.y.back());
      jmax = std::max(jmax, c.y.back());
    }
    jp.curves.push_back(std::move(c));
  }
  return jp;
}

/// "joints": the joint angles of each run on common angle limits.
plot::Figure joints_figure(const Model& model, const std::vector<CaptureRun>& runs) {
  plot::Figure joints;
  joints.name = "joints";
  joints.title = "Capture process: joint angles";
  // side by side for one or two runs; stacked for more (three columns leave the last panel, which
  // carries the legend outside, too narrow a viewport: PLplot aborts)
  joints.cols = runs.size() <= 2 ? static_cast<int>(std::max<size_t>(1, runs.size())) : 1;
  joints.rows = runs.size() <= 2 ? 1 : static_cast<int>(runs.size());
  std::vector<Panel> joint_panels;
  double jmin = 1e300, jmax = -1e300;
  for (size_t r = 0; r < runs.size(); ++r)
    joint_panels.push_back(joint_panel(model, runs[r], r + 1 == runs.size(), jmin, jmax));
  const double pad = 0.06 * std::max(1.0, jmax - jmin);
  for (auto& jp : joint_panels) {
    double tmax = 0;
    for (const auto& c : jp.curves)
      if (!c.x.empty()) tmax = std::max(tmax, c.x.back());
    jp.limits = {0.0, std::max(tmax, 1e-9), jmin - pad, jmax + pad};
    joints.panels.emplace_back(std::move(jp));
  }
  return joints;
}

}  // namespace

std::vector<plot::Figure> capture(const Model& model, int frame, const Target& target_at_start,
                                  double duration, const std::vector<CaptureRun>& runs,
                                  const SceneShapes* shapes) {
  Data data(model);
  const Target target = propagate_target(target_at_start, duration);
  const bool planar = planar_motion(model, data, target.contact_point().z(), runs);
  double reach = 0;
  for (int i = 1; i < model.nb(); ++i) reach += model.body(i).tree.p.norm();
  const ShapeDrawing target_at_T =
      target_drawing(target, planar, std::max(0.2, 0.12 * reach), shapes ? shapes->target : std::nullopt);

  std::vector<plot::Figure> out;
  for (size_t r = 0; r < runs.size(); ++r) {
    const bool bus_shape = shapes && !shapes->bodies.empty() && !shapes->bodies[0].empty();
    RunDrawings d = run_drawings(model, data, frame, *runs[r].result, target_at_T, planar,
                                 runs[r].reconfiguration_samples, !bus_shape);
    if (shapes) add_run_shapes(d, model, data, *runs[r].result, *shapes, target_at_start, runs[r].clearance);
    d.color = static_cast<int>(r);
    d.duration = duration;
    out.push_back(capture_figure(runs[r].label, *runs[r].result, d));
  }
  out.push_back(histories(model, data, frame, runs));
  out.push_back(joints_figure(model, runs));
  return out;
}


}  // namespace ffsr::cli::figures
