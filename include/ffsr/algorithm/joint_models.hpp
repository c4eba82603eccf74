// ffsr/algorithm/joint_models.hpp -- what the arm's joints do during the few milliseconds of a
// contact (free, locked, armature), their names and armature values, and the argument checks the
// effective-mass routes share. The effective mass and M_ie (Eq. 14) under each model:
// effective_mass.hpp; their gradients: effective_mass_gradient.hpp.
#pragma once

#include "ffsr/algorithm/crba.hpp"

#include <string>
#include <vector>

namespace ffsr {

/// The joints' behaviour during the impact.
///  - Free: the joints carry no torque during the impact (the paper's assumption): the inverse
///    effective mass along u at the contact point is u^T J_v H^-1 J_v^T u.
///  - Locked: the joints do not move during the impact; base and arm react as one rigid body (the
///    composite rigid body): u^T J_b H_bb^-1 J_b^T u, with H_bb the 6x6 base block of H (the
///    composite inertia of the whole robot about the base origin) and J_b the base columns of the
///    point Jacobian, J_b^T u = [u; (p_e - p_0) x u].
///  - Armature: free joints with a reflected rotor inertia a_k per coordinate (N^2 times the
///    rotor's inertia behind a gear of ratio N; kg m^2, or kg for a prismatic joint) added to H's
///    joint diagonal: u^T J_v (H + diag(0, a))^-1 J_v^T u. It runs from Free (a = 0) towards Locked
///    (a -> infinity). The rotor's own (un-reflected) mass and inertia belong to the link model.
enum class JointModel { Free, Locked, Armature };

inline const char* joint_model_name(JointModel m) {
  switch (m) {
    case JointModel::Locked:
      return "locked";
    case JointModel::Armature:
      return "armature";
    default:
      return "free";
  }
}

/// The joint model named `name` (free, locked, armature); InputError naming `where` otherwise.
inline JointModel parse_joint_model(const std::string& name, const std::string& where) {
  if (name == "free") return JointModel::Free;
  if (name == "locked") return JointModel::Locked;
  if (name != "armature")
    FFSR_THROW(InputError(detail::str(where, ": unknown joint model '", name, "'; use free, locked or armature")));
  return JointModel::Armature;
}

/// One non-negative finite value per coordinate of `model` from `values`: empty gives zeros, one value
/// is used for every joint, otherwise there must be n. InputError naming `where` (a key, "--armature"),
/// listing the joints when the count is wrong, naming the joint of a bad value.
inline Eigen::VectorXd per_joint_values(const std::vector<double>& values, const Model& model,
                                        const std::string& where) {
  const int n = model.n();
  if (!values.empty() && values.size() != 1 && int(values.size()) != n) {
    std::string list;
    for (const auto& name : model.joint_names()) list += (list.empty() ? "" : ", ") + name;
    FFSR_THROW(InputError(detail::str(where, ": ", values.size(), " values for ", n, " joints (", list,
                                 "); give one value or one per joint")));
  }
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    if (!values.empty()) v(k) = values.size() == 1 ? values[0] : values[size_t(k)];
    if (!(v(k) >= 0) || !std::isfinite(v(k)))
      FFSR_THROW(InputError(detail::str(where, ": the value of joint '", model.joint(k).name,
                                   "' must be finite and >= 0, got ", v(k))));
  }
  return v;
}

/// The joints' model during the contact, with the armature per coordinate (size n; used by the
/// Armature model, and by the multibody reference whatever the model).
struct ContactJoints {
  JointModel model = JointModel::Free;
  Eigen::VectorXd armature;
};

/// The joint model of a scenario: `name` (key contact-joints) and the armature values (key armature,
/// per_joint_values). InputError naming the key.
inline ContactJoints contact_joints_of(const std::string& name, const std::vector<double>& armature,
                                       const Model& model) {
  return {parse_joint_model(name, "--contact-joints"), per_joint_values(armature, model, "--armature")};
}

namespace detail {

inline void check_frame(const Model& model, int frame, const char* where) {
  if (frame < 0 || frame >= static_cast<int>(model.frames().size()))
    FFSR_THROW(InputError(str(where, ": frame index ", frame, " out of range")));
}

inline void check_unit_direction(const Vector3& u, const char* where) {
  require_finite_all(u, where, "direction u");
  if (std::abs(u.norm() - 1.0) > 1e-9)
    FFSR_THROW(InputError(str(where, ": direction u must be a unit vector, |u| = ", u.norm())));
}

}  // namespace detail

}  // namespace ffsr
