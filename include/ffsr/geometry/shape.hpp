// ffsr/geometry/shape.hpp -- collision shapes of the robot, the bus and the target (Eigen only).
#pragma once

#include "ffsr/errors.hpp"
#include "ffsr/model/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

// A Shape is a convex primitive with a pose in the frame of the body that carries it:
//   box       full edge lengths `size` (x, y, z), centred on its pose;
//   sphere    `radius`, centred on its pose;
//   cylinder  `radius`, `length` along the pose's z axis, centred (as URDF's <cylinder>);
//   capsule   `radius`, `length` of its centre segment along the pose's z axis, centred.
// RobotGeometry gives every body of a Model (body 0 is the base, or the bus it is mounted on) its
// shapes: the URDF's <collision> primitives where a body has them (parsers/urdf_collision.hpp), else a
// capsule of `link_radius` along each centre line between the body's joint origin and the joint
// origins of its children (and the end-effector point on the end-effector's body). The base gets
// only its URDF primitives or a box of the scenario (the bus). Distances between the shapes need FCL:
// geometry/distance.hpp (component ffsr::geometry).

namespace ffsr {

struct Shape {
  enum class Kind { Box, Sphere, Cylinder, Capsule };
  Kind kind = Kind::Sphere;
  Vector3 size = Vector3::Zero();  ///< box: full edge lengths
  double radius = 0;               ///< sphere, cylinder, capsule
  double length = 0;               ///< cylinder, capsule: along the local z axis, centred
  Pose pose;                       ///< in the frame of the body (or the target) that carries it

  static Shape box(const Vector3& size, const Pose& pose = {}) { return {Kind::Box, size, 0, 0, pose}; }
  static Shape sphere(double r, const Pose& pose = {}) { return {Kind::Sphere, Vector3::Zero(), r, 0, pose}; }
  static Shape cylinder(double r, double l, const Pose& pose = {}) {
    return {Kind::Cylinder, Vector3::Zero(), r, l, pose};
  }
  static Shape capsule(double r, double l, const Pose& pose = {}) {
    return {Kind::Capsule, Vector3::Zero(), r, l, pose};
  }
  /// The capsule of radius r around the segment a-b (points of the carrying frame).
  static Shape capsule_between(const Vector3& a, const Vector3& b, double r) {
    const Vector3 d = b - a;
    const double l = d.norm();
    Pose pose;
    pose.p = 0.5 * (a + b);
    if (l > 0) pose.R = Quaternion::FromTwoVectors(Vector3::UnitZ(), d / l).toRotationMatrix();
    return capsule(r, l, pose);
  }
};

/// The name of a kind as the scenario keys spell it.
inline const char* shape_kind_name(Shape::Kind k) {
  switch (k) {
    case Shape::Kind::Box:
      return "box";
    case Shape::Kind::Sphere:
      return "sphere";
    case Shape::Kind::Cylinder:
      return "cylinder";
    case Shape::Kind::Capsule:
      return "capsule";
  }
  return "?";
}

/// Checks a shape: finite pose, sizes and radius finite and positive (a capsule's length may be 0).
/// Throws InputError starting with `key`.
inline void validate_shape(const Shape& s, const std::string& key) {
  using detail::str;
  if (!s.pose.p.allFinite() || !s.pose.R.allFinite()) throw InputError(str(key, ": the offset must be finite"));
  if (s.kind == Shape::Kind::Box) {
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(s.size(i)) || !(s.size(i) > 0))
        throw InputError(str(key, ": box sizes must be positive and finite, got ", s.size(i)));
    return;
  }
  if (!std::isfinite(s.radius) || !(s.radius > 0))
    throw InputError(str(key, ": radius must be positive and finite, got ", s.radius));
  if (!std::isfinite(s.length) || s.length < 0 ||
      (s.kind == Shape::Kind::Cylinder && !(s.length > 0)))
    throw InputError(str(key, ": length must be positive and finite, got ", s.length));
}

