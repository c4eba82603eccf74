// bench/bench_pinocchio.cpp -- ffsr-bench-pinocchio: the joint-space inertia matrix H (CRBA) and the
// inverse effective mass u^T J_v H^-1 J_v^T u of the integrated effective mass (Eq. 14), per call,
// ffsr now, ffsr before the fixed-size rewrite and Pinocchio in the same run.
//
//   ffsr-bench-pinocchio [DIR]     DIR: the robots folder (default FFSR_SOURCE_DIR/robots)
//
// Built only with -DFFSR_BENCH_PINOCCHIO=ON (bench/CMakeLists.txt), against Pinocchio's C++ headers
// and libraries, e.g. those of the PyPI package `pin` (pip install pin==4.1.0). Nothing else in the
// project needs Pinocchio.
//
// Robots: the paper's 3-DOF and 7-DOF robots (joint axes along x or z) and serial chains of 3, 7, 14,
// 28 and 56 revolute joints on a floating base (random axes, offsets and inertias from a fixed seed),
// each loaded from the same URDF text by both libraries: ffsr's model from URDF, Pinocchio's built
// from it joint by joint with a free-flyer root, RX/RY/RZ joints for axes along x, y, z and the
// unaligned revolute joint otherwise (bench_pinocchio_side.cpp: Pinocchio's URDF parser and the
// system urdfdom headers that ffsr's loader uses do not mix in one translation unit). Poses: the same
// 1000 random configurations (fixed seed) and unit directions u for all.
//
// Columns: CRBA -- ffsr::crba (the full symmetric H), the frozen code before the rewrite
// (bench_before.hpp), pinocchio::crba (upper triangle; the default LOCAL convention and WORLD), and
// "pinL+s": LOCAL followed by the copy of its upper triangle into the lower, the same output as
// ffsr's (shown beside, with its own ratio "ffsr/s"; the headline ratio ffsr/p is against the faster
// of crba's two conventions alone); M_ie --
// ffsr::integrated_effective_mass (the O(n) articulated-body route), the frozen dispatching
// function, and Pinocchio's crba + computeJointJacobians + getFrameJacobian + LLT solve. Each time is
// the median over 51 passes of the mean time per call over 200 of the poses, in CPU time of the
// thread (CLOCK_THREAD_CPUTIME_ID: time while descheduled does not count); every pass times the eight
// loops back to back, so that a change of the machine's load hits them alike. All 1000 poses serve the
// agreement checks. Ratios are ffsr over Pinocchio
// (the faster of its two CRBA conventions for CRBA). The last columns check the numbers: H against
// the frozen code (largest entry difference over the largest entry), H's joint block against
// Pinocchio's, and the inverse effective mass against both (relative).
#include <ffsr/algorithm/effective_mass.hpp>
#include <ffsr/parsers/urdf.hpp>

#include "bench_before.hpp"
#include "bench_pinocchio.hpp"

#include <algorithm>
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

