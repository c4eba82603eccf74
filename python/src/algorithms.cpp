// python/src/algorithms.cpp -- the dynamics of ffsr._ffsr: kinematics, crba (H), rnea, the Jacobians
// J_bm and J_f, momentum (about the base origin and the centre of mass), the effective mass m_e
// (Eq. 4), the integrated effective mass M_ie (Eq. 14) and its gradient under each joint model. Every
// function is the C++ function of the same name; the matrices it leaves in its Data come back as
// read-only views (outputs.hpp).
#include "arguments.hpp"
#include "bindings.hpp"
#include "outputs.hpp"

#include "ffsr/algorithm/base_disturbance.hpp"

#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>

namespace ffsr::python {
namespace {

using namespace nb::literals;

/// Reads the configuration arguments shared by the algorithms; checks data against model.
struct Config {
  Config(const Model& model, const Data& data, nb::handle theta_h, const char* where)
      : theta(theta_h, where, "theta") {
    check_data(model, data, where);
  }
  VecIn theta;
};

const char* const kJointsDoc =
    "joints: the joints during the contact, 'free' (the paper's: no torque during the impact), 'locked'\n"
    "(base and arm react as one rigid body) or 'armature' (free joints with the reflected rotor inertia\n"
    "`armature` added to H's joint diagonal: one number for every joint, or one per joint).";

}  // namespace

void bind_kinematics(nb::module_& m) {
  m.def(
      "forward_kinematics",
      [](const Model& model, Data& data, const BasePose& base, nb::handle theta) {
        const Config c(model, data, theta, "forward_kinematics");
        forward_kinematics(model, data, base, c.theta.map());
      },
      "model"_a, "data"_a, "base"_a, "theta"_a,
      "Forward kinematics (RBDA 4.1, inertial frame). Writes every body frame into data (Data.positions,\n"
      "Data.rotations) and the joint motion subspaces.");

  m.def(
      "frame_pose",
      [](const Model& model, const Data& data, nb::handle frame) {
        check_data(model, data, "frame_pose");
        return frame_pose(model, data, frame_arg(model, frame, "frame_pose"));
      },
      "model"_a, "data"_a, "frame"_a.none() = nb::none(),
      "Pose of a frame (index or name; None: the end-effector) in the inertial frame, from the last\n"
      "forward_kinematics or crba.");

  m.def(
      "frame_jacobian",
      [](const Model& model, nb::handle data_h, nb::handle frame) {
        Data& data = nb::cast<Data&>(data_h);
        check_data(model, data, "frame_jacobian");
        return view(frame_jacobian(model, data, frame_arg(model, frame, "frame_jacobian")), data_h);
      },
      "model"_a, "data"_a, "frame"_a.none() = nb::none(),
      "Point Jacobian J_bm = [J_b J_m] of a frame's origin (Eq. 2), (6, 6+n), linear rows first, inertial\n"
      "frame, at the kinematics of the last crba or forward_kinematics. Returns a read-only view of data.J.");

  m.def(
      "generalized_jacobian",
      [](const Model& model, nb::handle data_h, const BasePose* base, nb::handle theta, nb::handle frame) {
        Data& data = nb::cast<Data&>(data_h);
        check_data(model, data, "generalized_jacobian");
        if (!base && theta.is_none()) return view(generalized_jacobian(model, data), data_h);
        if (!base || theta.is_none())
          throw InputError("generalized_jacobian: give both base and theta, or neither");
        const Config c(model, data, theta, "generalized_jacobian");
        return view(generalized_jacobian(model, data, *base, c.theta.map(),
                                         frame_arg(model, frame, "generalized_jacobian")),
                    data_h);
      },
      "model"_a, "data"_a, "base"_a.none() = nb::none(), "theta"_a.none() = nb::none(),
      "frame"_a.none() = nb::none(),
      "Generalized Jacobian J_f = J_m - J_b H_b^-1 H_bm (Eq. 29), (6, n): joint rates to the end-effector's\n"
      "velocity when the base moves under zero momentum. With base and theta: crba and frame_jacobian\n"
      "there first; without: from data.H and data.J of the last crba and frame_jacobian. Returns a\n"
      "read-only view of data.Jf.");
}

void bind_dynamics(nb::module_& m) {
  m.def(
      "crba",
      [](const Model& model, nb::handle data_h, const BasePose& base, nb::handle theta) {
        Data& data = nb::cast<Data&>(data_h);
        const Config c(model, data, theta, "crba");
        return view(crba(model, data, base, c.theta.map()), data_h);
      },
      "model"_a, "data"_a, "base"_a, "theta"_a,
      "Joint-space inertia matrix H of Eq. 1, (6+n, 6+n), by the composite rigid body algorithm (RBDA 6.2),\n"
      "in the generalized coordinates [v0, w0, theta_dot]. Returns a read-only view of data.H.");

  m.def(
      "rnea",
      [](const Model& model, nb::handle data_h, const BasePose& base, nb::handle theta, nb::handle v,
         nb::handle a) {
        Data& data = nb::cast<Data&>(data_h);
        const Config c(model, data, theta, "rnea");
        const VecIn vv(v, "rnea", "v"), aa(a, "rnea", "a");
        return view(rnea(model, data, base, c.theta.map(), vv.map(), aa.map()), data_h);
      },
      "model"_a, "data"_a, "base"_a, "theta"_a, "v"_a, "a"_a,
      "Inverse dynamics tau = H(q) a + C(q, v) of Eq. 1 by recursive Newton-Euler (RBDA 5.3), gravity\n"
      "model.gravity. v, a: (6+n,). The first six entries of tau are the force and the moment about the\n"
      "base frame origin (inertial frame). Returns a read-only view of data.tau.");

  m.def(
      "bias_forces",
      [](const Model& model, nb::handle data_h, const BasePose& base, nb::handle theta, nb::handle v) {
        Data& data = nb::cast<Data&>(data_h);
        const Config c(model, data, theta, "bias_forces");
        const VecIn vv(v, "bias_forces", "v");
        return view(bias_forces(model, data, base, c.theta.map(), vv.map()), data_h);
      },
      "model"_a, "data"_a, "base"_a, "theta"_a, "v"_a,
      "The bias C(q, v) of Eq. 1 (rnea with zero acceleration). Returns a read-only view of data.tau.");

  m.def(
      "inverse_inertia_matrix",
      [](const Model& model, Data& data, nb::handle frame) {
        check_data(model, data, "inverse_inertia_matrix");
        return out(Eigen::MatrixXd(
            inverse_inertia_matrix(model, data, frame_arg(model, frame, "inverse_inertia_matrix"))));
      },
      "model"_a, "data"_a, "frame"_a.none() = nb::none(),
      "The robot's 6x6 inverse inertia J H^-1 J^T at a frame's origin, from data.H of the last crba.");
}

void bind_momentum(nb::module_& m) {
  m.def(
      "momentum",
      [](const Model& model, const Data& data, nb::handle v) {
        check_data(model, data, "momentum");
        const VecIn vv(v, "momentum", "v");
        vv.require(model.nv());
        return out(momentum(model, data, vv.map()));
      },
      "model"_a, "data"_a, "v"_a,
      "Total momentum [P; L], L about the base frame origin, inertial frame, summed body by body at the\n"
      "last kinematics; equals the first six rows of H v.");

  m.def(
      "centroidal_momentum",
      [](const Model& model, const Data& data, nb::handle v) {
        check_data(model, data, "centroidal_momentum");
        const VecIn vv(v, "centroidal_momentum", "v");
        vv.require(model.nv());
        const CentroidalMomentum c = centroidal_momentum(model, data, vv.map());
        Vector6 h;
        h << c.linear, c.angular;
        return std::make_pair(out(c.com), out(h));
      },
      "model"_a, "data"_a, "v"_a,
      "The centroidal momentum from data.H of the last crba: (c, [P; L_c]), the system's centre of mass\n"
      "and its momentum, L_c about c, inertial frame (Pinocchio's computeCentroidalMomentum).");

  m.def(
      "kinetic_energy",
      [](const Model& model, const Data& data, nb::handle v) {
        check_data(model, data, "kinetic_energy");
        const VecIn vv(v, "kinetic_energy", "v");
        vv.require(model.nv());
        return kinetic_energy(model, data, vv.map());
      },
      "model"_a, "data"_a, "v"_a, "Kinetic energy 1/2 v^T H v, summed body by body at the last kinematics.");

  m.def(
      "base_velocity_from_momentum",
      [](const Model& model, const Data& data, nb::handle theta_dot, nb::handle h) {
        check_data(model, data, "base_velocity_from_momentum");
        const VecIn td(theta_dot, "base_velocity_from_momentum", "theta_dot");
        Vector6 hh = Vector6::Zero();
        if (!h.is_none()) {
          const VecIn hv(h, "base_velocity_from_momentum", "h");
          hv.require(6);
          hh = hv.map();
        }
        return out(base_velocity_from_momentum(model, data, td.map(), hh));
      },
      "model"_a, "data"_a, "theta_dot"_a, "h"_a.none() = nb::none(),
      "Base velocity [v0; w0] from momentum conservation H_b x_b_dot + H_bm theta_dot = h (default 0),\n"
      "from data.H of the last crba.");
}

void bind_effective_mass(nb::module_& m) {
  m.def(
      "effective_mass",
      [](const Model& model, Data& data, const BasePose& base, nb::handle theta, nb::handle frame,
         nb::handle u, const std::string& joints, nb::handle armature) {
        const Config c(model, data, theta, "effective_mass");
        const int f = frame_arg(model, frame, "effective_mass");
        const Vector3 uu = vec3(u, "effective_mass", "u");
        if (joints == "free" && armature.is_none())
          return effective_mass(model, data, base, c.theta.map(), f, uu);
        return effective_mass(model, data, base, c.theta.map(), f, uu,
                              joints_arg(model, joints, armature, "effective_mass"));
      },
      "model"_a, "data"_a, "base"_a, "theta"_a, "frame"_a.none(), "u"_a, "joints"_a = "free",
      "armature"_a.none() = nb::none(),
      (std::string("Effective mass m_e = 1 / (u^T J_v H^-1 J_v^T u) of the free-floating robot at a frame's\n"
                   "origin along the unit inertial direction u (Eq. 4), kg. Runs crba.\n") +
       kJointsDoc)
          .c_str());

  m.def(
      "integrated_effective_mass_gradient",
      [](const Model& model, Data& data, const BasePose& base, nb::handle theta, nb::handle frame,
         const Target* target, const std::string& joints, nb::handle armature) {
        const Config c(model, data, theta, "integrated_effective_mass_gradient");
        const int f = frame_arg(model, frame, "integrated_effective_mass_gradient");
        const Target& t = target_or_default(target);
        Eigen::VectorXd grad(model.n());
        const double M = integrated_effective_mass_gradient(
            model, data, base, c.theta.map(), f, t.normal_world(), t.inverse_mass_along_normal(),
            joints_arg(model, joints, armature, "integrated_effective_mass_gradient"), grad);
        return std::make_pair(M, out(grad));
      },
      "model"_a, "data"_a, "base"_a, "theta"_a, "frame"_a.none() = nb::none(), "target"_a.none() = nb::none(),
      "joints"_a = "free", "armature"_a.none() = nb::none(),
      (std::string(
           "(M_ie, dM_ie/dtheta): the integrated effective mass (Eq. 14) and its analytic O(n) gradient in\n"
           "the joint angles at a fixed base pose, for the contact direction u = R_t u_n (the objective of\n"
           "the null-space planner, Eq. 30-31), by the articulated-body recursion (mimic joints: the dense\n"
           "route inside it).\n") +
       kJointsDoc)
          .c_str());
}

void bind_integrated_effective_mass(nb::module_& m) {
  m.def(
      "integrated_effective_mass",
      [](const Model& model, Data& data, const BasePose& base, nb::handle theta, nb::handle frame,
         const Target* target, const std::string& joints, nb::handle armature) {
        const Config c(model, data, theta, "integrated_effective_mass");
        const Target& t = target_or_default(target);
        const int f = frame_arg(model, frame, "integrated_effective_mass");
        const Vector3 u = t.normal_world();
        if (joints == "free" && armature.is_none())  // the paper's joints, without the joint model's vectors
          return integrated_effective_mass(model, data, base, c.theta.map(), f, u,
                                                t.inverse_mass_along_normal());
        return integrated_effective_mass(
            model, data, base, c.theta.map(), f, u, t.inverse_mass_along_normal(),
            joints_arg(model, joints, armature, "integrated_effective_mass"));
      },
      "model"_a, "data"_a, "base"_a, "theta"_a, "frame"_a.none() = nb::none(), "target"_a.none() = nb::none(),
      "joints"_a = "free", "armature"_a.none() = nb::none(),
      (std::string("Integrated effective mass M_ie = 1 / (1/m_e + 1/m_t + (r x u)^T I^-1 (r x u))\n"
                   "(Eq. 14), kg, of the robot at (base, theta) with the end-effector frame (None: the\n"
                   "model's) touching `target` (None: the paper's); u = R_t u_n. In O(n) by the\n"
                   "articulated-body recursion (RBDA 7.3) with the joint model's contact inertia (locked:\n"
                   "the composite inertia of the whole robot), up to 7 joints (free, armature) by the\n"
                   "composite route (the floating base's Schur complement over the composite inertias); a\n"
                   "model with mimic joints takes crba and the dense solve. Writes the kinematics and the\n"
                   "routes' fields: do not rely on Data.H afterwards (integrated_effective_mass_dense\n"
                   "leaves H there).\n") +
       kJointsDoc)
          .c_str());

  m.def(
      "integrated_effective_mass",
      [](double m_e, const Target& target) { return integrated_effective_mass(m_e, target); }, "m_e"_a,
      "target"_a,
      "Integrated effective mass (Eq. 14) from the robot's effective mass m_e along u = R_t u_n.");

  m.def(
      "integrated_effective_mass_dense",
      [](const Model& model, Data& data, const BasePose& base, nb::handle theta, nb::handle frame,
         const Target* target, const std::string& joints, nb::handle armature) {
        const Config c(model, data, theta, "integrated_effective_mass_dense");
        const int f = frame_arg(model, frame, "integrated_effective_mass_dense");
        const Target& t = target_or_default(target);
        if (joints == "free" && armature.is_none())
          return integrated_effective_mass_dense(model, data, base, c.theta.map(), f, t);
        return integrated_effective_mass_dense(
            model, data, base, c.theta.map(), f, t,
            joints_arg(model, joints, armature, "integrated_effective_mass_dense"));
      },
      "model"_a, "data"_a, "base"_a, "theta"_a, "frame"_a.none() = nb::none(), "target"_a.none() = nb::none(),
      "joints"_a = "free", "armature"_a.none() = nb::none(),
      (std::string("M_ie (Eq. 14) as integrated_effective_mass, by crba and a dense Cholesky solve\n"
                   "(O(n^3)): the same value to rounding, for cross-checks; leaves H of (base, theta) in\n"
                   "Data.H.\n") +
       kJointsDoc)
          .c_str());
}

}  // namespace ffsr::python
