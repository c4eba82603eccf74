// ffsr/jobs/contact.hpp -- the job `contact`: the maximum contact force at a scenario's start
// configuration (any scope, scenario/scenario.hpp) by the closed form (Eq. 24), the exact single-body
// peak (Eq. 16) and the multibody reference (CVODE: robot + target, Figure 2), for one law of Table 1
// or every law, under one joint model of the contact or each; and that result as JSON (the keys and
// values of `ffsr-optimize contact --json`) and its series as CSV (`--csv`). Component ffsr::scenario
// (and SUNDIALS: ffsr::cvode). Never prints.
#pragma once

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/jobs/detail/json_values.hpp"
#include "ffsr/jobs/inspect.hpp"
#include "ffsr/optimize/objective.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace ffsr {

/// One law's row of the job.
struct ContactRow {
  std::string model;  ///< the law's name (Table 1)
  double M_ie = 0;    ///< Eq. 14 under the chosen joint model (free for 'all'), kg
  double v_in = 0;    ///< delta_dot^- of the multibody run, m/s
  double f_closed = 0, f_exact = 0, f_multibody = 0;  ///< Eq. 24, Eq. 16, the multibody peak, N
  double accuracy = 0;  ///< Eq. 32, closed form vs multibody, percent
  double xi = 0;        ///< the closed form's relative error xi (Eq. 25), percent
  double delta_max = 0;                     ///< the closed form's largest deformation, m
  double t_peak = 0, duration = 0;          ///< of the multibody run, s
  double restitution = 0;                   ///< realized by the multibody run
  std::vector<ContactSample> series;        ///< F(t), delta(t) of the multibody run (record_series)
  double mb_delta_max = 0, mb_delta_at_f_max = 0;  ///< of the multibody run, for the F-delta figure
  BaseDisturbance base_jump{};                     ///< predicted from the configuration (single-body impulse)
  /// [dv_0; dw_0] of the multibody run, separation - first touch
  Vector6 base_jump_multibody = Vector6::Zero();
  struct Prediction {
    JointModel joints;
    double M_ie, f_closed, f_exact;
  };
  std::vector<Prediction> predictions;  ///< contact-joints all: free, locked, armature
};

struct ContactJobOptions {
  bool record_series = false;  ///< keep F(t), delta(t) of each multibody run (ContactRow::series)
};

/// The laws to evaluate: every law of Table 1 for model 'all', else the one named. InputError naming
/// --model (an unknown name lists the laws).
std::vector<std::string> contact_laws(const Scenario& s);

/// One law's row: the multibody run (the scenario's joint-stiffness, joint-damping and armature), the
/// closed form and exact peaks at its approach velocity under the joint model(s), the base's jump.
ContactRow contact_row(const Scenario& s, const std::string& law, const ContactJobOptions& options = {});

/// The job: a row for each law of contact_laws(s).
std::vector<ContactRow> contact(const Scenario& s, const ContactJobOptions& options = {});

/// The rows as JSON: the keys and values of `ffsr-optimize contact --json` (`version` as given).
nlohmann::json contact_json(const Scenario& s, const std::vector<ContactRow>& rows,
                            const std::string& version);

/// F(t), delta(t) of the multibody run(s) (record_series) as the CSV of `ffsr-optimize contact --csv`.
std::string contact_series_csv(const std::vector<ContactRow>& rows);

namespace detail {

/// The closed-form predictions under each joint model asked for (the chosen one, or all three): the
/// capture objective's M_ie and peaks (CaptureEvaluator).
inline std::vector<ContactRow::Prediction> joint_predictions(const Scenario& s, const AnyContactLaw& law) {
  ContactJoints joints = s.contact_joints();
  std::vector<JointModel> models{joints.model};
  if (s.all_joint_models()) models = {JointModel::Free, JointModel::Locked, JointModel::Armature};
  std::vector<ContactRow::Prediction> out;
  Data data(*s.model);
  for (JointModel m : models) {
    joints.model = m;
    const CaptureEvaluator objective(*s.model, s.problem.frame, s.problem.target, &law, joints);
    const double M = objective.mass(data, s.problem.base, s.problem.theta);
    out.push_back({m, M, objective.f_max_closed_form(M), objective.f_max_exact(M)});
  }
  return out;
}

inline nlohmann::json contact_row_json(const ContactRow& r) {
  nlohmann::json j = {{"model", r.model},
                      {"integrated_effective_mass", r.M_ie},
                      {"approach_velocity", r.v_in},
                      {"f_max_closed_form", r.f_closed},
                      {"f_max_exact", r.f_exact},
                      {"f_max_multibody", r.f_multibody},
                      {"model_accuracy", r.accuracy},
                      {"relative_error_xi", r.xi},
                      {"delta_max", r.delta_max},
                      {"time_of_peak", r.t_peak},
                      {"contact_duration", r.duration},
                      {"restitution_realized", r.restitution}};
  j["base_disturbance"] = {
      {"impulse", r.base_jump.impulse},
      {"restitution_single_body", r.base_jump.restitution},
      {"angular_velocity_jump", vector_json(Eigen::VectorXd(r.base_jump.angular))},
      {"angular_velocity_jump_multibody", vector_json(Eigen::VectorXd(r.base_jump_multibody.tail<3>()))},
      {"linear_velocity_jump", vector_json(Eigen::VectorXd(r.base_jump.linear))},
      {"linear_velocity_jump_multibody", vector_json(Eigen::VectorXd(r.base_jump_multibody.head<3>()))},
      {"angular_rate_jump_deg_s", r.base_jump.angular_rate() * 180.0 / M_PI},
      {"angular_rate_jump_multibody_deg_s", r.base_jump_multibody.tail<3>().norm() * 180.0 / M_PI}};
  if (r.predictions.size() > 1 || r.predictions.front().joints != JointModel::Free) {  // joint models
    j["contact_joints"] = r.predictions.size() > 1 ? "all" : joint_model_name(r.predictions.front().joints);
    for (const auto& x : r.predictions)
      j["joint_models"].push_back({{"contact_joints", joint_model_name(x.joints)},
                                   {"integrated_effective_mass", x.M_ie},
                                   {"f_max_closed_form", x.f_closed},
                                   {"f_max_exact", x.f_exact}});
  }
  return j;
}

}  // namespace detail

