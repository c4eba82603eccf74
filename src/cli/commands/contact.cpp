// ffsr-optimize contact: closed-form, exact and multibody (CVODE) maximum contact force (the job is the
// library's, ffsr/jobs/contact.hpp): the table and Figure 3.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "figures/figures.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/contact.hpp"

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

/// Figure 3 from the same rows; the marked points from the multibody run.
StagedFiles plot_contact(const std::vector<ContactRow>& rows, const ContactParams& params,
                         const ContactOptions& o, plot::Format plot_format) {
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
  return plot::draw({figures::contact(curves, rows.front().M_ie, rows.front().v_in)}, o.out.plot,
                    plot_format);
}

/// The closed-form predictions under the joint models beside the multibody run (when not only free).
void print_joint_predictions(std::ostream& out, const std::vector<ContactRow>& rows) {
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

void print_contact_table(std::ostream& out, const std::vector<ContactRow>& rows) {
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

int run_contact(const ContactOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs = o.out.outputs();  // an output on standard output: the table goes to standard error
  const Scenario subject = load_subject(o.subject);
  const plot::Format plot_format = plot::check_request(o.out.plot, o.out.plot_format);
  ContactJobOptions job;
  job.record_series = !o.out.csv.empty() || !o.out.plot.empty();
  const std::vector<ContactRow> rows = contact(subject, job);
  if (!o.out.plot.empty()) outputs.stage(plot_contact(rows, subject.problem.contact, o, plot_format));
  outputs.set("--json", contact_json(subject, rows, FFSR_VERSION).dump(2) + "\n");
  if (!o.out.csv.empty()) outputs.set("--csv", contact_series_csv(rows));
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