/// The target's shape from the scenario keys target-shape ("box", "sphere", "cylinder"),
/// target-size (box: 3 edge lengths; sphere: radius; cylinder: radius, length along the target's z)
/// and target-shape-offset (its centre in the target frame). InputError naming the key.
inline Shape target_shape_of(const std::string& kind, const std::vector<double>& size,
                             const std::vector<double>& offset) {
  using detail::str;
  Shape s;
  auto need = [&](size_t k) {
    if (size.size() != k)
      throw InputError(str("--target-size: a ", kind, " needs ", k, " number", k > 1 ? "s" : "", ", got ",
                           size.size()));
  };
  if (kind == "box") {
    need(3);
    s = Shape::box(Vector3(size[0], size[1], size[2]));
  } else if (kind == "sphere") {
    need(1);
    s = Shape::sphere(size[0]);
  } else if (kind == "cylinder") {
    need(2);
    s = Shape::cylinder(size[0], size[1]);
  } else {
    throw InputError(str("--target-shape: unknown shape '", kind, "' (box, sphere or cylinder)"));
  }
  if (!offset.empty()) {
    if (offset.size() != 3) throw InputError(str("--target-shape-offset: expected 3 numbers, got ", offset.size()));
    s.pose.p = Vector3(offset[0], offset[1], offset[2]);
  }
  validate_shape(s, "--target-size");
  return s;
}

/// Signed distance from a point to the surface of a shape, both in the shape's carrying frame
/// (negative inside). Closed forms; used to check that the contact point lies on the target.
inline double point_surface_distance(const Shape& s, const Vector3& point) {
  const Vector3 q = s.pose.R.transpose() * (point - s.pose.p);
  switch (s.kind) {
    case Shape::Kind::Box: {
      const Vector3 d = q.cwiseAbs() - 0.5 * s.size;
      return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
    }
    case Shape::Kind::Sphere:
      return q.norm() - s.radius;
    case Shape::Kind::Cylinder: {
      const double dr = std::hypot(q.x(), q.y()) - s.radius, dz = std::abs(q.z()) - 0.5 * s.length;
      return std::hypot(std::max(dr, 0.0), std::max(dz, 0.0)) + std::min(std::max(dr, dz), 0.0);
    }
    case Shape::Kind::Capsule: {
      const double z = std::clamp(q.z(), -0.5 * s.length, 0.5 * s.length);
      return (q - Vector3(0, 0, z)).norm() - s.radius;
    }
  }
  return 0;
}

/// The shapes of a robot: shapes[b] are those of body b (in its frame), names[b] its name.
/// `origin[b]` tells where they came from: "urdf", "capsule", "urdf+capsule", "bus-box" or "" (no shape).
struct RobotGeometry {
  std::vector<std::vector<Shape>> shapes;
  std::vector<std::string> names, origin;
  /// The end-effector body's centre line (body frame) from its joint origin to the contact point:
  /// the contact exemption trims it (geometry/distance.hpp).
  Vector3 ee_line_start = Vector3::Zero(), ee_line_end = Vector3::Zero();
  int ee_body = -1;
  /// The radius of each moving body's centre-line capsule (link-radius; 0 for the base), also for a
  /// body with URDF shapes: the contact exemption trims the centre lines of the bodies it reaches.
  std::vector<double> line_radius;
};

/// A URDF <collision> primitive of a link (parsers/urdf_collision.hpp reads them).
struct LinkShape {
  std::string link;
  Shape shape;        ///< pose in the link frame
  bool mesh = false;  ///< a mesh (not read; shape unset): the link's body gets capsules too
};

namespace detail {

/// The centre-line points of body b in its frame: the joint origins of its child bodies and, on
/// the end-effector's body, the end-effector point; a leaf without them: its farthest frame.
inline std::vector<Vector3> centre_line_ends(const Model& model, int b) {
  std::vector<Vector3> ends;
  for (int c = 1; c < model.nb(); ++c)
    if (model.body(c).parent == b) ends.push_back(model.body(c).tree.p);
  const Frame& ee = model.frame(model.end_effector());
  if (ee.body == b) ends.push_back(ee.pose.p);
  if (ends.empty()) {
    Vector3 far = Vector3::Zero();
    for (const Frame& f : model.frames())
      if (f.body == b && f.pose.p.norm() > far.norm()) far = f.pose.p;
    ends.push_back(far);
  }
  return ends;
}

/// The base's box `bus_box` (edge lengths, centred on the base frame) when given; refused when the
/// URDF's base has <collision> primitives already (the key would change nothing).
inline void add_bus_box(RobotGeometry& g, const std::vector<double>& bus_box) {
  if (bus_box.empty()) return;
  if (!g.shapes[0].empty())
    throw InputError(str("--bus-box: the URDF's base '", g.names[0],
                         "' has <collision> primitives already (bus-box stands for a base without any)"));
  if (bus_box.size() != 3) throw InputError(str("--bus-box: expected 3 numbers, got ", bus_box.size()));
  const Shape s = Shape::box(Vector3(bus_box[0], bus_box[1], bus_box[2]));
  validate_shape(s, "--bus-box");
  g.shapes[0].push_back(s);
  g.origin[0] = "bus-box";
}

}  // namespace detail

