// python/src/model.cpp -- the model side of ffsr._ffsr: Pose, BasePose, Inertia, Joint, Body, Frame,
// Bus, UrdfReport, Model (Model.from_urdf, Model.from_urdf_string) and ModelBuilder.
#include "arguments.hpp"
#include "bindings.hpp"
#include "outputs.hpp"

#include "ffsr/parsers/urdf.hpp"

#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <limits>

namespace ffsr::python {
namespace {

using namespace nb::literals;
using detail::str;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// (name, value) pairs from a dict {joint: value} or a list of pairs, in the caller's order.
std::vector<std::pair<std::string, double>> locks_arg(nb::handle h) {
  std::vector<std::pair<std::string, double>> locks;
  if (h.is_none()) return locks;
  nb::object items = PyDict_Check(h.ptr()) ? nb::borrow(h).attr("items")() : nb::borrow(h);
  for (nb::handle it : items) {
    auto pair = nb::cast<std::pair<std::string, double>>(it);
    locks.push_back(pair);
  }
  return locks;
}

/// The loader options of Model.from_urdf (UrdfOptions).
UrdfOptions urdf_options(const std::string& end_effector, nb::handle end_effector_offset,
                         const std::optional<Bus>& bus, nb::handle locks, const std::string& inertia_repair,
                         double min_mass, double min_inertia) {
  UrdfOptions o;
  o.end_effector = end_effector;
  if (!end_effector_offset.is_none())
    o.end_effector_offset = vec3(end_effector_offset, "Model.from_urdf", "end_effector_offset");
  o.bus = bus;
  o.locks = locks_arg(locks);
  o.inertia_repair = parse_inertia_repair(inertia_repair);
  detail::require_finite(min_mass, "Model.from_urdf", "min_mass");
  detail::require_finite(min_inertia, "Model.from_urdf", "min_inertia");
  o.min_mass = min_mass;
  o.min_inertia = min_inertia;
  return o;
}

const char* const kFromUrdfDoc =
    "Builds a Model from a URDF file (C++ model_from_urdf_file with UrdfOptions).\n\n"
    "The root link is the free-floating base, or, with `bus`, the URDF is mounted on that spacecraft bus\n"
    "(Bus: mass, inertia, com, mount pose), which becomes the base. Revolute, continuous and prismatic\n"
    "joints move; fixed joints merge their child's inertia into the parent; mimic joints follow their\n"
    "leader; `locks` ({joint: value} in rad or m) fixes joints at a value. The loader validates the\n"
    "inertias and repairs only when asked: inertia_repair='balance' (the triangle inequality, as MuJoCo's\n"
    "balanceinertia), min_mass and min_inertia (boundmass, boundinertia); every repair is written to\n"
    "`report` (a UrdfReport) when one is given. end_effector names the end-effector link (default: the\n"
    "single leaf); end_effector_offset puts the contact point at xyz in its frame.\n"
    "Raises ModelError (the file, the element) or InputError (an option).";

}  // namespace

void bind_tree(nb::module_& m) {
  nb::enum_<JointType>(m, "JointType", "Joint type of a moving joint.")
      .value("Revolute", JointType::Revolute)
      .value("Prismatic", JointType::Prismatic);

  nb::class_<Joint>(m, "Joint", "A moving joint: name, type, unit axis (child frame), limits (rad or m).")
      .def_ro("name", &Joint::name)
      .def_ro("type", &Joint::type)
      .def_prop_ro(
          "axis", [](const Joint& j) { return out(j.axis); }, nb::rv_policy::automatic)
      .def_ro("lower", &Joint::lower)
      .def_ro("upper", &Joint::upper)
      .def("has_limits", &Joint::has_limits);

  nb::class_<Body>(m, "Body",
                   "One rigid body; body 0 is the free-floating base, body i > 0 hangs on a joint.")
      .def_ro("name", &Body::name)
      .def_ro("parent", &Body::parent)
      .def_ro("joint", &Body::joint)
      .def_ro("tree", &Body::tree, "Joint frame in the parent body frame at zero joint position.")
      .def_ro("inertia", &Body::inertia)
      .def_ro("coord", &Body::coord, "The coordinate that drives the joint (-1 for the base).")
      .def_ro("multiplier", &Body::multiplier)
      .def_ro("offset", &Body::offset)
      .def_ro("leader", &Body::leader);

  nb::class_<Frame>(m, "Frame", "A named frame rigidly attached to a body.")
      .def_ro("name", &Frame::name)
      .def_ro("body", &Frame::body)
      .def_ro("pose", &Frame::pose);
}

void bind_pose(nb::module_& m) {
  nb::class_<Pose>(m, "Pose", "Pose of a frame b in a frame a: p the origin of b in a, R = aRb.")
      .def(
          "__init__",
          [](Pose* self, nb::handle p, nb::handle R) {
            new (self) Pose();
            if (!p.is_none()) self->p = vec3(p, "Pose", "p");
            if (!R.is_none()) self->R = mat3(R, "Pose", "R");
            detail::require_finite_all(self->p, "Pose", "p");
            detail::require_finite_all(self->R, "Pose", "R");
          },
          "p"_a.none() = nb::none(), "R"_a.none() = nb::none())
      .def_static(
          "from_xyz_rpy",
          [](nb::handle xyz, nb::handle rpy) {
            return Pose::from_xyz_rpy(vec3(xyz, "Pose.from_xyz_rpy", "xyz"),
                                      vec3(rpy, "Pose.from_xyz_rpy", "rpy"));
          },
          "xyz"_a, "rpy"_a,
          "The pose of a URDF <origin xyz rpy> (roll, pitch, yaw about fixed x, y, z; radians).")
      .def_prop_rw(
          "p", [](const Pose& s) { return out(s.p); },
          [](Pose& s, nb::handle v) { s.p = vec3(v, "Pose", "p"); }, "Origin of b in a (3,).",
          nb::rv_policy::automatic)
      .def_prop_rw(
          "R", [](const Pose& s) { return out(s.R); },
          [](Pose& s, nb::handle v) { s.R = mat3(v, "Pose", "R"); }, "Rotation aRb (3, 3).",
          nb::rv_policy::automatic)
      .def("__mul__", &Pose::operator*, "Composition a_pose * b_pose.");
}

void bind_base_pose(nb::module_& m) {
  nb::class_<BasePose>(
      m, "BasePose",
      "The pose of the base in the inertial frame: position of the base link frame origin and\n"
      "attitude quaternion (x, y, z, w).")
      .def(
          "__init__",
          [](BasePose* self, nb::handle position, nb::handle orientation) {
            new (self) BasePose();
            if (!position.is_none()) self->position = vec3(position, "BasePose", "position");
            if (!orientation.is_none()) self->orientation = quat_xyzw(orientation, "BasePose", "orientation");
          },
          "position"_a.none() = nb::none(), "orientation"_a.none() = nb::none())
      .def_prop_rw(
          "position", [](const BasePose& s) { return out(s.position); },
          [](BasePose& s, nb::handle v) { s.position = vec3(v, "BasePose", "position"); },
          nb::rv_policy::automatic)
      .def_prop_rw(
          "orientation", [](const BasePose& s) { return out_quat(s.orientation); },
          [](BasePose& s, nb::handle v) { s.orientation = quat_xyzw(v, "BasePose", "orientation"); },
          "Attitude quaternion (x, y, z, w) of the base in the inertial frame.", nb::rv_policy::automatic);
}

void bind_inertia(nb::module_& m) {
  nb::class_<Inertia>(m, "Inertia",
                      "Mass (kg), centre of mass and inertia about it (kg m^2), in the link frame.")
      .def(
          "__init__",
          [](Inertia* self, double mass, nb::handle com, nb::handle I) {
            new (self) Inertia();
            self->mass = mass;
            if (!com.is_none()) self->com = vec3(com, "Inertia", "com");
            if (!I.is_none()) self->I = mat3(I, "Inertia", "I");
          },
          "mass"_a, "com"_a.none() = nb::none(), "I"_a.none() = nb::none())
      .def_rw("mass", &Inertia::mass)
      .def_prop_rw(
          "com", [](const Inertia& s) { return out(s.com); },
          [](Inertia& s, nb::handle v) { s.com = vec3(v, "Inertia", "com"); }, nb::rv_policy::automatic)
      .def_prop_rw(
          "I", [](const Inertia& s) { return out(s.I); },
          [](Inertia& s, nb::handle v) { s.I = mat3(v, "Inertia", "I"); }, nb::rv_policy::automatic);
}

void bind_bus(nb::module_& m) {
  nb::class_<Bus>(
      m, "Bus",
      "A spacecraft bus to mount a URDF on (scenario keys bus-mass, bus-inertia, bus-com, mount-xyz,\n"
      "mount-rpy-deg). The bus frame is the free-floating base frame.")
      .def(
          "__init__",
          [](Bus* self, double mass, nb::handle inertia, nb::handle com, const std::optional<Pose>& mount,
             const std::string& name) {
            new (self) Bus();
            self->name = name;
            self->mass = mass;
            self->inertia = mat3(inertia, "Bus", "inertia");
            if (!com.is_none()) self->com = vec3(com, "Bus", "com");
            if (mount) self->mount = *mount;
          },
          "mass"_a, "inertia"_a, "com"_a.none() = nb::none(), "mount"_a.none() = nb::none(), "name"_a = "bus")
      .def_rw("name", &Bus::name)
      .def_rw("mass", &Bus::mass)
      .def_prop_ro(
          "inertia", [](const Bus& b) { return out(b.inertia); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "com", [](const Bus& b) { return out(b.com); }, nb::rv_policy::automatic)
      .def_rw("mount", &Bus::mount);
}

void bind_urdf_report(nb::module_& m) {
  nb::class_<ModelRepair>(m, "ModelRepair", "One change the URDF loader made to a link's inertial values.")
      .def_ro("link", &ModelRepair::link)
      .def_ro("what", &ModelRepair::what)
      .def_ro("before", &ModelRepair::before)
      .def_ro("after", &ModelRepair::after);
  nb::class_<UrdfReport::Mimic>(m, "UrdfMimic")
      .def_ro("joint", &UrdfReport::Mimic::joint)
      .def_ro("leader", &UrdfReport::Mimic::leader)
      .def_ro("multiplier", &UrdfReport::Mimic::multiplier)
      .def_ro("offset", &UrdfReport::Mimic::offset);
  nb::class_<UrdfReport>(
      m, "UrdfReport",
      "What the URDF loader did to the file: links merged into the bus, mimic and locked joints,\n"
      "inertia repairs. Pass one as `report=` to Model.from_urdf.")
      .def(nb::init<>())
      .def_ro("merged_links", &UrdfReport::merged_links)
      .def_ro("mimics", &UrdfReport::mimics)
      .def_ro("locked", &UrdfReport::locked)
      .def_ro("repairs", &UrdfReport::repairs);
}

void bind_model(nb::module_& m) {
  nb::class_<Model>(
      m, "Model",
      "A free-floating multibody tree, constant once built (Model.from_urdf or ModelBuilder).\n"
      "Coordinates: the base pose (BasePose) and the joint positions theta (n,), in model order;\n"
      "generalized velocity (6 + n,) [v0, w0, theta_dot], v0 of the base frame origin, both in the\n"
      "inertial frame.")
      .def_static(
          "from_urdf",
          [](const std::string& path, const std::string& end_effector, nb::handle end_effector_offset,
             const std::optional<Bus>& bus, nb::handle locks, const std::string& inertia_repair,
             double min_mass, double min_inertia, UrdfReport* report) {
            const UrdfOptions o = urdf_options(end_effector, end_effector_offset, bus, locks, inertia_repair,
                                               min_mass, min_inertia);
            return model_from_urdf_file(path, o, report);
          },
          "path"_a, "end_effector"_a = "", "end_effector_offset"_a.none() = nb::none(),
          "bus"_a.none() = nb::none(), "locks"_a.none() = nb::none(), "inertia_repair"_a = "none",
          "min_mass"_a = 0.0, "min_inertia"_a = 0.0, "report"_a.none() = nb::none(), kFromUrdfDoc)
      .def_static(
          "from_urdf_string",
          [](const std::string& xml, const std::string& source, const std::string& end_effector,
             nb::handle end_effector_offset, const std::optional<Bus>& bus, nb::handle locks,
             const std::string& inertia_repair, double min_mass, double min_inertia, UrdfReport* report) {
            const UrdfOptions o = urdf_options(end_effector, end_effector_offset, bus, locks, inertia_repair,
                                               min_mass, min_inertia);
            return model_from_urdf_string(xml, source, o, report);
          },
          "xml"_a, "source"_a = "<string>", "end_effector"_a = "",
          "end_effector_offset"_a.none() = nb::none(), "bus"_a.none() = nb::none(),
          "locks"_a.none() = nb::none(), "inertia_repair"_a = "none", "min_mass"_a = 0.0,
          "min_inertia"_a = 0.0, "report"_a.none() = nb::none(),
          "Builds a Model from URDF text; `source` names it in error messages. Options as Model.from_urdf.")
      .def_prop_ro("n", &Model::n, "Number of coordinates (independent moving joints).")
      .def_prop_ro("nb", &Model::nb, "Number of bodies, the base included.")
      .def_prop_ro("nv", &Model::nv, "Dimension of the generalized velocity, 6 + n.")
      .def_prop_ro("end_effector", &Model::end_effector, "Index of the default end-effector frame.")
      .def_prop_ro("joint_names", &Model::joint_names,
                   "Names of the coordinates' joints, in coordinate order.")
      .def_prop_ro("total_mass", &Model::total_mass)
      .def_prop_ro(
          "gravity", [](const Model& s) { return out(s.gravity); },
          "Gravity in the inertial frame (zero by default).", nb::rv_policy::automatic)
      .def_ro("source", &Model::source, "A label for error messages (the URDF file).")
      .def(
          "joint",
          [](const Model& s, int k) {
            if (k < 0 || k >= s.n())
              throw InputError(str("Model.joint: index ", k, " out of range (n = ", s.n(), ")"));
            return s.joint(k);
          },
          "k"_a, "The joint of coordinate k.")
      .def(
          "coordinate_body",
          [](const Model& s, int k) {
            if (k < 0 || k >= s.n())
              throw InputError(str("Model.coordinate_body: index ", k, " out of range (n = ", s.n(), ")"));
            return s.coordinate_body(k);
          },
          "k"_a)
      .def_prop_ro("bodies", &Model::bodies)
      .def_prop_ro("frames", &Model::frames)
      .def_prop_ro("frame_names",
                   [](const Model& s) {
                     std::vector<std::string> names;
                     for (const auto& f : s.frames()) names.push_back(f.name);
                     return names;
                   })
      .def("frame_index", &Model::frame_index, "name"_a,
           "Index of a named frame; InputError listing the frames.");
}

void bind_model_builder(nb::module_& m) {
  nb::class_<ModelBuilder>(
      m, "ModelBuilder",
      "Builds a Model in code: ModelBuilder('base', Inertia(...)).add_joint(...)...build().")
      .def(nb::init<const std::string&, const Inertia&>(), "base_name"_a, "base_inertia"_a)
      .def(
          "add_joint",
          [](ModelBuilder& b, const std::string& name, JointType type, const std::string& parent,
             const Pose& origin, nb::handle axis, const std::string& child, const Inertia& inertia,
             double lower, double upper) -> ModelBuilder& {
            return b.add_joint(name, type, parent, origin, vec3(axis, "ModelBuilder.add_joint", "axis"),
                               child, inertia, lower, upper);
          },
          "name"_a, "type"_a, "parent"_a, "origin"_a, "axis"_a, "child"_a, "inertia"_a, "lower"_a = -kInf,
          "upper"_a = kInf, nb::rv_policy::reference,
          "Adds a moving joint from the frame `parent` to a new link `child` (origin: the joint frame in "
          "the\n"
          "parent's at zero position; axis in the joint frame). Returns the builder.")
      .def("add_fixed", &ModelBuilder::add_fixed, "name"_a, "parent"_a, "origin"_a, "child"_a, "inertia"_a,
           nb::rv_policy::reference, "Adds a fixed joint: `child` is merged into the body carrying `parent`.")
      .def("set_end_effector", &ModelBuilder::set_end_effector, "frame"_a, nb::rv_policy::reference)
      .def(
          "set_end_effector_offset",
          [](ModelBuilder& b, nb::handle xyz) -> ModelBuilder& {
            return b.set_end_effector_offset(vec3(xyz, "end-effector-offset", "xyz"));
          },
          "xyz"_a, nb::rv_policy::reference,
          "Puts the contact point at xyz in the end-effector frame (a frame '<end-effector>_contact').")
      .def("set_mimic", &ModelBuilder::set_mimic, "follower"_a, "leader"_a, "multiplier"_a, "offset"_a,
           nb::rv_policy::reference, "q_follower = multiplier * q_leader + offset (URDF <mimic>).")
      .def(
          "set_gravity",
          [](ModelBuilder& b, nb::handle g) -> ModelBuilder& {
            return b.set_gravity(vec3(g, "set_gravity", "g"));
          },
          "g"_a, nb::rv_policy::reference)
      .def("set_source", &ModelBuilder::set_source, "source"_a, nb::rv_policy::reference)
      .def("build", &ModelBuilder::build, "Validates the tree and returns the Model.");
}

}  // namespace ffsr::python
