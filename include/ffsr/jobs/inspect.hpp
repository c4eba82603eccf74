// ffsr/jobs/inspect.hpp -- the job `inspect`: one configuration of a subject (jobs/subject.hpp)
// evaluated: H, J_bm, J_f, the effective mass m_e (Eq. 4), the integrated effective mass M_ie (Eq. 14)
// and the base's jump at the impact under the subject's joint model, the distances between the shapes;
// and that evaluation as JSON (the keys and values of `ffsr-optimize inspect --json`). Component
// ffsr::scenario. Never prints.
#pragma once

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/jobs/subject.hpp"
#include "ffsr/optimize/objective.hpp"

#include <cmath>
#include <memory>
#include <optional>
#include <string>

namespace ffsr {

/// What inspect evaluates at the subject's configuration.
struct InspectResult {
  ContactJoints joints;  ///< the joint model of M_ie, m_e and the base's jump
  double M_ie = 0;       ///< Eq. 14, kg
  double m_e = 0;        ///< Eq. 4 along u, kg
  Vector3 u;             ///< the contact normal (the target's, inertial frame)
  Eigen::MatrixXd Jf;    ///< the generalized Jacobian J_f (6 x n, linear rows first)
  Pose ee;               ///< the end-effector's pose
  Data data;             ///< H (data.H) and J_bm (data.J) at the configuration
  /// the base's jump at the impact (single-body impulse); none when the end-effector moving at the
  /// approach speed along u does not approach the target's contact point
  std::optional<BaseDisturbance> disturbance;
  std::optional<ClearanceReport> clearance;  ///< with shapes: the distances at t = 0
  explicit InspectResult(const Model& model) : data(model) {}
};

/// Evaluates the subject's configuration. `embedded`: the URDF of a built-in scenario (its collision
/// shapes). InputError naming the key (contact-joints 'all' is refused: one joint model at a time;
/// --model when the law cannot be built at the approach velocity).
InspectResult inspect(const Subject& s, const EmbeddedUrdf* embedded = nullptr);

/// The evaluation as JSON: the keys and values of `ffsr-optimize inspect --json` (`version` recorded
/// as given).
nlohmann::json inspect_json(const Subject& s, const InspectResult& e, const std::string& version);

namespace detail {

/// A matrix as rows of numbers.
inline nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

/// The contact law at the approach velocity of the configuration, or nothing when the end-effector
/// moving at the approach speed along u does not approach the target's contact point.
inline std::optional<AnyContactLaw> inspect_law(const Subject& s) {
  const Target& target = s.target;
  const Vector3 u = target.normal_world();
  const double vin = approach_velocity(u, Vector3(s.approach_speed * u), target.velocity,
                                       target.angular_velocity_world(), target.offset_world());
  if (!(vin > 0)) return std::nullopt;
  try {
    return make_contact_law(s.law, s.params, vin);
  } catch (const InputError& e) {
    throw InputError(std::string("--model: ") + e.what());
  }
}

/// The distances of the configuration to the target at t = 0 (and to the bus, between the links) when
/// the scenario gives shapes (scenario/geometry.hpp), else nothing.
inline std::optional<ClearanceReport> inspect_clearance(const Subject& s, const EmbeddedUrdf* embedded) {
  const std::shared_ptr<const SceneGeometry> g =
      scene_geometry(s.keys, s.robot.model, s.target.contact_offset, embedded);
#ifdef FFSR_HAVE_GEOMETRY
  if (g)
    return configuration_clearance(s.robot.model, *g->checker, s.robot.base, s.robot.theta,
                                   target_pose(s.target));
#endif
  return std::nullopt;
}

inline nlohmann::json inspect_disturbance_json(const std::optional<BaseDisturbance>& d) {
  if (!d) return nullptr;
  return {{"impulse", d->impulse},
          {"restitution_single_body", d->restitution},
          {"approach_velocity", d->approach_velocity},
          {"angular_velocity_jump", vector_json(Eigen::VectorXd(d->angular))},
          {"angular_rate_jump_deg_s", d->angular_rate() * 180.0 / M_PI},
          {"linear_velocity_jump", vector_json(Eigen::VectorXd(d->linear))}};
}

}  // namespace detail

inline InspectResult inspect(const Subject& s, const EmbeddedUrdf* embedded) {
  if (s.all_joint_models())
    throw InputError(
        "--contact-joints: inspect evaluates one joint model; 'all' is for the contact subcommand");
  const Robot& r = s.robot;
  InspectResult e(r.model);
  e.joints = s.contact_joints();
  e.u = s.target.normal_world();
  const std::optional<AnyContactLaw> law = detail::inspect_law(s);
  // M_ie and the base's jump (single-body impulse) of the joint model: the capture objective's
  const CaptureEvaluator objective(r.model, r.end_effector, s.target, law ? &*law : nullptr, e.joints);
  if (law) e.disturbance = objective.disturbance(e.data, r.base, r.theta);
  e.M_ie = objective.mass(e.data, r.base, r.theta);
  e.m_e = 1.0 / inverse_effective_mass(r.model, e.data, r.end_effector, e.u, e.joints);
  frame_jacobian(r.model, e.data, r.end_effector);
  e.Jf = generalized_jacobian(r.model, e.data);
  e.ee = frame_pose(r.model, e.data, r.end_effector);
  e.clearance = detail::inspect_clearance(s, embedded);
  return e;
}

inline nlohmann::json inspect_json(const Subject& s, const InspectResult& e, const std::string& version) {
  using detail::matrix_json;
  using detail::vector_json;
  const Robot& r = s.robot;
  nlohmann::json j;
  j["urdf"] = s.keys.urdf;
  j["end_effector"] = r.model.frame(r.end_effector).name;
  j["joint_names"] = r.model.joint_names();
  j["joints_deg"] = vector_json(Eigen::VectorXd(r.theta * (180.0 / M_PI)));
  j["base_position"] = vector_json(Eigen::VectorXd(r.base.position));
  j["end_effector_position"] = vector_json(Eigen::VectorXd(e.ee.p));
  j["end_effector_rpy_deg"] = vector_json(Eigen::VectorXd(rpy_from_rotation(e.ee.R) * (180.0 / M_PI)));
  j["direction"] = vector_json(Eigen::VectorXd(e.u));
  j["H"] = matrix_json(e.data.H);
  j["J_bm"] = matrix_json(e.data.J);
  j["J_f"] = matrix_json(e.Jf);
  j["total_mass"] = r.model.total_mass();
  j["contact_joints"] = joint_model_name(e.joints.model);
  if (e.joints.model == JointModel::Armature) j["armature"] = vector_json(e.joints.armature);
  j["effective_mass"] = e.m_e;
  j["integrated_effective_mass"] = e.M_ie;
  j["base_disturbance"] = detail::inspect_disturbance_json(e.disturbance);
  j["clearance"] = e.clearance ? detail::clearance_json(*e.clearance) : nlohmann::json(nullptr);
  j["model_repairs"] = repairs_json(r.report);
  j["model_load"] = report_json(r.report);
  j["version"] = version;
  return j;
}

}  // namespace ffsr
