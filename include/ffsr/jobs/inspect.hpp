// ffsr/jobs/inspect.hpp -- the job `inspect`: the start configuration of a scenario (any scope,
// scenario/scenario.hpp) evaluated: H, J_bm, J_f, the effective mass m_e (Eq. 4), the integrated
// effective mass M_ie (Eq. 14) and the base's jump at the impact under the scenario's joint model, the
// distances between the shapes; and that evaluation as JSON (the keys and values of `ffsr-optimize
// inspect --json`). Component ffsr::scenario. Never prints.
#pragma once

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/objective.hpp"

#include <cmath>
#include <memory>
#include <optional>
#include <string>

namespace ffsr {

/// What inspect evaluates at the scenario's start configuration.
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

/// Evaluates the scenario's start configuration. `embedded`: the URDF of a built-in scenario (its collision
/// shapes). InputError naming the key (contact-joints 'all' is refused: one joint model at a time;
/// --model when the law cannot be built at the approach velocity).
InspectResult inspect(const Scenario& s, const EmbeddedUrdf* embedded = nullptr);

/// The evaluation as JSON: the keys and values of `ffsr-optimize inspect --json` (`version` recorded
/// as given).
nlohmann::json inspect_json(const Scenario& s, const InspectResult& e, const std::string& version);

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
inline std::optional<AnyContactLaw> inspect_law(const Scenario& s) {
  const Target& target = s.problem.target;
  const Vector3 u = target.normal_world();
  const double vin = approach_velocity(u, Vector3(s.problem.approach_speed * u), target.velocity,
                                       target.angular_velocity_world(), target.offset_world());
  if (!(vin > 0)) return std::nullopt;
  try {
    return make_contact_law(s.problem.law, s.problem.contact, vin);
  } catch (const InputError& e) {
    throw InputError(std::string("--model: ") + e.what());
  }
}

/// The distances of the configuration to the target at t = 0 (and to the bus, between the links) when
/// the scenario gives shapes (scenario/geometry.hpp), else nothing.
inline std::optional<ClearanceReport> inspect_clearance(const Scenario& s, const EmbeddedUrdf* embedded) {
  const std::shared_ptr<const SceneGeometry> g =
      scene_geometry(s.keys, *s.model, s.problem.target.contact_offset, embedded);
#ifdef FFSR_HAVE_GEOMETRY
  if (g)
    return configuration_clearance(*s.model, *g->checker, s.problem.base, s.problem.theta,
                                   target_pose(s.problem.target));
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

inline InspectResult inspect(const Scenario& s, const EmbeddedUrdf* embedded) {
  if (s.all_joint_models())
    throw InputError(
        "--contact-joints: inspect evaluates one joint model; 'all' is for the contact subcommand");
  InspectResult e(*s.model);
  e.joints = s.contact_joints();
  e.u = s.problem.target.normal_world();
  const std::optional<AnyContactLaw> law = detail::inspect_law(s);
  // M_ie and the base's jump (single-body impulse) of the joint model: the capture objective's
  const CaptureEvaluator objective(*s.model, s.problem.frame, s.problem.target, law ? &*law : nullptr,
                                   e.joints);
  if (law) e.disturbance = objective.disturbance(e.data, s.problem.base, s.problem.theta);
  e.M_ie = objective.mass(e.data, s.problem.base, s.problem.theta);
  e.m_e = 1.0 / inverse_effective_mass(*s.model, e.data, s.problem.frame, e.u, e.joints);
  frame_jacobian(*s.model, e.data, s.problem.frame);
  e.Jf = generalized_jacobian(*s.model, e.data);
  e.ee = frame_pose(*s.model, e.data, s.problem.frame);
  e.clearance = detail::inspect_clearance(s, embedded);
  return e;
}

inline nlohmann::json inspect_json(const Scenario& s, const InspectResult& e, const std::string& version) {
  using detail::matrix_json;
  using detail::vector_json;
  nlohmann::json j;
  j["urdf"] = s.keys.urdf;
  j["end_effector"] = s.model->frame(s.problem.frame).name;
  j["joint_names"] = s.model->joint_names();
  j["joints_deg"] = vector_json(Eigen::VectorXd(s.problem.theta * (180.0 / M_PI)));
  j["base_position"] = vector_json(Eigen::VectorXd(s.problem.base.position));
  j["end_effector_position"] = vector_json(Eigen::VectorXd(e.ee.p));
  j["end_effector_rpy_deg"] = vector_json(Eigen::VectorXd(rpy_from_rotation(e.ee.R) * (180.0 / M_PI)));
  j["direction"] = vector_json(Eigen::VectorXd(e.u));
  j["H"] = matrix_json(e.data.H);
  j["J_bm"] = matrix_json(e.data.J);
  j["J_f"] = matrix_json(e.Jf);
  j["total_mass"] = s.model->total_mass();
  j["contact_joints"] = joint_model_name(e.joints.model);
  if (e.joints.model == JointModel::Armature) j["armature"] = vector_json(e.joints.armature);
  j["effective_mass"] = e.m_e;
  j["integrated_effective_mass"] = e.M_ie;
  j["base_disturbance"] = detail::inspect_disturbance_json(e.disturbance);
  j["clearance"] = e.clearance ? detail::clearance_json(*e.clearance) : nlohmann::json(nullptr);
  j["model_repairs"] = repairs_json(s.report);
  j["model_load"] = report_json(s.report);
  j["version"] = version;
  return j;
}

}  // namespace ffsr
