#include "model_options.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace ffsr::cli {

using detail::str;

void ModelLoadOptions::add_to(CLI::App& app) {
  auto vec = [&](const char* name, std::vector<double>& v, const char* help) {
    return app.add_option(name, v, help)->delimiter(',')->allow_extra_args(false);
  };
  bus_mass_opt_ = app.add_option("--bus-mass", bus_mass,
                                 "Mount the URDF on a spacecraft bus of this mass, kg (the bus is the base)");
  mount_opts_ = {
      vec("--bus-inertia", bus_inertia,
          "Bus inertia about its centre of mass (bus frame): Ixx,Iyy,Izz[,Ixy,Ixz,Iyz], kg m^2"),
      vec("--bus-com", bus_com, "Bus centre of mass in the bus frame, m (default 0,0,0)"),
      vec("--mount-xyz", mount_xyz, "Position of the URDF's root link in the bus frame, m (default 0,0,0)"),
      vec("--mount-rpy-deg", mount_rpy_deg,
          "Attitude of the URDF's root link in the bus frame, roll,pitch,yaw deg (default 0,0,0)")};
  app.add_option("--lock-joints", lock_joints,
                 "Joints frozen at a value, name=value (rad or m), comma-separated")
      ->delimiter(',')
      ->allow_extra_args(false);
  app.add_option("--inertia-repair", inertia_repair,
                 "Inertias breaking the triangle inequality: none (error) or balance")
      ->capture_default_str();
  app.add_option("--min-mass", min_mass, "Links lighter than this get this mass, kg (0: off)")
      ->capture_default_str();
  app.add_option("--min-inertia", min_inertia,
                 "Principal moments below this are raised to it, kg m^2 (0: off)")
      ->capture_default_str();
  vec("--end-effector-offset", end_effector_offset, "Contact point in the end-effector frame, m (x,y,z)");
}

namespace {

Vector3 vec3_or_zero(const std::vector<double>& v, const char* key) {
  if (v.empty()) return Vector3::Zero();
  if (v.size() != 3) throw InputError(str(key, ": expected 3 numbers, got ", v.size()));
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(str(key, ": values must be finite, got ", x));
  return {v[0], v[1], v[2]};
}

}  // namespace

