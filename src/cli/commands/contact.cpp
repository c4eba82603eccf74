// ffsr-optimize contact: closed-form, exact and multibody (CVODE) maximum contact force.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/scenario_run.hpp"

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/optimize/objective.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace ffsr::cli {
namespace {

struct ContactOptions {
  SubjectOptions subject;
  OutputKeys out;  ///< --json, --csv (also --series: F(t), delta(t)), --plot, --quiet
};

struct Row {
  std::string model;
  double M_ie, v_in, f_closed, f_exact, f_multibody, accuracy, xi, delta_max, t_peak, duration, restitution;
  std::vector<ContactSample> series;
  double mb_delta_max = 0, mb_delta_at_f_max = 0;  ///< of the multibody run, for the F-delta figure
  BaseDisturbance base_jump{};                     ///< predicted from the configuration (single-body impulse)
  Vector6 base_jump_multibody =
      Vector6::Zero();  ///< [dv_0; dw_0] of the multibody run, separation - first touch
  struct Prediction {
    JointModel joints;
    double M_ie, f_closed, f_exact;
  };
  std::vector<Prediction> predictions;  ///< --contact-joints all: free, locked, armature
};

/// The closed-form predictions under each joint model asked for (the chosen one, or all three): the
/// capture objective's M_ie and peaks (CaptureEvaluator).
std::vector<Row::Prediction> joint_predictions(const Subject& s, const AnyContactLaw& law) {
  const Robot& r = s.robot;
  ContactJoints joints = s.contact_joints();
  std::vector<JointModel> models{joints.model};
  if (s.all_joint_models()) models = {JointModel::Free, JointModel::Locked, JointModel::Armature};
  std::vector<Row::Prediction> out;
  Data data(r.model);
  for (JointModel m : models) {
    joints.model = m;
    const CaptureEvaluator objective(r.model, r.end_effector, s.target, &law, joints);
    const double M = objective.mass(data, r.base, r.theta);
    out.push_back({m, M, objective.f_max_closed_form(M), objective.f_max_exact(M)});
  }
  return out;
}

Row evaluate(const Subject& s, const ContactOptions& o, const std::string& law_name) {
  const Robot& r = s.robot;
  const Target& target = s.target;
  const ContactParams& p = s.params;
  MultibodyContactOptions mo;
  mo.record_series = !o.out.csv.empty() || !o.out.plot.empty();
  mo.joint_stiffness = per_joint_values(s.keys.joint_stiffness, r.model, "--joint-stiffness");
  mo.joint_damping = per_joint_values(s.keys.joint_damping, r.model, "--joint-damping");
  mo.armature = per_joint_values(s.keys.armature, r.model, "--armature");
  MultibodyContactResult mb =
      simulate_contact(r.model, r.base, r.theta, r.end_effector, target, s.approach_speed, p, law_name, mo);
  const AnyContactLaw law = make_contact_law(law_name, p, mb.approach_velocity);
  auto predictions = joint_predictions(s, law);
  const double M_ie = predictions.front().M_ie;  // the chosen model's (free for all)
  ContactJoints joints = s.contact_joints();
  joints.model = predictions.front().joints;
  Row row{law_name,
          M_ie,
          mb.approach_velocity,
          max_force_closed_form(law, M_ie),
          max_force_exact(law, M_ie),
          mb.f_max,
          0,
          relative_error(law),
          max_deformation(law, M_ie),
          mb.t_at_f_max,
          mb.contact_duration,
          mb.restitution,
          std::move(mb.series),
          0,
          0,
          {},
          Vector6::Zero(),
          std::move(predictions)};
  row.accuracy = model_accuracy(row.f_closed, row.f_multibody);
  row.mb_delta_max = mb.delta_max;
  row.mb_delta_at_f_max = mb.delta_at_f_max;
  row.base_jump_multibody = mb.base_velocity_end - mb.base_velocity_start;
  Data data(r.model);  // the target's position does not enter (only its attitude, inertia and offset)
  row.base_jump =
      CaptureEvaluator(r.model, r.end_effector, target, &law, joints).disturbance(data, r.base, r.theta);
  return row;
}

nlohmann::json row_json(const Row& r) {
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
      {"angular_velocity_jump", to_json(Eigen::VectorXd(r.base_jump.angular))},
      {"angular_velocity_jump_multibody", to_json(Eigen::VectorXd(r.base_jump_multibody.tail<3>()))},
      {"linear_velocity_jump", to_json(Eigen::VectorXd(r.base_jump.linear))},
      {"linear_velocity_jump_multibody", to_json(Eigen::VectorXd(r.base_jump_multibody.head<3>()))},
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

/// The laws to evaluate: every law for --model all, else the one named (an unknown name lists them).
std::vector<std::string> contact_laws(const Subject& s) {
  std::vector<std::string> names;
  if (s.law == "all") {
    for (auto n : contact_law_names()) names.emplace_back(n);
    return names;
  }
  try {
    make_contact_law(s.law, s.params, 1.0);  // unknown name: lists the laws
  } catch (const InputError& e) {
    throw InputError(std::string("--model: ") + e.what());
  }
  names.push_back(s.law);
  return names;
}

/// Figure 3 from the same rows; the marked points from the multibody run.
void plot_contact(const std::vector<Row>& rows, const ContactParams& params, const ContactOptions& o,
                  plot::Format plot_format) {
  std::vector<figures::ContactCurve> curves;
  for (const auto& row : rows) {
    figures::ContactCurve c;
    c.law = row.model;
    for (const auto& s : row.series) {
      c.t.push_back(s.t);
      c.delta.push_back(s.delta);
      c.force.push_back(s.force);
    }
    const AnyContactLaw law = make_contact_law(row.model, params, row.v_in);
    c.delta_max = row.mb_delta_max;
    c.force_at_delta_max = force(law, row.mb_delta_max, 0.0);  // delta_dot = 0 at the largest deformation
    c.delta_at_f_max = row.mb_delta_at_f_max;
    c.f_max = row.f_multibody;
    curves.push_back(std::move(c));
  }
  plot::render({figures::contact(curves, rows.front().M_ie, rows.front().v_in)}, o.out.plot, plot_format);
}

nlohmann::json contact_json(const std::vector<Row>& rows, const Subject& s) {
  nlohmann::json j = s.law == "all" ? nlohmann::json::object() : row_json(rows.front());
  if (s.law == "all") {
    j["integrated_effective_mass"] = rows.front().M_ie;
    j["approach_velocity"] = rows.front().v_in;
    j["laws"] = nlohmann::json::array();
    for (const auto& row : rows) j["laws"].push_back(row_json(row));
  }
  j["parameters"] = {{"stiffness", s.params.K},     {"exponent", s.params.alpha},
                     {"restitution", s.params.c_r}, {"approach_speed", s.approach_speed},
                     {"urdf", s.keys.urdf},         {"joints_deg", s.keys.joints_deg}};
  j["version"] = FFSR_VERSION;
  return j;
}

/// The closed-form predictions under the joint models beside the multibody run (when not only free).
void print_joint_predictions(std::ostream& out, const std::vector<Row>& rows) {
  const auto& first = rows.front().predictions;
  if (first.size() == 1 && first.front().joints == JointModel::Free) return;
  out << "\njoints during the contact (closed form and exact beside the multibody run):\n"
      << std::left << std::setw(20) << "model" << std::setw(10) << "joints" << std::right << std::setw(11)
      << "M_ie (kg)" << std::setw(13) << "closed (N)" << std::setw(13) << "exact (N)" << std::setw(15)
      << "multibody (N)\n";
  for (const auto& row : rows)
    for (const auto& x : row.predictions)
      out << std::left << std::setw(20) << row.model << std::setw(10) << joint_model_name(x.joints)
          << std::right << std::fixed << std::setprecision(2) << std::setw(11) << x.M_ie << std::setw(13)
          << x.f_closed << std::setw(13) << x.f_exact << std::setw(15) << row.f_multibody << "\n";
}

void print_contact_table(std::ostream& out, const std::vector<Row>& rows) {
  out << std::setprecision(6) << "integrated effective mass M_ie = " << rows.front().M_ie << " kg (Eq. 14)\n"
      << "approach velocity delta_dot^-  = " << rows.front().v_in << " m/s (Eq. 10-12)\n\n";
  out << std::left << std::setw(20) << "model" << std::right << std::setw(13) << "closed (N)" << std::setw(13)
      << "exact (N)" << std::setw(15) << "multibody (N)" << std::setw(13) << "accuracy %" << std::setw(10)
      << "xi %" << std::setw(13) << "duration ms" << std::setw(11) << "c_r real"
      << "\n";
  for (const auto& row : rows)
    out << std::left << std::setw(20) << row.model << std::right << std::fixed << std::setprecision(2)
        << std::setw(13) << row.f_closed << std::setw(13) << row.f_exact << std::setw(15) << row.f_multibody
        << std::setw(13) << row.accuracy << std::setw(10) << row.xi << std::setw(13) << row.duration * 1e3
        << std::setw(11) << std::setprecision(4) << row.restitution << "\n";
  out << "\nbase angular velocity jump at the impact, deg/s (predicted: single-body impulse; multibody: "
         "separation - first touch)\n";
  for (const auto& row : rows)
    out << std::left << std::setw(20) << row.model << std::right << std::scientific << std::setprecision(4)
        << std::setw(13) << row.base_jump.angular_rate() * 180.0 / M_PI << std::setw(15)
        << row.base_jump_multibody.tail<3>().norm() * 180.0 / M_PI << std::defaultfloat << "\n";
  print_joint_predictions(out, rows);
  out << "\nclosed: Eq. 24 (F at the maximum deformation); exact: peak of the single-body model Eq. 16;\n"
         "multibody: CVODE integration of robot + target (Figure 2); accuracy: Eq. 32, closed vs "
         "multibody.\n";
}

/// F(t), delta(t) of the multibody run(s).
std::string series_csv(const std::vector<Row>& rows) {
  std::ostringstream csv;
  csv << std::setprecision(12) << "model,t_s,force_N,delta_m\n";
  for (const auto& row : rows)
    for (const auto& s : row.series) csv << row.model << "," << s.t << "," << s.force << "," << s.delta << "\n";
  return csv.str();
}

int run_contact(const ContactOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs = o.out.outputs();  // an output on standard output: the table goes to standard error
  const Subject subject = load_subject(o.subject);
  const plot::Format plot_format = plot::check_request(o.out.plot, o.out.plot_format);
  std::vector<Row> rows;
  for (const auto& n : contact_laws(subject)) rows.push_back(evaluate(subject, o, n));
  if (!o.out.plot.empty()) plot_contact(rows, subject.params, o, plot_format);
  outputs.set("--json", contact_json(rows, subject).dump(2) + "\n");
  if (!o.out.csv.empty()) outputs.set("--csv", series_csv(rows));
  outputs.write();
  print_contact_table(outputs.table(), rows);
  return 0;
}

}  // namespace

void register_contact(CLI::App& app, Action& action) {
  auto o = std::make_shared<ContactOptions>();
  CLI::App* sub = app.add_subcommand(
      "contact", "Maximum contact force: closed form, exact, and CVODE multibody reference");
  // --model and --contact-joints also take 'all': every law of Table 1, every joint model
  o->subject.add_to(*sub, {"contact-joints", "armature", "joint-stiffness", "joint-damping"});
  add_output_flags(*sub, o->out,
                   {"Write the forces (every law asked for, the joint models, the base's jump) as JSON to FILE",
                    "Write F(t), delta(t) of the multibody run(s) as CSV to FILE",
                    "Draw the F-delta loop(s) and F(t) (Figure 3)", "--series"});
  sub->callback([o, &action] { action = [o] { return run_contact(*o); }; });
}

}  // namespace ffsr::cli
