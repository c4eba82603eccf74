// ffsr-optimize inspect: evaluate one configuration (H, J_f, m_e, M_ie).
#include "common.hpp"
#include "subcommands.hpp"

#include "ffsr/algorithm/base_disturbance.hpp"

#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

namespace ffsr::cli {
namespace {

struct InspectOptions {
  RobotOptions robot;
  TargetOptions target;
  ContactLawOptions law;
  bool json = false;
};

/// The impact disturbance of the base at the configuration (single-body impulse), or nothing when the
/// end-effector moving at the approach speed along u does not approach the target's contact point.
std::optional<BaseDisturbance> inspect_disturbance(const Robot& r, const InspectOptions& o, Target target) {
  o.law.set_target_motion(target);
  if (!std::isfinite(o.law.approach_speed)) throw InputError("--approach-speed: must be finite");
  const ContactParams params = o.law.params();
  const Vector3 u = target.normal_world();
  const double vin = approach_velocity(u, Vector3(o.law.approach_speed * u), target.velocity,
                                       target.angular_velocity_world(), target.offset_world());
  if (!(vin > 0)) return std::nullopt;
  AnyContactLaw law = make_contact_law("hunt-crossley", params, vin);
  try {
    law = make_contact_law(o.law.model, params, vin);
  } catch (const InputError& e) {
    throw InputError(std::string("--model: ") + e.what());
  }
  Data data(r.model);
  return base_disturbance(r.model, data, r.base, r.theta, r.end_effector, target, law);
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
  const Robot r = load_robot(o.robot);
  const Target target = o.target.build();
  Data data(r.model);
  const Vector3 u = target.normal_world();
  const double M_ie = integrated_effective_mass(r.model, data, r.base, r.theta, r.end_effector, target);
  const double m_e = 1.0 / inverse_effective_mass(r.model, data, r.end_effector, u);
  frame_jacobian(r.model, data, r.end_effector);
  const Eigen::MatrixXd Jf = generalized_jacobian(r.model, data);
  const Pose ee = frame_pose(r.model, data, r.end_effector);
  const std::optional<BaseDisturbance> dist = inspect_disturbance(r, o, target);

  if (o.json) {
    nlohmann::json j;
    j["urdf"] = o.robot.urdf;
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
    j["effective_mass"] = m_e;
    j["integrated_effective_mass"] = M_ie;
    j["base_disturbance"] = disturbance_json(dist);
    j["model_repairs"] = repairs_json(r.report);
    j["model_load"] = report_json(r.report);
    j["version"] = FFSR_VERSION;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << std::setprecision(6);
  std::cout << "robot            " << o.robot.urdf << " (" << r.model.n() << " joints, "
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
  std::cout << "effective mass   m_e  = " << m_e << " kg   (Eq. 4)\n";
  std::cout << "integrated mass  M_ie = " << M_ie << " kg   (Eq. 14)\n";
  if (dist)
    std::cout << "base jump        |dw_0| = " << dist->angular_rate() * 180.0 / M_PI << " deg/s, |dv_0| = "
              << dist->linear.norm() << " m/s   (impulse " << dist->impulse << " N s, " << o.law.model << ")\n";
  else
    std::cout << "base jump        none: the end-effector does not approach the target at --approach-speed\n";
  std::cout << "J_f (generalized Jacobian, 6x" << r.model.n() << ", linear rows first):\n"
            << Jf.format(Eigen::IOFormat(5, 0, "  ", "\n", "  ")) << "\n";
  return 0;
}

}  // namespace

void register_inspect(CLI::App& app, Action& action) {
  auto opts = std::make_shared<InspectOptions>();
  CLI::App* sub =
      app.add_subcommand("inspect", "Evaluate one configuration: H, J_f, effective mass and M_ie");
  opts->robot.add_to(*sub);
  opts->target.add_to(*sub);
  opts->law.add_to(*sub, "Hysteresis damping law (Table 1) of the impact's base disturbance");
  sub->add_flag("--json", opts->json, "Print one JSON object on stdout");
  sub->callback([opts, &action] { action = [opts] { return run_inspect(*opts); }; });
}

}  // namespace ffsr::cli
