// bench/bench_pinocchio.cpp -- ffsr-bench-pinocchio: the inverse effective mass u^T J_v H^-1 J_v^T u
// (the robot part of Eq. 14) per evaluation, ffsr against Pinocchio in the same run.
//
//   ffsr-bench-pinocchio [DIR]     DIR: the robots folder (default FFSR_SOURCE_DIR/robots)
//
// Built only with -DFFSR_BENCH_PINOCCHIO=ON (bench/CMakeLists.txt), against Pinocchio's C++ headers
// and libraries, e.g. those of the PyPI package `pin` (pip install pin; CMAKE_PREFIX_PATH=
// <site-packages>/cmeel.prefix). Nothing else in the project needs Pinocchio.
//
// Robots: the paper's 3-DOF and 7-DOF robots, and serial chains of 14, 28 and 56 revolute joints
// (random axes, offsets and inertias from a fixed seed), each loaded from the same URDF text by both
// libraries: ffsr's model from URDF, Pinocchio's built from it joint by joint with a free-flyer
// root (bench_pinocchio_side.cpp: Pinocchio's URDF parser and the system urdfdom headers that
// ffsr's loader uses do not mix in one translation unit). Poses: the same 1000 random configurations
// (fixed seed) and unit directions u for both. Pinocchio: crba, computeJointJacobians +
// getFrameJacobian (LOCAL_WORLD_ALIGNED, linear rows), an LLT of M and the solve. ffsr: crba and the
// dense Cholesky path (inverse_effective_mass), the articulated-body recursion
// (inverse_effective_mass_articulated) and the dispatching integrated_effective_mass_fast. Each
// time is the median over 21 passes over the 1000 poses of the mean time per evaluation, in CPU time
// of the thread (CLOCK_THREAD_CPUTIME_ID: stable on a loaded machine, where wall time is not); the
// values of the two libraries are compared too (the quantity does not depend on the velocity
// coordinates, so they must agree to rounding).
#include <ffsr/ffsr.hpp>
#include <ffsr/io/urdf.hpp>

#include "bench_pinocchio.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

volatile double g_sink = 0;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// URDF of a serial chain of n revolute joints with random axes, offsets and inertias.
std::string chain_urdf(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::ostringstream os;
  os.precision(17);
  auto inertial = [&](double m) {
    const double a = 0.05 + 0.5 * (U(gen) + 1), b = 0.05 + 0.5 * (U(gen) + 1), c = 0.05 + 0.5 * (U(gen) + 1);
    os << "<inertial><origin xyz=\"" << 0.2 * U(gen) << " " << 0.2 * U(gen) << " " << 0.2 * U(gen)
       << "\" rpy=\"0 0 0\"/><mass value=\"" << m << "\"/><inertia ixx=\"" << b + c << "\" iyy=\"" << a + c
       << "\" izz=\"" << a + b << "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
  };
  os << "<robot name=\"chain" << n << "\"><link name=\"base\">";
  inertial(400);
  os << "</link>";
  for (int i = 1; i <= n; ++i) {
    os << "<link name=\"l" << i << "\">";
    inertial(1 + 9 * 0.5 * (U(gen) + 1));
    os << "</link><joint name=\"j" << i << "\" type=\"continuous\"><parent link=\""
       << (i == 1 ? std::string("base") : "l" + std::to_string(i - 1)) << "\"/><child link=\"l" << i
       << "\"/><origin xyz=\"" << 0.4 * U(gen) << " " << 0.4 * U(gen) << " " << 0.4 * U(gen) << "\" rpy=\""
       << U(gen) << " " << U(gen) << " " << U(gen) << "\"/><axis xyz=\"" << U(gen) << " " << U(gen) << " "
       << U(gen) + 1.5 << "\"/></joint>";
  }
  os << "<link name=\"ee\"/><joint name=\"ee_mount\" type=\"fixed\"><parent link=\"l" << n
     << "\"/><child link=\"ee\"/><origin xyz=\"0.3 0 0\" rpy=\"0 0 0\"/></joint></robot>";
  return os.str();
}

struct Poses {
  std::vector<ffsr::BasePose> base;
  std::vector<Eigen::VectorXd> theta;
  std::vector<Eigen::Vector3d> u;
};