inline std::vector<std::string> contact_laws(const Scenario& s) {
  std::vector<std::string> names;
  if (s.problem.law == "all") {
    for (auto n : contact_law_names()) names.emplace_back(n);
    return names;
  }
  try {
    make_contact_law(s.problem.law, s.problem.contact, 1.0);  // unknown name: lists the laws
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, std::string("--model: ") + e.what()));
  }
  names.push_back(s.problem.law);
  return names;
}

inline ContactRow contact_row(const Scenario& s, const std::string& law_name, const ContactJobOptions& o) {
  const Target& target = s.problem.target;
  const ContactParams& p = s.problem.contact;
  MultibodyContactOptions mo;
  mo.record_series = o.record_series;
  try {  // located in the file when the file gave the key
    mo.joint_stiffness = per_joint_values(s.keys.joint_stiffness, *s.model, "--joint-stiffness");
    mo.joint_damping = per_joint_values(s.keys.joint_damping, *s.model, "--joint-damping");
    mo.armature = per_joint_values(s.keys.armature, *s.model, "--armature");
  } catch (const InputError& e) {
    throw InputError(located_key_message(s.keys, e.what()));
  }
  MultibodyContactResult mb =
      simulate_contact(*s.model, s.problem.base, s.problem.theta, s.problem.frame, target,
                       s.problem.approach_speed, p, law_name, mo);
  const AnyContactLaw law = make_contact_law(law_name, p, mb.approach_velocity);
  auto predictions = detail::joint_predictions(s, law);
  const double M_ie = predictions.front().M_ie;  // the chosen model's (free for all)
  ContactJoints joints = s.contact_joints();
  joints.model = predictions.front().joints;
  ContactRow row;
  row.model = law_name;
  row.M_ie = M_ie;
  row.v_in = mb.approach_velocity;
  row.f_closed = max_force_closed_form(law, M_ie);
  row.f_exact = max_force_exact(law, M_ie);
  row.f_multibody = mb.f_max;
  row.xi = relative_error(law);
  row.delta_max = max_deformation(law, M_ie);
  row.t_peak = mb.t_at_f_max;
  row.duration = mb.contact_duration;
  row.restitution = mb.restitution;
  row.series = std::move(mb.series);
  row.predictions = std::move(predictions);
  row.accuracy = model_accuracy(row.f_closed, row.f_multibody);
  row.mb_delta_max = mb.delta_max;
  row.mb_delta_at_f_max = mb.delta_at_f_max;
  row.base_jump_multibody = mb.base_velocity_end - mb.base_velocity_start;
  Data data(*s.model);  // the target's position does not enter (only its attitude, inertia and offset)
  row.base_jump =
      CaptureEvaluator(*s.model, s.problem.frame, target, &law, joints)
          .disturbance(data, s.problem.base, s.problem.theta);
  return row;
}

inline std::vector<ContactRow> contact(const Scenario& s, const ContactJobOptions& options) {
  std::vector<ContactRow> rows;
  for (const auto& n : contact_laws(s)) rows.push_back(contact_row(s, n, options));
  return rows;
}

inline nlohmann::json contact_json(const Scenario& s, const std::vector<ContactRow>& rows,
                                   const std::string& version) {
  nlohmann::json j =
      s.problem.law == "all" ? nlohmann::json::object() : detail::contact_row_json(rows.front());
  if (s.problem.law == "all") {
    j["integrated_effective_mass"] = rows.front().M_ie;
    j["approach_velocity"] = rows.front().v_in;
    j["laws"] = nlohmann::json::array();
    for (const auto& row : rows) j["laws"].push_back(detail::contact_row_json(row));
  }
  j["parameters"] = {{"stiffness", s.problem.contact.K},     {"exponent", s.problem.contact.alpha},
                     {"restitution", s.problem.contact.c_r}, {"approach_speed", s.problem.approach_speed},
                     {"urdf", s.keys.urdf},         {"joints_deg", s.keys.joints_deg}};
  j["version"] = version;
  return j;
}

inline std::string contact_series_csv(const std::vector<ContactRow>& rows) {
  std::ostringstream csv;
  csv << std::setprecision(12) << "model,t_s,force_N,delta_m\n";
  for (const auto& row : rows)
    for (const auto& s : row.series) csv << row.model << "," << s.t << "," << s.force << "," << s.delta << "\n";
  return csv.str();
}

}  // namespace ffsr
