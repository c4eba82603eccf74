// bench/bench_pinocchio.cpp -- ffsr-bench-pinocchio: the joint-space inertia matrix H (CRBA) and the
// inverse effective mass u^T J_v H^-1 J_v^T u of the integrated effective mass (Eq. 14), per call,
// ffsr now, ffsr before the fixed-size rewrite and Pinocchio's fastest routes in the same run.
//
//   ffsr-bench-pinocchio [DIR]     DIR: the robots folder (default FFSR_SOURCE_DIR/robots)
//
// Built only with -DFFSR_BENCH_PINOCCHIO=ON (bench/CMakeLists.txt), against Pinocchio's C++ headers
// and libraries, e.g. those of the PyPI package `pin` (pip install pin==4.1.0). Nothing else in the
// project needs Pinocchio. Pinocchio's templates are instantiated in this executable at the bench's
// compiler and flags, linked statically (bench_pinocchio_side.cpp; its precompiled library is timed
// beside, from a shared library of its own).
//
// Robots: the paper's 3-DOF and 7-DOF robots (joint axes along x or z) and serial chains of 3, 7, 14,
// 28 and 56 continuous joints on a floating base (random axes, offsets and inertias from a fixed
// seed), each loaded from the same URDF text by both libraries as their users load one: ffsr's
// model_from_urdf_string and Pinocchio's urdf::buildModelFromXML with a free-flyer root (its RZ, RX
// or unaligned unbounded revolute joints, whose configuration is the pair (cos q, sin q): Pinocchio
// gets the sines and cosines precomputed, ffsr computes them from the angles). Poses: the same 1000
// random configurations (fixed seed) and unit directions u for all.
//
// Routes: CRBA -- ffsr::crba (the full symmetric H), the frozen code before the rewrite
// (bench_before.hpp), pinocchio::crba in its LOCAL and WORLD conventions (upper triangle; the ratio is
// against the faster of the two) and LOCAL followed by the copy of its upper triangle into the lower
// (the same output as ffsr's); M_ie -- ffsr::integrated_effective_mass (the O(n) articulated-body
// route), the frozen function, and four Pinocchio routes (bench_pinocchio.hpp): crba +
// computeFrameJacobian + its sparse cholesky::decompose ("dense LOCAL"), crba WORLD + getFrameJacobian
// from the joint Jacobians it leaves + the same factorization ("dense WORLD"), computeMinverse +
// computeFrameJacobian ("Minverse") and computeDelassusMatrix of a 3-D contact at the frame
// ("Delassus", O(n)); the ratio is against the fastest of the four. Each time is the minimum over 51
// passes of the mean time per call over 200 of the poses, in CPU time of the thread
// (CLOCK_THREAD_CPUTIME_ID); every pass times all the loops back to back, so that a change of the
// machine's load hits them alike. All 1000 poses serve the agreement checks: H against the frozen
// code (largest entry difference over the largest entry), H's joint block against Pinocchio's (both
// conventions), and the inverse effective mass against the frozen code and every Pinocchio route
// (relative; the dense column is the largest over the three dense routes). They also check that the
// two libraries read the URDF alike.
// The output is the two Markdown tables of docs/performance.md.
#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/parsers/urdf.hpp"

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

struct Row {
  std::string name;
  int n = 0;
  double t[18] = {};  // the routes' times, in the order of compare's loops
  double agree[6] = {};
};

