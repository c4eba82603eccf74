// ffsr/jobs/detail/scenario_series.hpp -- the main job's time series (the CSV of `ffsr-optimize
// --csv`) and the scene that a picture or a 3-D view of it needs (the "scene" key of the JSON):
// per sample the joint angles, the base's, every body's and the target's pose, the end-effector,
// M_ie, the F_max estimate and the phase; once the bodies' tree, their shapes, the target's shape,
// the capture instant and the contact normal there.
#pragma once

#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/jobs/detail/json_values.hpp"

#include "ffsr/algorithm/kinematics.hpp"

#include <iomanip>
#include <sstream>

namespace ffsr {

inline long reconfiguration_samples(const ScenarioResult& r) {
  if (!r.global || !r.global->result.reconfigured || r.global->result.phases.empty()) return 0;
  return r.global->result.phases.front().samples;
}

namespace detail {

/// x, y, z, qw, qx, qy, qz of a pose, comma separated (a leading comma).
inline void pose_csv(std::ostream& c, const Vector3& p, const Quaternion& q) {
  c << "," << p.x() << "," << p.y() << "," << p.z() << "," << q.w() << "," << q.x() << "," << q.y() << ","
    << q.z();
}

/// The seven column names of a pose: prefix_x ... prefix_qz (a leading comma).
inline void pose_header(std::ostream& c, const std::string& prefix) {
  for (const char* k : {"x", "y", "z", "qw", "qx", "qy", "qz"}) c << "," << prefix << "_" << k;
}

/// The runs that hold a result, with the CSV's and the JSON's names: baseline, optimized, global.
inline std::vector<std::pair<const char*, const CaptureResult*>> series_runs(const ScenarioResult& r) {
  std::vector<std::pair<const char*, const CaptureResult*>> runs;
  if (r.plain_ok()) runs.emplace_back("baseline", &r.plain);
  if (r.optimized_ok()) runs.emplace_back("optimized", &r.optimized);
  if (r.global) runs.emplace_back("global", &r.global->result.run);
  return runs;
}

}  // namespace detail

inline std::string scenario_series_csv(const Scenario& sc, const ScenarioResult& r) {
  const Model& model = *sc.model;
  Data data(model);
  std::ostringstream c;
  c << std::setprecision(12) << "run,t";
  for (const auto& name : model.joint_names()) c << "," << name << "_deg";
  detail::pose_header(c, "base");
  c << ",ee_x,ee_y,ee_z,M_ie,F_max_estimate";
  detail::pose_header(c, "target");
  for (int b = 1; b < model.nb(); ++b) detail::pose_header(c, "body" + std::to_string(b));
  c << ",phase\n";
  for (const auto& [label, run] : detail::series_runs(r)) {
    const long reconfiguring = r.global && run == &r.global->result.run ? reconfiguration_samples(r) : 0;
    Target target = sc.problem.target;  // propagated sample to sample
    double target_t = 0;
    for (const CaptureSample& s : run->series) {
      c << label << "," << s.t;
      for (Eigen::Index i = 0; i < s.theta.size(); ++i) c << "," << s.theta(i) * 180.0 / M_PI;
      detail::pose_csv(c, s.base.position, s.base.orientation);
      c << "," << s.end_effector.x() << "," << s.end_effector.y() << "," << s.end_effector.z() << ","
        << s.M_ie << "," << s.f_max_estimate;
      target = propagate_target(target, s.t - target_t);
      target_t = s.t;
      detail::pose_csv(c, target.position, target.attitude.normalized());
      forward_kinematics(model, data, s.base, s.theta);
      for (int b = 1; b < model.nb(); ++b) {
        const auto k = static_cast<size_t>(b);
        detail::pose_csv(c, data.p[k], Quaternion(data.R[k]));
      }
      c << "," << (&s - run->series.data() < reconfiguring ? "reconfiguration" : "approach") << "\n";
    }
  }
  return c.str();
}

namespace detail {

/// A shape as JSON: kind, its sizes, its pose in the carrying frame.
inline nlohmann::json shape_json(const Shape& s) {
  const Quaternion q(s.pose.R);
  nlohmann::json j = {{"kind", shape_kind_name(s.kind)},
                      {"position", vector_json(s.pose.p)},
                      {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
  if (s.kind == Shape::Kind::Box) j["size"] = vector_json(s.size);
  if (s.kind != Shape::Kind::Box) j["radius"] = s.radius;
  if (s.kind == Shape::Kind::Cylinder || s.kind == Shape::Kind::Capsule) j["length"] = s.length;
  return j;
}

/// "scene": the bodies (name, parent, shapes in the body frame; the series' body<i> columns are body
/// i), the end-effector's body and its point in that body, the target's shape (null: none), the
/// contact point and normal in the target frame, the capture instant and the contact normal there.
inline nlohmann::json scene_json(const Scenario& sc) {
  const Model& model = *sc.model;
  std::vector<std::vector<Shape>> shapes(static_cast<size_t>(model.nb()));
  std::optional<Shape> target_shape;
#ifdef FFSR_HAVE_GEOMETRY
  if (sc.geometry) {
    shapes = sc.geometry->checker->geometry().shapes;
    target_shape = sc.geometry->checker->target_shape();
  }
#endif
  nlohmann::json bodies = nlohmann::json::array();
  for (int b = 0; b < model.nb(); ++b) {
    nlohmann::json s = nlohmann::json::array();
    for (const Shape& x : shapes[static_cast<size_t>(b)]) s.push_back(shape_json(x));
    bodies.push_back({{"name", model.body(b).name}, {"parent", model.body(b).parent}, {"shapes", s}});
  }
  const Frame& ee = model.frame(sc.problem.frame);
  const Target& t0 = sc.problem.target;
  const Target at_capture = propagate_target(t0, sc.capture.duration);
  nlohmann::json scene = {{"bodies", bodies},
                          {"end_effector_body", ee.body},
                          {"end_effector_point", vector_json(ee.pose.p)},
                          {"contact_offset", vector_json(t0.contact_offset)},
                          {"contact_normal_target_frame", vector_json(t0.normal.normalized())},
                          {"capture_time", sc.capture.duration},
                          {"capture_normal", vector_json(at_capture.normal_world())}};
  // present with a shape only: a null in the results means a value that is not a number
  if (target_shape) scene["target_shape"] = shape_json(*target_shape);
  return scene;
}

}  // namespace detail
}  // namespace ffsr
