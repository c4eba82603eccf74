// ffsr/parsers/urdf.hpp -- URDF -> Model, through urdfdom. Link with ffsr::urdf.
#pragma once

#include "ffsr/model/model.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

// The root link is the free-floating base, or (UrdfOptions::bus) the URDF is mounted on a
// spacecraft bus that becomes the base, its root link and every link fixed to it merged into the bus.
// Revolute, continuous and prismatic joints move; fixed joints merge their child's inertia into the
// parent body and keep the child as a named frame; mimic joints follow their leader (model.hpp);
// locked joints (UrdfOptions::locks) are fixed at a value. Joint order: depth-first from the root,
// siblings in the order of their <joint> elements in the file. The loader validates rather than
// repairs unless asked (UrdfOptions::inertia_repair, min_mass, min_inertia), and reports every repair
// in UrdfReport; every error is a ModelError (or an InputError for a bad option) naming the file and
// the element, or the option.
//
// The loader's bodies are compiled once, in the library of the CMake target ffsr::urdf
// (src/parsers/urdf.cpp, with urdfdom), so that a program that loads a URDF does not compile the
// parser: this header declares the entry points and includes neither urdfdom nor the parser's
// internals (those are in parsers/detail/urdf_document.hpp).

namespace ffsr {

/// A spacecraft bus to mount the URDF on (the keys bus-mass, bus-inertia, bus-com, mount-xyz,
/// mount-rpy-deg of the command). The bus frame is the free-floating base frame.
struct Bus {
  std::string name = "bus";
  double mass = 0.0;                  ///< kg, > 0
  Matrix3 inertia = Matrix3::Zero();  ///< about the bus centre of mass, bus frame
  Vector3 com = Vector3::Zero();      ///< bus centre of mass in the bus frame
  Pose mount;                         ///< pose of the URDF's root link in the bus frame
};

enum class InertiaRepair { None, Balance };

/// How a URDF is turned into a Model.
struct UrdfOptions {
  std::string end_effector;                           ///< link name; empty: the single leaf link
  std::optional<Vector3> end_effector_offset;         ///< contact point in the end-effector frame
  std::optional<Bus> bus;                             ///< mount the robot on a bus
  std::vector<std::pair<std::string, double>> locks;  ///< joint name, value (rad or m)
  /// Balance: raise the two smaller principal moments of a link just enough (by half the deficit
  /// each) that the largest equals their sum (the triangle inequality; cf. MuJoCo's balanceinertia).
  InertiaRepair inertia_repair = InertiaRepair::None;
  double min_mass = 0.0;     ///< links with an <inertial> lighter than this get this mass (boundmass)
  double min_inertia = 0.0;  ///< principal moments below this are raised to it (boundinertia)
};

/// One change the loader made to a link's inertial values. `before` and `after` are the mass (one
/// number) or the principal moments (three, ascending).
struct ModelRepair {
  std::string link, what;
  std::vector<double> before, after;
};

/// What the loader did to the file, for `inspect` and the JSON output.
struct UrdfReport {
  std::vector<std::string> merged_links;  ///< links merged into the base (bus) body
  struct Mimic {
    std::string joint, leader;
    double multiplier, offset;
  };
  std::vector<Mimic> mimics;                           ///< resolved to independent leaders
  std::vector<std::pair<std::string, double>> locked;  ///< every joint fixed at a value (with followers)
  std::vector<ModelRepair> repairs;
};

inline const char* inertia_repair_name(InertiaRepair r) {
  return r == InertiaRepair::Balance ? "balance" : "none";
}
/// "none" or "balance"; throws InputError naming the option otherwise.
inline InertiaRepair parse_inertia_repair(const std::string& s) {
  if (s == "none") return InertiaRepair::None;
  if (s == "balance") return InertiaRepair::Balance;
  throw InputError(detail::str("inertia-repair: unknown mode '", s, "'; expected 'none' or 'balance'"));
}
/// Builds a Model from URDF text with the options `opt` (bus, mimic, locks, repairs, end-effector).
/// `source` names the file in error messages. Fills `report` (when given) with what was done to the
/// file: links merged into the bus, mimic and locked joints, inertia repairs. Never prints.
/// The steps: detail::parse_urdf_document, then detail::model_from_urdf_document.
Model model_from_urdf_string(const std::string& xml, const std::string& source, const UrdfOptions& opt,
                             UrdfReport* report = nullptr);

/// Builds a Model from URDF text. `source` names the file in error messages. `end_effector` names
/// the end-effector frame (a link name); empty means the single leaf link.
Model model_from_urdf_string(const std::string& xml, const std::string& source = "<string>",
                             const std::string& end_effector = "");

/// Builds a Model from a URDF file with options (see model_from_urdf_string). Only a regular file of
/// at most 64 MiB is read.
Model model_from_urdf_file(const std::string& path, const UrdfOptions& opt, UrdfReport* report = nullptr);

/// Builds a Model from a URDF file (see model_from_urdf_string).
Model model_from_urdf_file(const std::string& path, const std::string& end_effector = "");

}  // namespace ffsr