Poses random_poses(int n, int count, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  Poses p;
  for (int k = 0; k < count; ++k) {
    ffsr::BasePose b;
    b.position = Eigen::Vector3d(U(gen), U(gen), U(gen));
    b.orientation = Eigen::Quaterniond(N(gen), N(gen), N(gen), N(gen)).normalized();
    Eigen::VectorXd th(n);
    for (int j = 0; j < n; ++j) th(j) = M_PI * U(gen);
    Eigen::Vector3d u(N(gen), N(gen), N(gen));
    p.base.push_back(b);
    p.theta.push_back(th);
    p.u.push_back(u.normalized());
  }
  return p;
}

/// Median over `passes` of the mean time per evaluation of fn(k) over all poses; sums the values.
template <class Fn>
double time_per_eval(int count, int passes, Fn&& fn) {
  std::vector<double> t;
  double acc = 0;
  for (int k = 0; k < count; ++k) acc += fn(k);  // warm-up
  for (int r = 0; r < passes; ++r) {
    const double t0 = ffsr_bench::thread_seconds();
    for (int k = 0; k < count; ++k) acc += fn(k);
    t.push_back((ffsr_bench::thread_seconds() - t0) / count);
  }
  g_sink = g_sink + acc;
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

void compare(const std::string& name, const std::string& urdf) {
  const ffsr::Model fm = ffsr::model_from_urdf_string(urdf, name, "ee");
  const int fee = fm.frame_index("ee");
  ffsr::Data fd(fm);
  const int n = fm.n();
  constexpr int kPoses = 1000, kPasses = 21;
  const Poses P = random_poses(n, kPoses, 1234u + static_cast<unsigned>(n));
  std::vector<double> pin_values;
  const double tp =
      ffsr_bench::pinocchio_inverse_effective_mass(fm, fee, P.base, P.theta, P.u, kPasses, pin_values);

  auto dense = [&](int k) {
    const auto uk = static_cast<size_t>(k);
    ffsr::crba(fm, fd, P.base[uk], P.theta[uk]);
    return ffsr::inverse_effective_mass(fm, fd, fee, P.u[uk]);
  };
  auto articulated = [&](int k) {
    const auto uk = static_cast<size_t>(k);
    ffsr::forward_kinematics(fm, fd, P.base[uk], P.theta[uk]);
    return ffsr::inverse_effective_mass_articulated(fm, fd, fee, P.u[uk]);
  };
  auto fast = [&](int k) {
    const auto uk = static_cast<size_t>(k);
    return 1.0 / ffsr::integrated_effective_mass_fast(fm, fd, P.base[uk], P.theta[uk], fee, P.u[uk], 0.0);
  };
  double worst = 0;
  for (int k = 0; k < kPoses; ++k) {
    const double a = pin_values[static_cast<size_t>(k)], b = dense(k), c = articulated(k);
    worst = std::max({worst, std::abs(b - a) / a, std::abs(c - a) / a});
  }
  const double td = time_per_eval(kPoses, kPasses, dense);
  const double ta = time_per_eval(kPoses, kPasses, articulated);
  const double tf = time_per_eval(kPoses, kPasses, fast);
  std::printf("%-10s %3d %11.3f %11.3f %11.3f %11.3f %9.2fx %9.2fx %9.2fx %10.1e\n", name.c_str(), n,
              tp * 1e6, td * 1e6, ta * 1e6, tf * 1e6, td / tp, ta / tp, tf / tp, worst);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : std::string(FFSR_SOURCE_DIR) + "/robots";
  try {
    std::printf(
        "u^T J_v H^-1 J_v^T u per evaluation, median of 21 passes over the same 1000 random poses (us)\n");
    std::printf("%-10s %3s %11s %11s %11s %11s %10s %10s %10s %10s\n", "robot", "n", "pinocchio",
                "ffsr dense", "ffsr ABA", "ffsr fast", "dense/pin", "ABA/pin", "fast/pin", "max rel");
    compare("3-DOF", read_text(dir + "/paper_3dof.urdf"));
    compare("7-DOF", read_text(dir + "/paper_7dof.urdf"));
    for (int n : {14, 28, 56}) compare("chain " + std::to_string(n), chain_urdf(n, static_cast<unsigned>(n)));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ffsr-bench-pinocchio: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