Row compare(const std::string& name, const std::string& urdf) {
  namespace before = ffsr_bench::before;
  using Kind = ffsr_bench::PinocchioRoutes::Kind;
  const ffsr::Model fm = ffsr::model_from_urdf_string(urdf, name, "ee");
  const int fee = fm.frame_index("ee");
  ffsr::Data fd(fm);
  before::BeforeData bd(fm);
  const int n = fm.n();
  constexpr int kPoses = 1000, kBlocks = 20, kPassPoses = 200, kPasses = 51;
  const Poses P = random_poses(n, kPoses, 1234u + static_cast<unsigned>(n));
  const auto pin = ffsr_bench::make_pinocchio_inline(urdf, "ee", P.base, P.theta, P.u);
#ifdef FFSR_BENCH_PIN_LIBRARY
  const auto lib = ffsr_bench::make_pinocchio_library(urdf, "ee", P.base, P.theta, P.u);
#else  // no precompiled library in this build: its columns time the templates again
  const auto& lib = pin;
#endif

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
  auto rel = [](double a, double b) { return std::abs(a - b) / std::abs(b); };
  Row row{name, n, {}, {}};
  double* d = row.agree;  // H-before, H-Pinocchio, M-before, M-Pinocchio dense, M-Delassus, Delassus-dense
  for (int k = 0; k < kPoses; ++k) {
    const auto uk = static_cast<size_t>(k);
    const Eigen::MatrixXd& Hb = before::crba(fm, bd, P.base[uk], P.theta[uk]);
    const Eigen::MatrixXd& Hn = ffsr::crba(fm, fd, P.base[uk], P.theta[uk]);
    d[0] = std::max(d[0], (Hn - Hb).cwiseAbs().maxCoeff() / Hb.cwiseAbs().maxCoeff());
    if (k < kBlocks)
      for (Kind c : {Kind::CrbaLocal, Kind::CrbaWorld}) {
        const Eigen::MatrixXd Hp = pin->joint_block(c, k);
        const double dp = (Hn.bottomRightCorner(n, n) - Hp).cwiseAbs().maxCoeff();
        d[1] = std::max(d[1], dp / Hp.cwiseAbs().maxCoeff());
      }
    const double a = mie_now(k), b = mie_before(k);
    const double p = pin->inverse_effective_mass(Kind::DenseLocal, k);
    const double q = pin->inverse_effective_mass(Kind::Delassus, k);
    d[2] = std::max(d[2], rel(a, b));
    for (Kind c : {Kind::DenseLocal, Kind::DenseWorld, Kind::Minverse})
      d[3] = std::max(d[3], rel(a, pin->inverse_effective_mass(c, k)));
    d[4] = std::max(d[4], rel(a, q));
    d[5] = std::max(d[5], rel(q, p));
  }
  auto ffsr_pass = [&](auto&& fn) {
    double acc = 0;
    const double t0 = ffsr_bench::thread_seconds();
    for (int k = 0; k < kPassPoses; ++k) acc += fn(k);
    const double t = ffsr_bench::thread_seconds() - t0;
    g_sink = g_sink + acc;
    return t / kPassPoses;
  };
  auto pin_pass = [&](ffsr_bench::PinocchioRoutes& r, Kind kind) {
    return r.pass(kind, kPassPoses) / kPassPoses;
  };
  for (double& x : row.t) x = 1e300;
  for (int r = -1; r < kPasses; ++r) {  // pass -1 warms up; the minimum over the others
    const double a[18] = {ffsr_pass(crba_now),
                          ffsr_pass(crba_before),
                          pin_pass(*pin, Kind::CrbaLocal),
                          pin_pass(*pin, Kind::CrbaWorld),
                          pin_pass(*pin, Kind::CrbaLocalFull),
                          pin_pass(*lib, Kind::CrbaLocal),
                          pin_pass(*lib, Kind::CrbaWorld),
                          ffsr_pass(mie_now),
                          ffsr_pass(mie_before),
                          pin_pass(*pin, Kind::DenseLocal),
                          pin_pass(*pin, Kind::DenseWorld),
                          pin_pass(*pin, Kind::Minverse),
                          pin_pass(*pin, Kind::Delassus),
                          pin_pass(*lib, Kind::DenseLocal),
                          pin_pass(*lib, Kind::DenseWorld),
                          pin_pass(*lib, Kind::Delassus),
                          ffsr_pass(crba_now),
                          ffsr_pass(mie_now)};
    if (r >= 0)
      for (int i = 0; i < 18; ++i) row.t[i] = std::min(row.t[i], a[i]);
  }
  row.t[0] = std::min(row.t[0], row.t[16]);  // ffsr timed twice a pass, at both ends
  row.t[7] = std::min(row.t[7], row.t[17]);
  return row;
}

#ifdef FFSR_BENCH_PIN_LIBRARY
constexpr bool kLibraryTimed = true;
#else
constexpr bool kLibraryTimed = false;
#endif

void print_tables(const std::vector<Row>& rows) {
  std::printf(
      "ns per call, minimum over 51 interleaved passes of the mean over the same 200 random poses "
      "(thread CPU time); Pinocchio's templates instantiated in this executable at its flags, "
      "\"library\" its precompiled libpinocchio_default%s\n\n",
      kLibraryTimed ? "" : " (not in this build: the library columns time the templates again)");
  std::printf(
      "| robot | n | CRBA ffsr / Pinocchio | before | Pinocchio LOCAL / WORLD | LOCAL + sym | library | "
      "M_ie ffsr / Pinocchio | before | Pinocchio dense LOCAL / WORLD | Minverse | Delassus | "
      "library dense / Delassus |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& w : rows) {
    const double* t = w.t;
    const double pc = std::min(t[2], t[3]), pm = std::min({t[9], t[10], t[11], t[12]});
    std::printf(
        "| %s | %d | %.0f / %.0f ns = %.2fx | %.0f | %.0f / %.0f | %.0f | %.0f | %.0f / %.0f ns = %.2fx | "
        "%.0f | %.0f / %.0f | %.0f | %.0f | %.0f / %.0f |\n",
        w.name.c_str(), w.n, t[0] * 1e9, pc * 1e9, t[0] / pc, t[1] * 1e9, t[2] * 1e9, t[3] * 1e9, t[4] * 1e9,
        std::min(t[5], t[6]) * 1e9, t[7] * 1e9, pm * 1e9, t[7] / pm, t[8] * 1e9, t[9] * 1e9, t[10] * 1e9,
        t[11] * 1e9, t[12] * 1e9, std::min(t[13], t[14]) * 1e9, t[15] * 1e9);
  }
  std::printf(
      "\n| robot | H - before | H - Pinocchio | M_ie - before | M_ie - Pinocchio dense | M_ie - Delassus | "
      "Delassus - dense |\n|---|---|---|---|---|---|---|\n");
  for (const Row& w : rows)
    std::printf("| %s | %.0e | %.0e | %.0e | %.0e | %.0e | %.0e |\n", w.name.c_str(), w.agree[0], w.agree[1],
                w.agree[2], w.agree[3], w.agree[4], w.agree[5]);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : std::string(FFSR_SOURCE_DIR) + "/robots";
  try {
    std::vector<Row> rows;
    rows.push_back(compare("3-DOF paper", read_text(dir + "/paper_3dof.urdf")));
    rows.push_back(compare("7-DOF paper", read_text(dir + "/paper_7dof.urdf")));
    for (int n : {3, 7, 14, 28, 56})
      rows.push_back(compare("chain " + std::to_string(n), chain_urdf(n, static_cast<unsigned>(n))));
    print_tables(rows);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ffsr-bench-pinocchio: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
