// python/src/contact.cpp -- the contact side of ffsr._ffsr: the Hertz-damped contact law (Eq. 15) with
// the eight damping laws of Table 1 chosen by name, the closed-form and exact force maxima (Eq. 16-25),
// xi (Eq. 21), and the single-body (Eq. 16) and multibody (Figure 2) contact runs (SUNDIALS CVODE).
#include "arguments.hpp"
#include "bindings.hpp"
#include "outputs.hpp"

#include "ffsr/contact/contact_law.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "ffsr/simulate/single_body.hpp"

#include <nanobind/stl/string.h>
#include <nanobind/stl/string_view.h>
#include <nanobind/stl/vector.h>

namespace ffsr::python {
namespace {

using namespace nb::literals;
using detail::str;

ContactParams params_of(double K, double alpha, double c_r) {
  ContactParams p{K, alpha, c_r};
  validate(p, "ContactParams");
  return p;
}

/// One field of every sample of a multibody contact run, as an array.
template <class Field>
NewArray series_of(const MultibodyContactResult& r, Field field) {
  std::vector<double> v;
  for (const auto& s : r.series) v.push_back(s.*field);
  return array_of(v);
}

}  // namespace

void bind_contact_params(nb::module_& m) {
  nb::class_<ContactParams>(
      m, "ContactParams",
      "Parameters of the contact law Eq. 15: stiffness K (N/m^alpha), exponent alpha, restitution c_r.")
      .def(
          "__init__",
          [](ContactParams* s, double K, double alpha, double c_r) {
            new (s) ContactParams(params_of(K, alpha, c_r));
          },
          "K"_a = 1e9, "alpha"_a = 1.5, "c_r"_a = 0.9)
      .def_rw("K", &ContactParams::K)
      .def_rw("alpha", &ContactParams::alpha)
      .def_rw("c_r", &ContactParams::c_r)
      .def("__repr__", [](const ContactParams& p) {
        return str("ContactParams(K=", p.K, ", alpha=", p.alpha, ", c_r=", p.c_r, ")");
      });

  nb::class_<ForcePeak>(m, "ForcePeak", "The point of maximum force of the single-body contact (Eq. 16).")
      .def_ro("force", &ForcePeak::force, "F_max, N.")
      .def_ro("deformation", &ForcePeak::deformation, "delta'_max, m.")
      .def_ro("deformation_rate", &ForcePeak::deformation_rate, "delta_dot at the peak, m/s.");
}

void bind_contact_law(nb::module_& m) {
  m.def(
      "contact_law_names",
      [] {
        std::vector<std::string> names;
        for (auto n : contact_law_names()) names.emplace_back(n);
        return names;
      },
      "The names of the eight damping laws of Table 1.");

  nb::class_<ContactLaw>(
      m, "ContactLaw",
      "The Hertz contact law with hysteresis damping F = K delta^alpha + lambda delta^alpha delta_dot\n"
      "(Eq. 15), lambda = f(c_r) K / delta_dot^- (Eq. 22) with the damping law `name` (Table 1;\n"
      "contact_law_names()) at the approach velocity delta_dot^- > 0 (m/s).")
      .def(
          "__init__",
          [](ContactLaw* s, const std::string& name, const ContactParams& params, double approach_velocity) {
            new (s) ContactLaw{make_contact_law(name, params, approach_velocity)};
          },
          "name"_a, "params"_a, "approach_velocity"_a)
      .def_prop_ro("name", [](const ContactLaw& l) { return std::string(contact_law_name(l.law)); })
      .def_prop_ro(
          "params",
          [](const ContactLaw& l) { return std::visit([](const auto& x) { return x.params(); }, l.law); })
      .def_prop_ro(
          "approach_velocity", [](const ContactLaw& l) { return approach_velocity(l.law); },
          "delta_dot^-, m/s.")
      .def_prop_ro(
          "f", [](const ContactLaw& l) { return damping_factor(l.law); }, "f(c_r) of Table 1 (Eq. 22).")
      .def_prop_ro(
          "lambda_", [](const ContactLaw& l) { return lambda(l.law); },
          "lambda = f K / delta_dot^- (Eq. 22).")
      .def_prop_ro(
          "zeta", [](const ContactLaw& l) { return zeta(l.law); }, "zeta of Eq. 25, N/kg^(alpha/(alpha+1)).")
      .def(
          "force", [](const ContactLaw& l, double d, double dd) { return force(l.law, d, dd); }, "delta"_a,
          "delta_dot"_a, "F(delta, delta_dot) of Eq. 15, N; 0 for delta <= 0, clamped at 0 (never pulls).")
      .def(
          "max_deformation", [](const ContactLaw& l, double M) { return max_deformation(l.law, M); },
          "M_ie"_a, "delta_max, the deformation where delta_dot = 0 (Eq. 20), m.")
      .def(
          "max_force_estimate", [](const ContactLaw& l, double M) { return max_force_estimate(l.law, M); },
          "M_ie"_a, "F'_max = K delta_max^alpha (Eq. 23), N.")
      .def(
          "max_force_closed_form",
          [](const ContactLaw& l, double M) { return max_force_closed_form(l.law, M); }, "M_ie"_a,
          "F_max = zeta M_ie^(alpha/(alpha+1)) (Eq. 24), N.")
      .def(
          "exact_peak", [](const ContactLaw& l, double M) { return exact_peak(l.law, M); }, "M_ie"_a,
          "The exact maximum of F along the single-body contact (Eq. 16; Figure 3, '*').")
      .def(
          "max_force_exact", [](const ContactLaw& l, double M) { return max_force_exact(l.law, M); },
          "M_ie"_a, "exact_peak(M_ie).force, N.")
      .def(
          "relative_error", [](const ContactLaw& l) { return relative_error(l.law); },
          "xi = (F_max - F'_max) / F_max x 100 (Eq. 21), percent; depends on f(c_r) and alpha only.")
      .def_prop_ro(
          "xi", [](const ContactLaw& l) { return relative_error(l.law); },
          "xi of Eq. 21 (relative_error()).");
  m.def(
      "make_contact_law",
      [](const std::string& name, const ContactParams& params, double approach_velocity) {
        return ContactLaw{make_contact_law(name, params, approach_velocity)};
      },
      "name"_a, "params"_a, "approach_velocity"_a,
      "The law called `name` (contact_law_names()); InputError for an unknown name or bad parameters.");
}

void bind_contact_functions(nb::module_& m) {
  m.def(
      "max_force_closed_form", [](const ContactLaw& l, double M) { return max_force_closed_form(l.law, M); },
      "law"_a, "M_ie"_a, "F_max = zeta M_ie^(alpha/(alpha+1)) (Eq. 24), N.");
  m.def(
      "max_force_exact", [](const ContactLaw& l, double M) { return max_force_exact(l.law, M); }, "law"_a,
      "M_ie"_a, "The exact peak force of the single-body contact (Eq. 16), N.");
  m.def(
      "exact_peak", [](const ContactLaw& l, double M) { return exact_peak(l.law, M); }, "law"_a, "M_ie"_a);
  m.def(
      "relative_error", [](const ContactLaw& l) { return relative_error(l.law); }, "law"_a,
      "xi of Eq. 21, percent.");
  m.def(
      "approach_velocity",
      [](nb::handle u, nb::handle v_e, nb::handle v_t, nb::handle omega_t, nb::handle r) {
        const char* w = "approach_velocity";
        return approach_velocity(vec3(u, w, "u"), vec3(v_e, w, "v_e"), vec3(v_t, w, "v_t"),
                                 vec3(omega_t, w, "omega_t"), vec3(r, w, "r"));
      },
      "u"_a, "v_e"_a, "v_t"_a, "omega_t"_a, "r"_a,
      "delta_dot^- = u . (v_e - (v_t + omega_t x r)) (Eq. 10-12), inertial frame; positive when "
      "approaching.");
  m.def("model_accuracy", &model_accuracy, "F_model"_a, "F_exact"_a,
        "Model accuracy of Eq. 32, percent: (1 - |F_model - F_exact| / F_exact) x 100.");
}

void bind_single_body(nb::module_& m) {
  nb::class_<SingleBodyResult>(m, "SingleBodyResult", "Result of simulate_single_body, SI units.")
      .def_ro("f_max", &SingleBodyResult::f_max)
      .def_ro("t_at_f_max", &SingleBodyResult::t_at_f_max)
      .def_ro("delta_at_f_max", &SingleBodyResult::delta_at_f_max)
      .def_ro("delta_dot_at_f_max", &SingleBodyResult::delta_dot_at_f_max)
      .def_ro("delta_max", &SingleBodyResult::delta_max)
      .def_ro("t_at_delta_max", &SingleBodyResult::t_at_delta_max)
      .def_ro("contact_duration", &SingleBodyResult::contact_duration)
      .def_ro("separation_velocity", &SingleBodyResult::separation_velocity)
      .def_ro("restitution", &SingleBodyResult::restitution)
      .def_ro("num_steps", &SingleBodyResult::num_steps)
      .def_prop_ro(
          "t", [](const SingleBodyResult& r) { return array_of(r.series.t); },
          "Series (record_series): time, s.", nb::rv_policy::automatic)
      .def_prop_ro(
          "force", [](const SingleBodyResult& r) { return array_of(r.series.force); }, "Series: F, N.",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "delta", [](const SingleBodyResult& r) { return array_of(r.series.delta); }, "Series: delta, m.",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "delta_dot", [](const SingleBodyResult& r) { return array_of(r.series.delta_dot); },
          "Series: delta_dot, m/s.", nb::rv_policy::automatic);

  m.def(
      "simulate_single_body",
      [](const ContactLaw& law, double M_ie, bool record_series, double rtol, double atol) {
        SingleBodyOptions o;
        o.record_series = record_series;
        o.cvode.rtol = rtol;
        o.cvode.atol = atol;
        nb::gil_scoped_release release;
        return simulate_single_body(law.law, M_ie, o);
      },
      "law"_a, "M_ie"_a, "record_series"_a = false, "rtol"_a = cvode::Options{}.rtol,
      "atol"_a = cvode::Options{}.atol,
      "Integrates the single-body contact M_ie delta'' + lambda delta^alpha delta' + K delta^alpha = 0 (Eq. "
      "16)\n"
      "from first touch to separation with CVODE (scaled state; tolerances in those units).");
}

namespace {

/// Robot and target at one instant of the contact run (MultibodyContactResult::start, end).
void bind_contact_bodies(nb::module_& m) {
  nb::class_<ContactBodies>(m, "ContactBodies",
                            "Robot and target at one instant of the contact run (inertial frame): the\n"
                            "base pose, joint angles, generalized velocity [v0, w0, theta_dot]; the\n"
                            "target's pose, velocity and spin.")
      .def_ro("base", &ContactBodies::base)
      .def_prop_ro(
          "theta", [](const ContactBodies& b) { return out(b.theta); }, nb::rv_policy::automatic)
      .def_prop_ro(
          "v", [](const ContactBodies& b) { return out(b.v); }, nb::rv_policy::automatic)
      .def_ro("target", &ContactBodies::target);
}

}  // namespace

void bind_multibody_contact(nb::module_& m) {
  bind_contact_bodies(m);
  nb::class_<MultibodyContactResult>(m, "MultibodyContactResult", "Result of simulate_contact, SI units.")
      .def_ro("model", &MultibodyContactResult::model, "Contact law name.")
      .def_ro("approach_velocity", &MultibodyContactResult::approach_velocity)
      .def_ro("integrated_effective_mass", &MultibodyContactResult::integrated_effective_mass)
      .def_ro("f_max", &MultibodyContactResult::f_max)
      .def_ro("t_at_f_max", &MultibodyContactResult::t_at_f_max)
      .def_ro("delta_at_f_max", &MultibodyContactResult::delta_at_f_max)
      .def_ro("delta_max", &MultibodyContactResult::delta_max)
      .def_ro("contact_duration", &MultibodyContactResult::contact_duration)
      .def_ro("separation_velocity", &MultibodyContactResult::separation_velocity)
      .def_ro("restitution", &MultibodyContactResult::restitution)
      .def_prop_ro(
          "momentum_start", [](const MultibodyContactResult& r) { return out(r.momentum_start); },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "momentum_end", [](const MultibodyContactResult& r) { return out(r.momentum_end); },
          nb::rv_policy::automatic)
      .def_ro("energy_start", &MultibodyContactResult::energy_start)
      .def_ro("energy_end", &MultibodyContactResult::energy_end)
      .def_ro("steps", &MultibodyContactResult::steps)
      .def_prop_ro(
          "base_velocity_start", [](const MultibodyContactResult& r) { return out(r.base_velocity_start); },
          nb::rv_policy::automatic)
      .def_prop_ro(
          "base_velocity_end", [](const MultibodyContactResult& r) { return out(r.base_velocity_end); },
          nb::rv_policy::automatic)
      .def_ro("start", &MultibodyContactResult::start, "Robot and target at the first touch.")
      .def_ro("end", &MultibodyContactResult::end,
              "Robot and target at the separation (the penetration back to zero).")
      .def_prop_ro(
          "t", [](const MultibodyContactResult& r) { return series_of(r, &ContactSample::t); },
          "Series (record_series): time, s.", nb::rv_policy::automatic)
      .def_prop_ro(
          "force", [](const MultibodyContactResult& r) { return series_of(r, &ContactSample::force); },
          "Series: F, N.", nb::rv_policy::automatic)
      .def_prop_ro(
          "delta", [](const MultibodyContactResult& r) { return series_of(r, &ContactSample::delta); },
          "Series: delta, m.", nb::rv_policy::automatic);

  m.def(
      "simulate_contact",
      [](const Model& model, const BasePose& base, nb::handle theta, nb::handle frame, const Target& target,
         double approach_speed, const ContactParams& params, const std::string& law, bool record_series,
         nb::handle robot_contact_offset, nb::handle joint_stiffness, nb::handle joint_damping,
         nb::handle armature, double rtol, double max_duration) {
        const char* w = "simulate_contact";
        const VecIn th(theta, w, "theta");
        speed_arg(approach_speed, w, "approach_speed");
        MultibodyContactOptions o;
        o.record_series = record_series;
        o.rtol = rtol;
        o.max_duration = max_duration;
        if (!robot_contact_offset.is_none())
          o.robot_contact_offset = vec3(robot_contact_offset, w, "robot_contact_offset");
        if (!joint_stiffness.is_none()) o.joint_stiffness = vecx(joint_stiffness, w, "joint_stiffness");
        if (!joint_damping.is_none()) o.joint_damping = vecx(joint_damping, w, "joint_damping");
        if (!armature.is_none()) o.armature = vecx(armature, w, "armature");
        const int f = frame_arg(model, frame, w);
        const Eigen::VectorXd q = th.map();
        nb::gil_scoped_release release;
        return simulate_contact(model, base, q, f, target, approach_speed, params, law, o);
      },
      "model"_a, "base"_a, "theta"_a, "frame"_a.none() = nb::none(), "target"_a = Target(),
      "approach_speed"_a = 0.2052, "params"_a = ContactParams(), "law"_a = "herbert-mcwhannell",
      "record_series"_a = false, "robot_contact_offset"_a.none() = nb::none(),
      "joint_stiffness"_a.none() = nb::none(), "joint_damping"_a.none() = nb::none(),
      "armature"_a.none() = nb::none(), "rtol"_a = MultibodyContactOptions{}.rtol, "max_duration"_a = 0.0,
      "The full robot-plus-target contact simulation (Figure 2; the paper's reference of Tables 3 and 6):\n"
      "the free-floating robot at the capture configuration theta, its contact point moving at\n"
      "approach_speed (m/s) along the target's normal with zero momentum, the target placed to touch it\n"
      "(its position is ignored), integrated with CVODE from first touch to separation. Joints passive,\n"
      "or a PD servo (joint_stiffness, joint_damping) holding the pre-contact rates and an armature.");
}

}  // namespace ffsr::python
