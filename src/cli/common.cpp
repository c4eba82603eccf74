#include "common.hpp"

#include "ffsr/io/urdf.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace ffsr::cli {

using detail::str;

std::vector<double> parse_list(const std::string& text, const std::string& flag, std::vector<size_t> counts) {
  std::vector<double> out;
  std::string item;
  std::stringstream ss(text);
  if (text.empty()) throw InputError(str(flag, ": expected comma-separated numbers, got an empty value"));
  while (std::getline(ss, item, ',')) {
    const size_t b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    const std::string t = b == std::string::npos ? std::string() : item.substr(b, e - b + 1);
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size())
      throw InputError(str(flag, ": '", t, "' is not a number (in '", text, "')"));
    if (!std::isfinite(x) || errno == ERANGE)
      throw InputError(str(flag, ": '", t, "' is not a finite number (in '", text, "')"));
    out.push_back(x);
  }
  if (!text.empty() && text.back() == ',') throw InputError(str(flag, ": trailing comma in '", text, "'"));
  if (!counts.empty()) {
    bool ok = false;
    std::string expected;
    for (size_t c : counts) {
      ok = ok || out.size() == c;
      expected += (expected.empty() ? "" : " or ") + std::to_string(c);
    }
    if (!ok) throw InputError(str(flag, ": expected ", expected, " comma-separated numbers, got ", out.size(), " ('", text, "')"));
  }
  return out;
}

Vector3 parse_vec3(const std::string& text, const std::string& flag) {
  const auto v = parse_list(text, flag, {3});
  return {v[0], v[1], v[2]};
}

double deg2rad(double deg) { return deg * M_PI / 180.0; }
double rad2deg(double rad) { return rad * 180.0 / M_PI; }

void RobotOptions::add_to(CLI::App& app) {
  app.add_option("--urdf", urdf, "Robot URDF file; its root link is the free-floating base")->required();
  app.add_option("--joints-deg", joints_deg, "Joint angles in degrees, comma-separated, URDF tree order")->required();
  app.add_option("--end-effector", end_effector, "End-effector frame (a link name); default: the single leaf link");
  app.add_option("--base-position", base_position, "Base frame origin in the inertial frame, m")->capture_default_str();
  app.add_option("--base-rpy-deg", base_rpy_deg, "Base attitude, URDF roll,pitch,yaw in degrees")->capture_default_str();
}

void TargetOptions::add_to(CLI::App& app) {
  app.add_option("--target-mass", mass, "Target mass m_t, kg")->capture_default_str();
  app.add_option("--target-inertia", inertia, "Target inertia about its centre of mass (target frame): Ixx,Iyy,Izz or Ixx,Iyy,Izz,Ixy,Ixz,Iyz, kg m^2")
      ->capture_default_str();
  app.add_option("--target-rpy-deg", rpy_deg, "Target attitude, roll,pitch,yaw in degrees")->capture_default_str();
  app.add_option("--contact-offset", contact_offset, "r_tp: contact point from the target's centre of mass (target frame), m")
      ->capture_default_str();
  app.add_option("--normal", normal, "u_n: contact normal (target frame); normalized")->capture_default_str();
}

Matrix3 parse_inertia(const std::string& text, const std::string& flag) {
  const auto v = parse_list(text, flag, {3, 6});
  Matrix3 I = Matrix3::Zero();
  I.diagonal() << v[0], v[1], v[2];
  if (v.size() == 6) {
    I(0, 1) = I(1, 0) = v[3];
    I(0, 2) = I(2, 0) = v[4];
    I(1, 2) = I(2, 1) = v[5];
  }
  return I;
}

Target TargetOptions::build() const {
  Target t;
  if (!std::isfinite(mass) || mass <= 0) throw InputError(str("--target-mass: must be positive and finite, got ", mass));
  t.mass = mass;
  t.inertia = parse_inertia(inertia, "--target-inertia");
  const Vector3 rpy = parse_vec3(rpy_deg, "--target-rpy-deg") * (M_PI / 180.0);
  t.attitude = Quaternion(rotation_from_rpy(rpy));
  t.contact_offset = parse_vec3(contact_offset, "--contact-offset");
  const Vector3 n = parse_vec3(normal, "--normal");
  if (n.norm() < 1e-12) throw InputError("--normal: the contact normal must be a non-zero vector");
  t.normal = n.normalized();
  try {
    t.validate("target");
  } catch (const InputError& e) {
    throw InputError(str("--target-inertia/--target-mass: ", e.what()));
  }
  return t;
}

Robot load_robot(const RobotOptions& o) {
  Robot r{model_from_urdf_file(o.urdf, o.end_effector), 0, {}, {}};
  r.end_effector = r.model.end_effector();
  const auto q = parse_list(o.joints_deg, "--joints-deg");
  if (static_cast<int>(q.size()) != r.model.n())
    throw InputError(str("--joints-deg: got ", q.size(), " angles, the robot in ", o.urdf, " has ", r.model.n(),
                         " joints"));
  r.theta = Eigen::Map<const Eigen::VectorXd>(q.data(), static_cast<Eigen::Index>(q.size())) * (M_PI / 180.0);
  r.base.position = parse_vec3(o.base_position, "--base-position");
  r.base.orientation = Quaternion(rotation_from_rpy(parse_vec3(o.base_rpy_deg, "--base-rpy-deg") * (M_PI / 180.0)));
  return r;
}

void write_file_atomic(const std::string& path, const std::string& content) {
  write_files_atomic({{path, content}});
}

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
  std::random_device rd;
  std::vector<std::string> tmps;
  auto remove_tmps = [&tmps](size_t from) {
    for (size_t k = from; k < tmps.size(); ++k) std::remove(tmps[k].c_str());
  };
  for (const auto& [path, content] : files) {
    const std::string tmp = path + ".tmp-" + std::to_string(rd());
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      remove_tmps(0);
      throw InputError(str(path, ": cannot write the output file"));
    }
    tmps.push_back(tmp);
    out << content;
    out.flush();
    if (!out) {
      out.close();
      remove_tmps(0);
      throw InputError(str(path, ": cannot write the output file"));
    }
  }
  // a directory cannot be replaced by a file: check them all before renaming any
  for (const auto& f : files) {
    std::error_code ec;
    if (std::filesystem::is_directory(f.first, ec)) {
      remove_tmps(0);
      throw InputError(str(f.first, ": cannot write the output file (it is a directory)"));
    }
  }
  for (size_t i = 0; i < files.size(); ++i) {
    if (std::rename(tmps[i].c_str(), files[i].first.c_str()) != 0) {
      remove_tmps(i);
      throw InputError(str(files[i].first, ": cannot write the output file (rename failed)"));
    }
  }
}

nlohmann::json to_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json to_json(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

}  // namespace ffsr::cli