/// The median of v.
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void compare(const std::string& name, const std::string& urdf) {
  namespace before = ffsr_bench::before;
  using Kind = ffsr_bench::PinocchioBench::Kind;
  const ffsr::Model fm = ffsr::model_from_urdf_string(urdf, name, "ee");
  const int fee = fm.frame_index("ee");
  ffsr::Data fd(fm);
  before::BeforeData bd(fm);
  const int n = fm.n();
  constexpr int kPoses = 1000, kBlocks = 20, kPassPoses = 200, kPasses = 51;
  const Poses P = random_poses(n, kPoses, 1234u + static_cast<unsigned>(n));
  ffsr_bench::PinocchioBench pin(fm, fee, P.base, P.theta, P.u);

  auto crba_now = [&](int k) { return ffsr::crba(fm, fd, P.base[size_t(k)], P.theta[size_t(k)])(6, 6); };
  auto crba_before = [&](int k) { return before::crba(fm, bd, P.base[size_t(k)], P.theta[size_t(k)])(6, 6); };
  auto mie_now = [&](int k) {
    const auto uk = static_cast<size_t>(k);
    return 1.0 / ffsr::integrated_effective_mass(fm, fd, P.base[uk], P.theta[uk], fee, P.u[uk], 0.0);
  };
  auto mie_before = [&](int k) {
    const auto uk = static_cast<size_t>(k);
    return 1.0 / before::integrated_effective_mass(fm, bd, P.base[uk], P.theta[uk], fee, P.u[uk], 0.0);
  };
  double dH = 0, dHpin = 0, dM = 0, dMpin = 0;
  for (int k = 0; k < kPoses; ++k) {
    const auto uk = static_cast<size_t>(k);
    const Eigen::MatrixXd& Hb = before::crba(fm, bd, P.base[uk], P.theta[uk]);
    const Eigen::MatrixXd& Hn = ffsr::crba(fm, fd, P.base[uk], P.theta[uk]);
    dH = std::max(dH, (Hn - Hb).cwiseAbs().maxCoeff() / Hb.cwiseAbs().maxCoeff());
    if (k < kBlocks) {
      const Eigen::MatrixXd Hp = pin.joint_block(k);
      dHpin = std::max(dHpin, (Hn.bottomRightCorner(n, n) - Hp).cwiseAbs().maxCoeff() / Hp.cwiseAbs().maxCoeff());
    }
    const double a = mie_now(k), b = mie_before(k), p = pin.inverse_effective_mass(k);
    dM = std::max(dM, std::abs(a - b) / b);
    dMpin = std::max(dMpin, std::abs(a - p) / p);
  }
  // Interleaved passes: every pass times the eight loops back to back over the same 200 poses, so a
  // change of the machine's load hits them alike; the median over the passes of each.
  auto ffsr_pass = [&](auto&& fn) {
    double acc = 0;
    const double t0 = ffsr_bench::thread_seconds();
    for (int k = 0; k < kPassPoses; ++k) acc += fn(k);
    const double t = ffsr_bench::thread_seconds() - t0;
    g_sink = g_sink + acc;
    return t / kPassPoses;
  };
  std::vector<double> t[8];
  for (int r = -1; r < kPasses; ++r) {  // pass -1 warms up
    const double a[8] = {ffsr_pass(crba_now),
                         ffsr_pass(crba_before),
                         pin.pass(Kind::CrbaLocal, kPassPoses) / kPassPoses,
                         pin.pass(Kind::CrbaWorld, kPassPoses) / kPassPoses,
                         ffsr_pass(mie_now),
                         ffsr_pass(mie_before),
                         pin.pass(Kind::InverseEffectiveMass, kPassPoses) / kPassPoses,
                         pin.pass(Kind::CrbaLocalFull, kPassPoses) / kPassPoses};
    if (r >= 0)
      for (int i = 0; i < 8; ++i) t[i].push_back(a[i]);
  }
  const double tcn = median(t[0]), tcb = median(t[1]), tpl = median(t[2]), tpw = median(t[3]);
  const double tmn = median(t[4]), tmb = median(t[5]), tmp = median(t[6]), tpf = median(t[7]);
  const double tcp = std::min(tpl, tpw);
  std::printf(
      "%-9s %2d | %6.0f %6.0f %6.0f %6.0f %5.2fx %5.2fx %6.0f %5.2fx | %6.0f %6.0f %6.0f %5.2fx %5.2fx | "
      "%7.0e %7.0e %7.0e %7.0e\n",
      name.c_str(), n, tcn * 1e9, tcb * 1e9, tpl * 1e9, tpw * 1e9, tcn / tcp, tcb / tcp, tpf * 1e9, tcn / tpf,
      tmn * 1e9, tmb * 1e9, tmp * 1e9, tmn / tmp, tmb / tmp, dH, dHpin, dM, dMpin);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : std::string(FFSR_SOURCE_DIR) + "/robots";
  try {
    std::printf(
        "ns per call, median of 51 interleaved passes over the same 200 random poses (thread CPU time)\n");
    std::printf("%-9s %2s | %-62s | %-41s | %s\n", "", "", "CRBA", "M_ie (u^T J_v H^-1 J_v^T u)",
                "agreement");
    std::printf("%-9s %2s | %6s %6s %6s %6s %6s %6s %6s %6s | %6s %6s %6s %6s %6s | %7s %7s %7s %7s\n",
                "robot", "n", "ffsr", "before", "pinL", "pinW", "ffsr/p", "bef/p", "pinL+s", "ffsr/s", "ffsr",
                "before", "pin", "ffsr/p", "bef/p", "H-bef", "H-pin", "M-bef", "M-pin");
    compare("3-DOF", read_text(dir + "/paper_3dof.urdf"));
    compare("7-DOF", read_text(dir + "/paper_7dof.urdf"));
    for (int n : {3, 7, 14, 28, 56}) compare("chain " + std::to_string(n), chain_urdf(n, static_cast<unsigned>(n)));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ffsr-bench-pinocchio: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
