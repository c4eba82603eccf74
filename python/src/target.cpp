// python/src/target.cpp -- ffsr.Target, the tumbling target of the paper (Section 2.2), and its
// torque-free propagation.
#include "arguments.hpp"
#include "bindings.hpp"
#include "outputs.hpp"

namespace ffsr::python {

using namespace nb::literals;

void bind_target(nb::module_& m) {
  nb::class_<Target>(
      m, "Target",
      "The tumbling target (Section 2.2). Defaults are the paper's: 200 kg, diag(100, 100, 100) kg m^2,\n"
      "r_tp = (-0.25, 0.15, 0), u_n = x. Vectors marked (target frame) rotate with it; attitude is the\n"
      "quaternion oR_t as (x, y, z, w). Validated when made (Target.validate).")
      .def(
          "__init__",
          [](Target* self, double mass, nb::handle inertia, nb::handle position, nb::handle attitude,
             nb::handle velocity, nb::handle angular_velocity, nb::handle contact_offset, nb::handle normal) {
            Target t;
            t.mass = mass;
            if (!inertia.is_none()) t.inertia = mat3(inertia, "Target", "inertia");
            if (!position.is_none()) t.position = vec3(position, "Target", "position");
            if (!attitude.is_none()) t.attitude = quat_xyzw(attitude, "Target", "attitude");
            if (!velocity.is_none()) t.velocity = vec3(velocity, "Target", "velocity");
            if (!angular_velocity.is_none())
              t.angular_velocity = vec3(angular_velocity, "Target", "angular_velocity");
            if (!contact_offset.is_none())
              t.contact_offset = vec3(contact_offset, "Target", "contact_offset");
            if (!normal.is_none()) t.normal = vec3(normal, "Target", "normal");
            t.validate();
            new (self) Target(t);
          },
          "mass"_a = 200.0, "inertia"_a.none() = nb::none(), "position"_a.none() = nb::none(),
          "attitude"_a.none() = nb::none(), "velocity"_a.none() = nb::none(),
          "angular_velocity"_a.none() = nb::none(), "contact_offset"_a.none() = nb::none(),
          "normal"_a.none() = nb::none())
      .def_rw("mass", &Target::mass, "m_t, kg.")
      .def_prop_rw(
          "inertia", [](const Target& s) { return out(s.inertia); },
          [](Target& s, nb::handle v) { s.inertia = mat3(v, "Target", "inertia"); },
          "I_t about the centre of mass (target frame).", nb::rv_policy::automatic)
      .def_prop_rw(
          "position", [](const Target& s) { return out(s.position); },
          [](Target& s, nb::handle v) { s.position = vec3(v, "Target", "position"); }, "Centre of mass in o.",
          nb::rv_policy::automatic)
      .def_prop_rw(
          "attitude", [](const Target& s) { return out_quat(s.attitude); },
          [](Target& s, nb::handle v) { s.attitude = quat_xyzw(v, "Target", "attitude"); },
          "oR_t as (x, y, z, w).", nb::rv_policy::automatic)
      .def_prop_rw(
          "velocity", [](const Target& s) { return out(s.velocity); },
          [](Target& s, nb::handle v) { s.velocity = vec3(v, "Target", "velocity"); }, "v_t, inertial frame.",
          nb::rv_policy::automatic)
      .def_prop_rw(
          "angular_velocity", [](const Target& s) { return out(s.angular_velocity); },
          [](Target& s, nb::handle v) { s.angular_velocity = vec3(v, "Target", "angular_velocity"); },
          "omega_t (target frame), rad/s.", nb::rv_policy::automatic)
      .def_prop_rw(
          "contact_offset", [](const Target& s) { return out(s.contact_offset); },
          [](Target& s, nb::handle v) { s.contact_offset = vec3(v, "Target", "contact_offset"); },
          "r_tp (target frame).", nb::rv_policy::automatic)
      .def_prop_rw(
          "normal", [](const Target& s) { return out(s.normal); },
          [](Target& s, nb::handle v) { s.normal = vec3(v, "Target", "normal"); },
          "u_n (target frame), unit.", nb::rv_policy::automatic)
      .def(
          "validate", [](const Target& t) { t.validate(); },
          "Checks every field; InputError naming the field.")
      .def(
          "rotation", [](const Target& t) { return out(t.rotation()); }, "oR_t.")
      .def(
          "normal_world", [](const Target& t) { return out(t.normal_world()); }, "u = R_t u_n in o.")
      .def(
          "offset_world", [](const Target& t) { return out(t.offset_world()); }, "r = R_t r_tp in o.")
      .def("contact_point", [](const Target& t) { return out(t.contact_point()); })
      .def(
          "contact_point_velocity", [](const Target& t) { return out(t.contact_point_velocity()); },
          "v_tp = v_t + w_t x r (Eq. 12), in o.")
      .def("inverse_mass_along_normal", &Target::inverse_mass_along_normal,
           "1/m_t + (r x u)^T I^-1 (r x u): the target part of Eq. 14.");
  m.def("propagate_target", &propagate_target, "target"_a, "t"_a,
        "The target at time t: drift and torque-free Euler rotation.");
}

}  // namespace ffsr::python
