// ffsr-optimize inspect: evaluate one configuration (H, J_f, m_e, M_ie, the base's jump at the impact,
// the distances between the shapes).
#include "common.hpp"
#include "scenario.hpp"
#include "subcommands.hpp"

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/optimize/objective.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

namespace ffsr::cli {
namespace {

struct InspectOptions {
  SubjectOptions subject;
  bool json = false;
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

void print_clearance(const ClearanceReport& c) {
  std::cout << "distances        ";
  const std::pair<const char*, const ClearanceReport::Entry*> kinds[] = {
      {"arm-target", &c.arm_target}, {"arm-bus", &c.arm_bus}, {"self", &c.self}};
  bool first = true;
  for (const auto& [name, e] : kinds) {
    if (e->pair.empty()) continue;
    std::cout << (first ? "" : ", ") << name << " " << e->distance << " m (" << e->pair << ")";
    first = false;
  }
  std::cout << (first ? "no pair of bodies" : "") << "\n";
}

/// What the loader did to the file: merged links, mimic and locked joints, repairs.
void print_load_report(const UrdfReport& rep) {
  auto line = [](const char* label, const std::vector<std::string>& items) {
    if (items.empty()) return;
    std::cout << label;
    for (size_t i = 0; i < items.size(); ++i) std::cout << items[i] << (i + 1 < items.size() ? ", " : "\n");
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

int run_inspect(const InspectOptions& o) {
  const Subject s = load_subject(o.subject);
  if (s.all_joint_models())
    throw InputError(
        "--contact-joints: inspect evaluates one joint model; 'all' is for the contact subcommand");
  const ContactJoints joints = s.contact_joints();
  const Robot& r = s.robot;
  const Target& target = s.target;
  const std::optional<AnyContactLaw> law = inspect_law(s);
  // M_ie and the base's jump (single-body impulse) of the joint model: the capture objective's
  const CaptureEvaluator objective(r.model, r.end_effector, target, law ? &*law : nullptr, joints);
  std::optional<BaseDisturbance> dist;
  Data data(r.model);
  if (law) dist = objective.disturbance(data, r.base, r.theta);
  const Vector3 u = target.normal_world();
  const double M_ie = objective.mass(data, r.base, r.theta);
  const double m_e = 1.0 / inverse_effective_mass(r.model, data, r.end_effector, u, joints);
  frame_jacobian(r.model, data, r.end_effector);
  const Eigen::MatrixXd Jf = generalized_jacobian(r.model, data);
  const Pose ee = frame_pose(r.model, data, r.end_effector);
  const std::optional<ClearanceReport> clearance = inspect_clearance(s);

  if (o.json) {
    nlohmann::json j;
    j["urdf"] = s.keys.urdf;
    j["end_effector"] = r.model.frame(r.end_effector).name;
    j["joint_names"] = r.model.joint_names();
    j["joints_deg"] = to_json(Eigen::VectorXd(r.theta * (180.0 / M_PI)));
    j["base_position"] = to_json(Eigen::VectorXd(r.base.position));
    j["end_effector_position"] = to_json(Eigen::VectorXd(ee.p));
    j["end_effector_rpy_deg"] = to_json(Eigen::VectorXd(rpy_from_rotation(ee.R) * (180.0 / M_PI)));
    j["direction"] = to_json(Eigen::VectorXd(u));
    j["H"] = to_json(data.H);
    j["J_bm"] = to_json(data.J);
    j["J_f"] = to_json(Jf);
    j["total_mass"] = r.model.total_mass();
    j["contact_joints"] = joint_model_name(joints.model);
    if (joints.model == JointModel::Armature) j["armature"] = to_json(joints.armature);
    j["effective_mass"] = m_e;
    j["integrated_effective_mass"] = M_ie;
    j["base_disturbance"] = disturbance_json(dist);
    j["clearance"] = clearance ? ffsr::detail::clearance_json(*clearance) : nlohmann::json(nullptr);
    j["model_repairs"] = repairs_json(r.report);
    j["model_load"] = report_json(r.report);
    j["version"] = FFSR_VERSION;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << std::setprecision(6);
  std::cout << "robot            " << s.keys.urdf << " (" << r.model.n() << " joints, "
            << r.model.total_mass() << " kg)\n";
  std::cout << "end-effector     " << r.model.frame(r.end_effector).name << " at ["
            << ee.p.transpose().format(Eigen::IOFormat(6, 0, ", ")) << "] m\n";
  std::cout << "joints           ";
  const auto names = r.model.joint_names();
  for (size_t i = 0; i < names.size(); ++i)
    std::cout << names[i] << "=" << r.theta(static_cast<Eigen::Index>(i)) * 180.0 / M_PI
              << (i + 1 < names.size() ? ", " : " deg\n");
  print_load_report(r.report);
  std::cout << "direction u      [" << u.transpose().format(Eigen::IOFormat(6, 0, ", ")) << "]\n";
  if (joints.model != JointModel::Free)
    std::cout << "contact joints   " << joint_model_name(joints.model) << " (M_ie, m_e and the base jump)\n";
  std::cout << "effective mass   m_e  = " << m_e << " kg   (Eq. 4)\n";
  std::cout << "integrated mass  M_ie = " << M_ie << " kg   (Eq. 14)\n";
  if (dist)
    std::cout << "base jump        |dw_0| = " << dist->angular_rate() * 180.0 / M_PI
              << " deg/s, |dv_0| = " << dist->linear.norm() << " m/s   (impulse " << dist->impulse << " N s, "
              << s.law << ")\n";
  else
    std::cout << "base jump        none: the end-effector does not approach the target at --approach-speed\n";
  if (clearance) print_clearance(*clearance);
  std::cout << "J_f (generalized Jacobian, 6x" << r.model.n() << ", linear rows first):\n"
            << Jf.format(Eigen::IOFormat(5, 0, "  ", "\n", "  ")) << "\n";
  return 0;
}

}  // namespace

void register_inspect(CLI::App& app, Action& action) {
  auto opts = std::make_shared<InspectOptions>();
  CLI::App* sub =
      app.add_subcommand("inspect",
                         "Evaluate one configuration (a scenario's start state; flags override it): H, J_f, "
                         "effective mass, M_ie, the base's jump at the impact, distances between shapes");
  opts->subject.add_to(*sub, {"target-position", "target-shape", "target-size", "target-shape-offset",
                              "link-radius", "bus-box", "contact-exemption", "contact-joints", "armature"});
  sub->add_flag("--json", opts->json, "Print one JSON object on stdout");
  sub->callback([opts, &action] { action = [opts] { return run_inspect(*opts); }; });
}

}  // namespace ffsr::cli
