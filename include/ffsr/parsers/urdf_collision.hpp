// ffsr/parsers/urdf_collision.hpp -- the <collision> primitives of a URDF (box, sphere, cylinder), for
// geometry/shape.hpp's robot_geometry. Meshes are not read (the files do not ship them); each is
// listed as a mesh, so that its body also gets capsules along its centre lines (a Panda's hand body
// has the finger pads' boxes, and its meshes are the hand itself). Component ffsr::urdf.
#pragma once

#include "ffsr/geometry/shape.hpp"
#include "ffsr/parsers/detail/urdf_document.hpp"

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace ffsr {

/// The primitive <collision> shapes of every link of URDF text, poses in the link frame, and an
/// entry with `mesh` set for each mesh, in the order of the file's links (urdfdom's map order: by
/// name). `source` names the file in errors.
inline std::vector<LinkShape> urdf_collision_shapes_from_string(const std::string& xml,
                                                                const std::string& source) {
  const detail::UrdfDocument doc = detail::parse_urdf_document(xml, source);
  std::vector<LinkShape> out;
  for (const auto& [name, link] : doc.model->links_)
    for (const urdf::CollisionSharedPtr& c : link->collision_array) {
      if (!c || !c->geometry) continue;
      const Pose pose = detail::urdf_pose(c->origin);
      Shape s;
      switch (c->geometry->type) {
        case urdf::Geometry::BOX: {
          const auto& b = static_cast<const urdf::Box&>(*c->geometry);
          s = Shape::box(Vector3(b.dim.x, b.dim.y, b.dim.z), pose);
          break;
        }
        case urdf::Geometry::SPHERE:
          s = Shape::sphere(static_cast<const urdf::Sphere&>(*c->geometry).radius, pose);
          break;
        case urdf::Geometry::CYLINDER: {
          const auto& y = static_cast<const urdf::Cylinder&>(*c->geometry);
          s = Shape::cylinder(y.radius, y.length, pose);
          break;
        }
        default:  // a mesh: its body gets capsules too
          out.push_back({name, Shape{}, true});
          continue;
      }
      validate_shape(s, detail::str(source, ": link '", name, "' <collision>"));
      out.push_back({name, s});
    }
  return out;
}

/// The same from a file.
inline std::vector<LinkShape> urdf_collision_shapes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelError(detail::str(path, ": cannot open the URDF file"));
  std::ostringstream ss;
  ss << in.rdbuf();
  return urdf_collision_shapes_from_string(ss.str(), path);
}

}  // namespace ffsr
