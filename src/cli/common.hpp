// src/cli/common.hpp -- options shared by the subcommands, parsing helpers and output files.
#pragma once

#include "ffsr/ffsr.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace ffsr::cli {

/// Exit codes: 2 for bad input (arguments, files, models), 3 for a numerical failure.
constexpr int kExitInput = 2;
constexpr int kExitNumerical = 3;

/// Parses "a,b,c" into numbers; throws InputError naming `flag` on a bad or non-finite number or
/// when the count is not one of `counts` (empty: any count >= 1).
std::vector<double> parse_list(const std::string& text, const std::string& flag, std::vector<size_t> counts = {});
Vector3 parse_vec3(const std::string& text, const std::string& flag);
double deg2rad(double deg);
double rad2deg(double rad);

/// --urdf, --joints-deg, --end-effector, --base-position, --base-rpy-deg.
struct RobotOptions {
  std::string urdf;
  std::string joints_deg;
  std::string end_effector;
  std::string base_position = "0,0,0";
  std::string base_rpy_deg = "0,0,0";
  void add_to(CLI::App& app);
};

/// --target-mass, --target-inertia, --target-rpy-deg, --contact-offset, --normal (the paper's target
/// by default).
struct TargetOptions {
  double mass = 200.0;
  std::string inertia = "100,100,100";
  std::string rpy_deg = "0,0,0";
  std::string contact_offset = "-0.25,0.15,0";
  std::string normal = "1,0,0";
  void add_to(CLI::App& app);
  /// The target (attitude, inertia, offset, normal, mass), validated.
  Target build() const;
};

/// A robot loaded from --urdf at the configuration of the flags.
struct Robot {
  Model model;
  int end_effector = 0;
  BasePose base;
  Eigen::VectorXd theta;
};
Robot load_robot(const RobotOptions& options);

/// Parses an inertia given as "Ixx,Iyy,Izz" or "Ixx,Iyy,Izz,Ixy,Ixz,Iyz".
Matrix3 parse_inertia(const std::string& text, const std::string& flag);

/// Writes a file atomically: a temporary file in the same directory, then rename. Throws InputError
/// naming the path when it cannot be written; never leaves a partial file behind.
void write_file_atomic(const std::string& path, const std::string& content);
/// Writes several files all or nothing: every content goes to a temporary file next to its path
/// first, and only when all of them are written are they renamed into place. A failure removes the
/// temporary files and throws InputError naming the path, so no output of the run is left behind.
void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files);

/// Matrix -> JSON array of rows.
nlohmann::json to_json(const Eigen::MatrixXd& m);
nlohmann::json to_json(const Eigen::VectorXd& v);

}  // namespace ffsr::cli
