// ffsr-optimize inspect: evaluate one configuration (H, J_f, m_e, M_ie, the base's jump at the impact,
// the distances between the shapes; the job is the library's, ffsr/jobs/inspect.hpp) and print it.
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/inspect.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <set>

namespace ffsr::cli {
namespace {

struct InspectOptions {
  SubjectOptions subject;
  OutputKeys out;  ///< --json, --quiet
};

void print_clearance(std::ostream& out, const ClearanceReport& c) {
  out << "distances        ";
  const std::pair<const char*, const ClearanceReport::Entry*> kinds[] = {
      {"arm-target", &c.arm_target}, {"arm-bus", &c.arm_bus}, {"self", &c.self}};
  bool first = true;
  for (const auto& [name, e] : kinds) {
    if (e->pair.empty()) continue;
    out << (first ? "" : ", ") << name << " " << e->distance << " m (" << e->pair << ")";
    first = false;
  }
  out << (first ? "no pair of bodies" : "") << "\n";
}

/// What the loader did to the file: merged links, mimic and locked joints, repairs.
void print_load_report(std::ostream& out, const UrdfReport& rep) {
  auto line = [&out](const char* label, const std::vector<std::string>& items) {
    if (items.empty()) return;
    out << label;
    for (size_t i = 0; i < items.size(); ++i) out << items[i] << (i + 1 < items.size() ? ", " : "\n");
  };
  line("merged into base ", rep.merged_links);
  std::vector<std::string> m, l, r;
  for (const auto& x : rep.mimics)
    m.push_back(detail::str(x.joint, " = ", x.multiplier, " * ", x.leader, " + ", x.offset));
  for (const auto& x : rep.locked) l.push_back(detail::str(x.first, " = ", x.second));
  for (const auto& x : rep.repairs) r.push_back(detail::str(x.link, ": ", x.what));
  line("mimic joints     ", m);
  line("locked joints    ", l);
  line("inertia repairs  ", r);
}

void print_inspect(std::ostream& out, const Scenario& s, const InspectResult& e) {
  out << std::setprecision(6);
  out << "robot            " << s.keys.urdf << " (" << s.model->n() << " joints, " << s.model->total_mass()
      << " kg)\n";
  out << "end-effector     " << s.model->frame(s.problem.frame).name << " at ["
      << e.ee.p.transpose().format(Eigen::IOFormat(6, 0, ", ")) << "] m\n";
  out << "joints           ";
  const auto names = s.model->joint_names();
  for (size_t i = 0; i < names.size(); ++i)
    out << names[i] << "=" << s.problem.theta(static_cast<Eigen::Index>(i)) * 180.0 / M_PI
        << (i + 1 < names.size() ? ", " : " deg\n");
  print_load_report(out, s.report);
  out << "direction u      [" << e.u.transpose().format(Eigen::IOFormat(6, 0, ", ")) << "]\n";
  if (e.joints.model != JointModel::Free)
    out << "contact joints   " << joint_model_name(e.joints.model) << " (M_ie, m_e and the base jump)\n";
  out << "effective mass   m_e  = " << e.m_e << " kg   (Eq. 4)\n";
  out << "integrated mass  M_ie = " << e.M_ie << " kg   (Eq. 14)\n";
  if (e.disturbance)
    out << "base jump        |dw_0| = " << e.disturbance->angular_rate() * 180.0 / M_PI
        << " deg/s, |dv_0| = " << e.disturbance->linear.norm() << " m/s   (impulse " << e.disturbance->impulse
        << " N s, "
        << s.problem.law << ")\n";
  else
    out << "base jump        none: the end-effector does not approach the target at --approach-speed\n";
  if (e.clearance) print_clearance(out, *e.clearance);
  out << "J_f (generalized Jacobian, 6x" << s.model->n() << ", linear rows first):\n"
      << e.Jf.format(Eigen::IOFormat(5, 0, "  ", "\n", "  ")) << "\n";
}

int run_inspect(const InspectOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs = o.out.outputs();  // --json '-': the table goes to standard error
  const Scenario s = load_subject(o.subject);
  const EmbeddedUrdf embedded = builtin_urdf();
  const InspectResult e = inspect(s, &embedded);
  outputs.set("--json", inspect_json(s, e, FFSR_VERSION).dump(2) + "\n");
  outputs.write();
  print_inspect(outputs.table(), s, e);
  return 0;
}

}  // namespace

void register_inspect(CLI::App& app, Action& action) {
  auto opts = std::make_shared<InspectOptions>();
  CLI::App* sub =
      app.add_subcommand("inspect",
                         "Evaluate one configuration (a scenario's start state; flags override it): H, J_f, "
                         "effective mass, M_ie, the base's jump at the impact, distances between shapes");
  // where the target is and the shapes: the distances between them (the clearance constrains plans only)
  std::set<std::string> also = scenario_key_names({KeyGroup::TargetPlace, KeyGroup::Shapes});
  also.erase("clearance");
  also.erase("contact-exemption");  // the distances are between whole bodies: no contact zone is exempt
  also.insert({"contact-joints", "armature"});  // the joint model of M_ie, m_e and the base's jump
  // the base's jump at the impact depends on the law's damping (model, restitution), not on K or alpha
  opts->subject.add_to(*sub, also, {"stiffness", "exponent"});
  add_output_flags(*sub, opts->out, {"Write the evaluation (H, J_f, m_e, M_ie, ...) as JSON to FILE"});
  sub->callback([opts, &action] { action = [opts] { return run_inspect(*opts); }; });
}

}  // namespace ffsr::cli