/// The robot's shapes: `urdf_shapes` (the <collision> primitives, mapped to bodies through the
/// model's frames) where a body has some, and capsules too where one of its links has a mesh;
/// otherwise capsules of radius link_radius[b - 1] (one
/// value: every link) along the body's centre lines. The base (body 0): its URDF primitives, else
/// `bus_box` when given (edge lengths, centred on the base frame), else nothing. InputError
/// naming `link-radius` or `bus-box` on a bad value.
inline RobotGeometry robot_geometry(const Model& model, const std::vector<LinkShape>& urdf_shapes,
                                    const std::vector<double>& link_radius, const std::vector<double>& bus_box) {
  using detail::str;
  const int nb = model.nb();
  if (link_radius.size() != 1 && link_radius.size() != static_cast<size_t>(nb - 1))
    throw InputError(str("--link-radius: expected 1 value or one per moving body (", nb - 1, "), got ",
                         link_radius.size()));
  for (double r : link_radius)
    if (!std::isfinite(r) || !(r > 0)) throw InputError(str("--link-radius: must be positive and finite, got ", r));
  RobotGeometry g;
  g.shapes.resize(static_cast<size_t>(nb));
  g.origin.assign(static_cast<size_t>(nb), "");
  for (int b = 0; b < nb; ++b) g.names.push_back(model.body(b).name);
  std::vector<char> has_mesh(static_cast<size_t>(nb), 0);
  for (const LinkShape& ls : urdf_shapes) {
    const Frame& f = model.frame(model.frame_index(ls.link));
    if (ls.mesh) {
      has_mesh[static_cast<size_t>(f.body)] = 1;
      continue;
    }
    Shape s = ls.shape;
    s.pose = f.pose * s.pose;
    validate_shape(s, str(model.source, ": link '", ls.link, "' <collision>"));
    g.shapes[static_cast<size_t>(f.body)].push_back(s);
    g.origin[static_cast<size_t>(f.body)] = "urdf";
  }
  detail::add_bus_box(g, bus_box);
  const Frame& ee = model.frame(model.end_effector());
  g.line_radius.assign(static_cast<size_t>(nb), 0.0);
  for (int b = 1; b < nb; ++b) {
    const double r = link_radius[link_radius.size() == 1 ? 0 : static_cast<size_t>(b - 1)];
    g.line_radius[static_cast<size_t>(b)] = r;
    if (b == ee.body) {
      g.ee_body = b;
      g.ee_line_end = ee.pose.p;
    }
    const bool primitives = !g.shapes[static_cast<size_t>(b)].empty();
    if (primitives && !has_mesh[static_cast<size_t>(b)]) continue;
    for (const Vector3& e : detail::centre_line_ends(model, b))
      g.shapes[static_cast<size_t>(b)].push_back(Shape::capsule_between(Vector3::Zero(), e, r));
    g.origin[static_cast<size_t>(b)] = primitives ? "urdf+capsule" : "capsule";
  }
  return g;
}

/// The smallest distance of a configuration or along a path: overall and per kind of pair
/// (arm-target, arm-bus, self), with the pair's name and the time (geometry/clearance.hpp fills it).
struct ClearanceReport {
  struct Entry {
    double distance = std::numeric_limits<double>::infinity();
    std::string pair;  ///< "link3 - target"; empty: no pair of this kind
    double time = 0;   ///< s, along a path
    Vector3 p_a = Vector3::Zero(), p_b = Vector3::Zero();  ///< nearest points (inertial frame)
  };
  Entry overall, arm_target, arm_bus, self;
  std::string kind;  ///< the overall's kind
};

}  // namespace ffsr