UrdfOptions ModelLoadOptions::build(const std::string& end_effector) const {
  UrdfOptions u;
  u.end_effector = end_effector;
  const bool has_bus = bus_mass_opt_ && bus_mass_opt_->count() > 0;
  for (const CLI::Option* opt : mount_opts_)
    if (opt->count() > 0 && !has_bus)
      throw InputError(str(opt->get_name(), ": needs --bus-mass (the mount keys describe a spacecraft bus)"));
  if (has_bus) {
    if (!std::isfinite(bus_mass) || bus_mass <= 0)
      throw InputError(str("--bus-mass: must be positive and finite, got ", bus_mass));
    if (bus_inertia.size() != 3 && bus_inertia.size() != 6)
      throw InputError(
          str("--bus-inertia: expected 3 or 6 numbers with --bus-mass, got ", bus_inertia.size()));
    Bus bus;
    bus.mass = bus_mass;
    for (double x : bus_inertia)
      if (!std::isfinite(x)) throw InputError(str("--bus-inertia: values must be finite, got ", x));
    bus.inertia.diagonal() << bus_inertia[0], bus_inertia[1], bus_inertia[2];
    if (bus_inertia.size() == 6) {
      bus.inertia(0, 1) = bus.inertia(1, 0) = bus_inertia[3];
      bus.inertia(0, 2) = bus.inertia(2, 0) = bus_inertia[4];
      bus.inertia(1, 2) = bus.inertia(2, 1) = bus_inertia[5];
    }
    bus.com = vec3_or_zero(bus_com, "--bus-com");
    bus.mount = Pose::from_xyz_rpy(vec3_or_zero(mount_xyz, "--mount-xyz"),
                                   vec3_or_zero(mount_rpy_deg, "--mount-rpy-deg") * (M_PI / 180.0));
    u.bus = bus;
  }
  for (const std::string& item : lock_joints) {
    const size_t eq = item.rfind('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw InputError(str("--lock-joints: '", item, "' is not name=value"));
    const std::string name = item.substr(0, eq), value = item.substr(eq + 1);
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(value.c_str(), &end);
    if (end != value.c_str() + value.size() || !std::isfinite(x) || errno == ERANGE)
      throw InputError(str("--lock-joints: '", item, "': the value is not a finite number"));
    u.locks.emplace_back(name, x);
  }
  try {
    u.inertia_repair = parse_inertia_repair(inertia_repair);
  } catch (const InputError& e) {
    throw InputError(str("--", e.what()));
  }
  if (!std::isfinite(min_mass) || min_mass < 0)
    throw InputError(str("--min-mass: must be >= 0, got ", min_mass));
  if (!std::isfinite(min_inertia) || min_inertia < 0)
    throw InputError(str("--min-inertia: must be >= 0, got ", min_inertia));
  u.min_mass = min_mass;
  u.min_inertia = min_inertia;
  if (!end_effector_offset.empty()) {
    if (end_effector_offset.size() != 3)
      throw InputError(
          str("--end-effector-offset: expected 3 finite numbers, got ", end_effector_offset.size()));
    u.end_effector_offset = vec3_or_zero(end_effector_offset, "--end-effector-offset");
  }
  return u;
}

nlohmann::json ModelLoadOptions::to_json() const {
  nlohmann::json j;
  if (bus_mass_opt_ && bus_mass_opt_->count() > 0) {
    j["bus-mass"] = bus_mass;
    j["bus-inertia"] = bus_inertia;
    j["bus-com"] = bus_com.empty() ? std::vector<double>{0, 0, 0} : bus_com;
    j["mount-xyz"] = mount_xyz.empty() ? std::vector<double>{0, 0, 0} : mount_xyz;
    j["mount-rpy-deg"] = mount_rpy_deg.empty() ? std::vector<double>{0, 0, 0} : mount_rpy_deg;
  }
  j["lock-joints"] = lock_joints;
  j["inertia-repair"] = inertia_repair;
  j["min-mass"] = min_mass;
  j["min-inertia"] = min_inertia;
  if (!end_effector_offset.empty()) j["end-effector-offset"] = end_effector_offset;
  return j;
}

void warn_repairs(const UrdfReport& report) {
  auto list = [](const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += (s.empty() ? "" : ", ") + str(x);
    return v.size() == 1 ? s : "(" + s + ")";
  };
  for (const ModelRepair& r : report.repairs)
    std::fprintf(stderr, "ffsr-optimize: warning: link '%s': %s: %s -> %s\n", r.link.c_str(), r.what.c_str(),
                 list(r.before).c_str(), list(r.after).c_str());
}

nlohmann::json repairs_json(const UrdfReport& report) {
  nlohmann::json a = nlohmann::json::array();
  for (const ModelRepair& r : report.repairs) {
    nlohmann::json before = r.before.size() == 1 ? nlohmann::json(r.before[0]) : nlohmann::json(r.before);
    nlohmann::json after = r.after.size() == 1 ? nlohmann::json(r.after[0]) : nlohmann::json(r.after);
    a.push_back({{"link", r.link}, {"what", r.what}, {"before", before}, {"after", after}});
  }
  return a;
}

nlohmann::json report_json(const UrdfReport& report) {
  nlohmann::json mimic = nlohmann::json::array(), locked = nlohmann::json::array();
  for (const auto& m : report.mimics)
    mimic.push_back(
        {{"joint", m.joint}, {"leader", m.leader}, {"multiplier", m.multiplier}, {"offset", m.offset}});
  for (const auto& l : report.locked) locked.push_back({{"joint", l.first}, {"value", l.second}});
  return {{"merged_links", report.merged_links},
          {"mimic_joints", mimic},
          {"locked_joints", locked},
          {"model_repairs", repairs_json(report)}};
}

}  // namespace ffsr::cli
