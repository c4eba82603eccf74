// src/cli/model_options.hpp -- how a URDF becomes a model: the spacecraft bus it is mounted on,
// locked joints, inertia repairs and the contact point at the gripper (issue 11). The keys are the
// same in a scenario file and as flags of every subcommand that loads a robot.
#pragma once

#include "ffsr/io/urdf.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace ffsr::cli {

/// --bus-mass, --bus-inertia, --bus-com, --mount-xyz, --mount-rpy-deg, --lock-joints,
/// --inertia-repair, --min-mass, --min-inertia, --end-effector-offset.
struct ModelLoadOptions {
  double bus_mass = 0.0;
  std::vector<double> bus_inertia, bus_com, mount_xyz, mount_rpy_deg, end_effector_offset;
  std::vector<std::string> lock_joints;
  std::string inertia_repair = "none";
  double min_mass = 0.0, min_inertia = 0.0;
  void add_to(CLI::App& app);
  /// The loader options; throws InputError naming the key on a bad value (mount keys without
  /// bus-mass, bus-mass <= 0, a malformed lock, an unknown repair mode, an offset that is not 3
  /// finite numbers).
  UrdfOptions build(const std::string& end_effector) const;
  /// The keys as given (for the resolved scenario in the JSON output).
  nlohmann::json to_json() const;

 private:
  std::vector<const CLI::Option*> mount_opts_;
  const CLI::Option* bus_mass_opt_ = nullptr;
};

/// One warning line on stderr per repair ("ffsr-optimize: warning: link 'x': ...").
void warn_repairs(const UrdfReport& report);
/// [{link, what, before, after}] for the JSON key model_repairs.
nlohmann::json repairs_json(const UrdfReport& report);
/// merged links, mimic and locked joints, repairs: what the loader did to the file.
nlohmann::json report_json(const UrdfReport& report);

}  // namespace ffsr::cli
