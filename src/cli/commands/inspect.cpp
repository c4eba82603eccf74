// ffsr-optimize inspect: evaluate one configuration (H, J_f, m_e, M_ie, the base's jump at the impact,
// the distances between the shapes).
#include "support/output.hpp"
#include "support/parse.hpp"
#include "support/progress.hpp"
#include "support/subject.hpp"
#include "commands/subcommands.hpp"

#include "ffsr/jobs/scenario_run.hpp"

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/optimize/objective.hpp"

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

/// The contact law at the approach velocity of the configuration, or nothing when the end-effector
/// moving at the approach speed along u does not approach the target's contact point.
std::optional<AnyContactLaw> inspect_law(const Subject& s) {
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

nlohmann::json disturbance_json(const std::optional<BaseDisturbance>& d) {
  if (!d) return nullptr;
  return {{"impulse", d->impulse},
          {"restitution_single_body", d->restitution},
          {"approach_velocity", d->approach_velocity},
          {"angular_velocity_jump", to_json(Eigen::VectorXd(d->angular))},
          {"angular_rate_jump_deg_s", d->angular_rate() * 180.0 / M_PI},
          {"linear_velocity_jump", to_json(Eigen::VectorXd(d->linear))}};
}

/// The distances of the configuration to the target at t = 0 (and to the bus, between the links) when
/// the scenario gives shapes (io/scenario_geometry.hpp), else nothing.
std::optional<ClearanceReport> inspect_clearance(const Subject& s) {
  const EmbeddedUrdf embedded = builtin_urdf();
  const std::shared_ptr<const SceneGeometry> g =
      scene_geometry(s.keys, s.robot.model, s.target.contact_offset, &embedded);
#ifdef FFSR_HAVE_GEOMETRY
  if (g)
    return configuration_clearance(s.robot.model, *g->checker, s.robot.base, s.robot.theta,
                                   target_pose(s.target));
#endif
  return std::nullopt;
}

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

/// What inspect evaluates at the subject's configuration.
struct Evaluation {
  ContactJoints joints;  ///< the joint model of M_ie, m_e and the base's jump
  double M_ie = 0, m_e = 0;
  Vector3 u;
  Eigen::MatrixXd Jf;
  Pose ee;
  Data data;
  std::optional<BaseDisturbance> dist;
  std::optional<ClearanceReport> clearance;
  explicit Evaluation(const Model& model) : data(model) {}
};

Evaluation evaluate(const Subject& s) {
  if (s.all_joint_models())
    throw InputError(
        "--contact-joints: inspect evaluates one joint model; 'all' is for the contact subcommand");
  const Robot& r = s.robot;
  Evaluation e(r.model);
  e.joints = s.contact_joints();
  e.u = s.target.normal_world();
  const std::optional<AnyContactLaw> law = inspect_law(s);
  // M_ie and the base's jump (single-body impulse) of the joint model: the capture objective's
  const CaptureEvaluator objective(r.model, r.end_effector, s.target, law ? &*law : nullptr, e.joints);
  if (law) e.dist = objective.disturbance(e.data, r.base, r.theta);
  e.M_ie = objective.mass(e.data, r.base, r.theta);
  e.m_e = 1.0 / inverse_effective_mass(r.model, e.data, r.end_effector, e.u, e.joints);
  frame_jacobian(r.model, e.data, r.end_effector);
  e.Jf = generalized_jacobian(r.model, e.data);
  e.ee = frame_pose(r.model, e.data, r.end_effector);
  e.clearance = inspect_clearance(s);
  return e;
}

nlohmann::json inspect_json(const Subject& s, const Evaluation& e) {
  const Robot& r = s.robot;
  nlohmann::json j;
  j["urdf"] = s.keys.urdf;
  j["end_effector"] = r.model.frame(r.end_effector).name;
  j["joint_names"] = r.model.joint_names();
  j["joints_deg"] = to_json(Eigen::VectorXd(r.theta * (180.0 / M_PI)));
  j["base_position"] = to_json(Eigen::VectorXd(r.base.position));
  j["end_effector_position"] = to_json(Eigen::VectorXd(e.ee.p));
  j["end_effector_rpy_deg"] = to_json(Eigen::VectorXd(rpy_from_rotation(e.ee.R) * (180.0 / M_PI)));
  j["direction"] = to_json(Eigen::VectorXd(e.u));
  j["H"] = to_json(e.data.H);
  j["J_bm"] = to_json(e.data.J);
  j["J_f"] = to_json(e.Jf);
  j["total_mass"] = r.model.total_mass();
  j["contact_joints"] = joint_model_name(e.joints.model);
  if (e.joints.model == JointModel::Armature) j["armature"] = to_json(e.joints.armature);
  j["effective_mass"] = e.m_e;
  j["integrated_effective_mass"] = e.M_ie;
  j["base_disturbance"] = disturbance_json(e.dist);
  j["clearance"] = e.clearance ? ffsr::detail::clearance_json(*e.clearance) : nlohmann::json(nullptr);
  j["model_repairs"] = repairs_json(r.report);
  j["model_load"] = report_json(r.report);
  j["version"] = FFSR_VERSION;
  return j;
}

void print_inspect(std::ostream& out, const Subject& s, const Evaluation& e) {
  const Robot& r = s.robot;
  out << std::setprecision(6);
  out << "robot            " << s.keys.urdf << " (" << r.model.n() << " joints, " << r.model.total_mass()
      << " kg)\n";
  out << "end-effector     " << r.model.frame(r.end_effector).name << " at ["
      << e.ee.p.transpose().format(Eigen::IOFormat(6, 0, ", ")) << "] m\n";
  out << "joints           ";
  const auto names = r.model.joint_names();
  for (size_t i = 0; i < names.size(); ++i)
    out << names[i] << "=" << r.theta(static_cast<Eigen::Index>(i)) * 180.0 / M_PI
        << (i + 1 < names.size() ? ", " : " deg\n");
  print_load_report(out, r.report);
  out << "direction u      [" << e.u.transpose().format(Eigen::IOFormat(6, 0, ", ")) << "]\n";
  if (e.joints.model != JointModel::Free)
    out << "contact joints   " << joint_model_name(e.joints.model) << " (M_ie, m_e and the base jump)\n";
  out << "effective mass   m_e  = " << e.m_e << " kg   (Eq. 4)\n";
  out << "integrated mass  M_ie = " << e.M_ie << " kg   (Eq. 14)\n";
  if (e.dist)
    out << "base jump        |dw_0| = " << e.dist->angular_rate() * 180.0 / M_PI
        << " deg/s, |dv_0| = " << e.dist->linear.norm() << " m/s   (impulse " << e.dist->impulse << " N s, "
        << s.law << ")\n";
  else
    out << "base jump        none: the end-effector does not approach the target at --approach-speed\n";
  if (e.clearance) print_clearance(out, *e.clearance);
  out << "J_f (generalized Jacobian, 6x" << r.model.n() << ", linear rows first):\n"
      << e.Jf.format(Eigen::IOFormat(5, 0, "  ", "\n", "  ")) << "\n";
}

int run_inspect(const InspectOptions& o) {
  set_quiet(o.out.quiet);
  Outputs outputs = o.out.outputs();  // --json '-': the table goes to standard error
  const Subject s = load_subject(o.subject);
  const Evaluation e = evaluate(s);
  outputs.set("--json", inspect_json(s, e).dump(2) + "\n");
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
