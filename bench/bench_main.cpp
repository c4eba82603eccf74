// bench/bench_main.cpp -- ffsr-bench: time per call and heap allocations per call of the hot paths.
//
//   ffsr-bench [--quick] [DIR]
//
// DIR holds paper_3dof.urdf and paper_7dof.urdf (or is a source tree with them in robots/);
// default FFSR_SOURCE_DIR/robots. For each robot it reports the median and the minimum over 31
// batches of the mean time per call (std::chrono::steady_clock; a batch lasts about 5 ms), and the
// heap allocations per call after set-up, of: forward_kinematics, crba, J_f (frame_jacobian +
// generalized_jacobian), crba + J_f, M_ie (integrated_effective_mass, the O(n) recursion; and
// integrated_effective_mass_dense: H, J, the solve), its analytic gradient, rnea, and momentum +
// kinetic_energy; one point of `ffsr-optimize map` (M_ie, F_max and its CSV row) in points per
// second. Then the contact benchmarks (bench_contact.hpp), one multibody CVODE contact run per robot,
// and the paper's capture scenarios (plan_capture, plain and optimized). The time targets are printed beside the figures.
//
// Allocations are counted by replacing the global operator new/delete and, on glibc, by
// interposing malloc/calloc/realloc/free (Eigen allocates with malloc, not with operator new).
// The exit status is 1 when a hot path allocates per call (or something throws), else 0. Timing
// never fails the program: --quick (far fewer repetitions, for the ctest smoke test) checks the
// allocation counts and that everything runs (bench_contact, with its fixed repetition counts, is
// skipped there; each simulation and capture run happens once).
#include <cstdlib>  // first: defines __GLIBC__

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/capture.hpp"
#include "ffsr/simulate/multibody.hpp"
#ifdef FFSR_HAVE_GLOBAL
#include "ffsr/optimize/global.hpp"
#endif

#include "bench_contact.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <new>
#include <string>
#include <vector>

// ---------------------------------------------------------------------------------------------
// Heap allocation counting
// ---------------------------------------------------------------------------------------------
namespace {
std::atomic<unsigned long> g_new_calls{0};     // global operator new (all forms)
std::atomic<unsigned long> g_malloc_calls{0};  // malloc family (includes operator new below)
}  // namespace

#if defined(__GLIBC__) && !defined(FFSR_BENCH_NO_MALLOC_HOOK)
#define FFSR_BENCH_MALLOC_HOOK 1
// glibc exports its allocator under these names too; the definitions below interpose the public
// names for the whole process (shared libraries included) and forward to glibc.
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
void* memalign(std::size_t a, std::size_t n) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) {
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  void* p = __libc_memalign(a, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
void free(void* p) { __libc_free(p); }
}
#else
#define FFSR_BENCH_MALLOC_HOOK 0
#endif

namespace {
void* counted_new(std::size_t n) {
  g_new_calls.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* counted_new_aligned(std::size_t n, std::align_val_t al) {
  g_new_calls.fetch_add(1, std::memory_order_relaxed);
  const auto a = std::max(static_cast<std::size_t>(al), sizeof(void*));
  void* p = nullptr;
  if (posix_memalign(&p, a, n ? n : 1) != 0) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return counted_new(n); }
void* operator new[](std::size_t n) { return counted_new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_new(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_new(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a) { return counted_new_aligned(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted_new_aligned(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace {

/// Heap allocations so far: the malloc family when it is interposed (it sees Eigen's and the C
/// libraries' allocations as well as operator new), else operator new only.
unsigned long allocations() {
  return FFSR_BENCH_MALLOC_HOOK ? g_malloc_calls.load(std::memory_order_relaxed)
                                : g_new_calls.load(std::memory_order_relaxed);
}

// ---------------------------------------------------------------------------------------------
// Timing
// ---------------------------------------------------------------------------------------------
volatile double g_sink = 0;

/// Keeps the compiler from assuming anything about the memory behind p.
inline void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

struct Settings {
  bool quick = false;
  int batches = 31;             ///< batches per hot path
  double batch_seconds = 5e-3;  ///< target duration of one batch
  int contact_runs = 11;        ///< multibody CVODE runs per robot (median)
  int capture_runs = 3;         ///< plan_capture runs per case (median)
};

struct Timing {
  double median = 0, min = 0;  ///< seconds per call
  double allocs = 0;           ///< heap allocations per call after the first call
  long calls = 0;              ///< calls per batch
};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Times fn(i) (returns a double that feeds the sink): calibrates the calls per batch so that a
/// batch lasts about s.batch_seconds, then reports the median and minimum batch mean, and the heap
/// allocations per call over one extra batch (after the warm-up: set-up costs are excluded).
template <class Fn>
Timing measure(const Settings& s, Fn&& fn) {
  Timing r;
  double acc = 0;
  // warm-up and calibration
  long n = 1;
  for (;;) {
    const auto t0 = Clock::now();
    for (long i = 0; i < n; ++i) acc += fn(i);
    const double dt = seconds_since(t0);
    if (dt >= 0.2 * s.batch_seconds || n >= (1L << 26)) {
      n = std::max(
          1L, static_cast<long>(std::llround(static_cast<double>(n) * s.batch_seconds / std::max(dt, 1e-9))));
      break;
    }
    n *= 4;
  }
  r.calls = n;
  std::vector<double> per_call;
  per_call.reserve(static_cast<size_t>(s.batches));
  for (int b = 0; b < s.batches; ++b) {
    const auto t0 = Clock::now();
    for (long i = 0; i < n; ++i) acc += fn(i);
    per_call.push_back(seconds_since(t0) / static_cast<double>(n));
  }
  const unsigned long a0 = allocations();
  for (long i = 0; i < n; ++i) acc += fn(i);
  r.allocs = static_cast<double>(allocations() - a0) / static_cast<double>(n);
  g_sink = g_sink + acc;
  std::sort(per_call.begin(), per_call.end());
  r.median = per_call[per_call.size() / 2];
  r.min = per_call.front();
  return r;
}

/// Median wall time and allocations of `runs` runs of fn() (whole runs: set-up included).
template <class Fn>
Timing measure_runs(int runs, Fn&& fn) {
  Timing r;
  std::vector<double> t;
  unsigned long allocs = 0;
  double acc = 0;
  for (int k = 0; k < runs; ++k) {
    const unsigned long a0 = allocations();
    const auto t0 = Clock::now();
    acc += fn();
    t.push_back(seconds_since(t0));
    allocs += allocations() - a0;
  }
  g_sink = g_sink + acc;
  std::sort(t.begin(), t.end());
  r.median = t[t.size() / 2];
  r.min = t.front();
  r.allocs = static_cast<double>(allocs) / runs;
  r.calls = 1;
  return r;
}

std::string with_unit(double seconds) {
  char buf[32];
  if (seconds < 1e-6)
    std::snprintf(buf, sizeof buf, "%8.1f ns", seconds * 1e9);
  else if (seconds < 1e-3)
    std::snprintf(buf, sizeof buf, "%8.3f us", seconds * 1e6);
  else if (seconds < 1.0)
    std::snprintf(buf, sizeof buf, "%8.2f ms", seconds * 1e3);
  else
    std::snprintf(buf, sizeof buf, "%8.3f s ", seconds);
  return buf;
}

void print_header(const char* title) {
  std::printf("\n%s\n", title);
  std::printf("%-11s %-50s %11s %11s %12s  %s\n", "robot", "quantity", "median", "min", "allocs/call",
              "target");
}

void print_row(const std::string& robot, const std::string& what, const Timing& t, const std::string& target,
               double limit_seconds = 0) {
  std::string verdict;
  if (limit_seconds > 0) verdict = t.median < limit_seconds ? "  ok" : "  MISSED";
  char allocs[32] = "-";  // negative: not counted (a sum of runs)
  if (t.allocs >= 0) std::snprintf(allocs, sizeof allocs, "%.4g", t.allocs);
  std::printf("%-11s %-50s %11s %11s %12s  %s%s\n", robot.c_str(), what.c_str(), with_unit(t.median).c_str(),
              with_unit(t.min).c_str(), allocs, target.c_str(), verdict.c_str());
}

// ---------------------------------------------------------------------------------------------
// The paper's robots and scenarios
// ---------------------------------------------------------------------------------------------
constexpr double kDeg = M_PI / 180.0;

Eigen::VectorXd degrees(std::initializer_list<double> d) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(d.size()));
  Eigen::Index i = 0;
  for (double x : d) v(i++) = x * kDeg;
  return v;
}

struct Robot {
  std::string name;
  ffsr::Model model;
  int ee = -1;
  Eigen::VectorXd theta_contact;  ///< the configuration of Tables 3 and 6
  ffsr::Target target;            ///< the paper's target (Sections 5.1 and 5.2)
  Eigen::VectorXd theta_start;    ///< initial configuration of the capture scenario
};

Robot paper_3dof(const std::string& dir) {
  Robot r{"3-DOF", ffsr::model_from_urdf_file(dir + "/paper_3dof.urdf", "ee"),
          -1,      degrees({0, 90, -90}),
          {},      degrees({0, 150, -100})};
  r.ee = r.model.frame_index("ee");
  r.target.contact_offset = ffsr::Vector3(-0.25, 0.15, 0.0);
  r.target.angular_velocity = ffsr::Vector3(0, 0, 2) * kDeg;
  r.target.position = ffsr::Vector3(2.75, 1.45, 0.0);
  return r;
}

Robot paper_7dof(const std::string& dir) {
  Robot r{"7-DOF", ffsr::model_from_urdf_file(dir + "/paper_7dof.urdf", "ee"),
          -1,      degrees({0, 29, 54, 10, -10, 120, 32}),
          {},      degrees({0, 90, 90, -90, 90, 90, 0})};
  r.ee = r.model.frame_index("ee");
  r.target.contact_offset = ffsr::Vector3(-0.25, 0.15, 0.1);
  r.target.angular_velocity = ffsr::Vector3(1, -0.5, 2) * kDeg;
  r.target.position = ffsr::Vector3(2.3, -0.8, 2.0);
  return r;
}

const ffsr::ContactParams kContact{1e9, 1.5, 0.9};
constexpr const char* kLaw = "herbert-mcwhannell";
constexpr double kApproachSpeed = 0.2;

// ---------------------------------------------------------------------------------------------
// Hot paths
// ---------------------------------------------------------------------------------------------
struct AllocCheck {
  std::vector<std::string> failures;
  void require_zero(const std::string& robot, const std::string& what, const Timing& t) {
    if (t.allocs > 0) {
      char line[160];
      std::snprintf(line, sizeof line, "%s %s: %.4g heap allocations per call", robot.c_str(), what.c_str(),
                    t.allocs);
      failures.emplace_back(line);
    }
  }
};

void bench_hot_paths(const Settings& s, const Robot& r, AllocCheck& check) {
  using namespace ffsr;
  const Model& model = r.model;
  const int n = model.n();
  // K configurations around the paper's one, so that each call sees different inputs
  constexpr int K = 16;
  std::vector<Eigen::VectorXd> thetas;
  std::vector<BasePose> bases;
  std::vector<Data> datas;  // each with crba at its configuration (for J_f alone)
  for (int k = 0; k < K; ++k) {
    Eigen::VectorXd th = r.theta_contact;
    for (int j = 0; j < n; ++j) th(j) += 0.05 * std::sin(1.0 + k + 3.0 * j);
    thetas.push_back(th);
    BasePose b;
    b.position = Vector3(0.01 * k, -0.02 * k, 0.005 * k);
    b.orientation = Quaternion(Eigen::AngleAxisd(0.02 * k, Vector3(1, 2, 3).normalized()));
    bases.push_back(b);
    datas.emplace_back(model);
    crba(model, datas.back(), b, th);
  }
  Data data(model);
  const Target& target = r.target;
  const Vector3 u = target.normal_world();
  const double target_inv_mass = target.inverse_mass_along_normal();
  Eigen::VectorXd grad(n);
  std::vector<Eigen::VectorXd> vs, as;
  for (int k = 0; k < K; ++k) {
    vs.push_back(Eigen::VectorXd::LinSpaced(model.nv(), -0.1, 0.1 + 0.01 * k));
    as.push_back(Eigen::VectorXd::LinSpaced(model.nv(), 0.2 - 0.01 * k, -0.3));
  }
  auto pick = [](long i) { return static_cast<size_t>(i % K); };

  const Timing fk = measure(s, [&](long i) {
    forward_kinematics(model, data, bases[pick(i)], thetas[pick(i)]);
    escape(&data);
    return data.p.back()(0);
  });
  print_row(r.name, "forward_kinematics", fk, "");
  check.require_zero(r.name, "forward_kinematics", fk);

  const Timing h =
      measure(s, [&](long i) { return crba(model, data, bases[pick(i)], thetas[pick(i)])(6, 6); });
  print_row(r.name, "crba (H)", h, "0 allocs");
  check.require_zero(r.name, "crba", h);

  const Timing jf = measure(s, [&](long i) {
    Data& d = datas[pick(i)];
    frame_jacobian(model, d, r.ee);
    return generalized_jacobian(model, d)(0, 0);
  });
  print_row(r.name, "J_f: frame_jacobian + generalized_jacobian", jf, "0 allocs");
  check.require_zero(r.name, "J_f", jf);

  const Timing hjf = measure(s, [&](long i) {
    return generalized_jacobian(model, data, bases[pick(i)], thetas[pick(i)], r.ee)(0, 0);
  });
  print_row(r.name, "crba + J_f (one configuration)", hjf, "0 allocs");
  check.require_zero(r.name, "crba + J_f", hjf);

  const Timing mie = measure(s, [&](long i) {
    return integrated_effective_mass(model, data, bases[pick(i)], thetas[pick(i)], r.ee, target);
  });
  print_row(r.name, "M_ie: integrated_effective_mass (O(n))", mie, n == 7 ? "< 2 us, 0 allocs" : "0 allocs",
            n == 7 ? 2e-6 : 0);
  check.require_zero(r.name, "integrated_effective_mass", mie);
  const Timing mie_dense = measure(s, [&](long i) {
    return integrated_effective_mass_dense(model, data, bases[pick(i)], thetas[pick(i)], r.ee, target);
  });
  print_row(r.name, "M_ie: integrated_effective_mass_dense (H, J, solve)", mie_dense, "0 allocs");
  check.require_zero(r.name, "integrated_effective_mass_dense", mie_dense);

  const Timing dmie = measure(s, [&](long i) {
    const double M = integrated_effective_mass_gradient_dense(model, data, bases[pick(i)], thetas[pick(i)],
                                                              r.ee, u, target_inv_mass, grad);
    return M + grad(0);
  });
  print_row(r.name, "dM_ie/dtheta: integrated_effective_mass_gradient_dense", dmie, "0 allocs");
  check.require_zero(r.name, "integrated_effective_mass_gradient", dmie);

  const Timing id = measure(s, [&](long i) {
    return rnea(model, data, bases[pick(i)], thetas[pick(i)], vs[pick(i)], as[pick(i)])(0);
  });
  print_row(r.name, "rnea (tau = H a + C)", id, "");
  check.require_zero(r.name, "rnea", id);

  const Timing mom = measure(s, [&](long i) {
    const Data& d = datas[pick(i)];
    return momentum(model, d, vs[pick(i)])(3) + kinetic_energy(model, d, vs[pick(i)]);
  });
  print_row(r.name, "momentum + kinetic_energy (body by body)", mom, "0 allocs");
  check.require_zero(r.name, "momentum + kinetic_energy", mom);
}

/// One point of `ffsr-optimize map` (src/cli/map.cpp): crba, the inverse effective mass, M_ie
/// (Eq. 14), the closed-form F_max (Eq. 24) and the CSV row formatted with std::to_chars, on a grid
/// walked in the map's order (last joint fastest, 2 deg steps). Reports points per second on one
/// thread beside its target (5.83 million points in 10 s on 2 threads: 292k/s each).
void bench_map(const Settings& s, const Robot& r, AllocCheck& check) {
  using namespace ffsr;
  const Model& model = r.model;
  Data data(model);
  const Vector3 u = r.target.normal_world();
  const double target_inv_mass = r.target.inverse_mass_along_normal();
  const double v_in = approach_velocity(u, Vector3(kApproachSpeed * u), r.target.velocity,
                                        r.target.angular_velocity_world(), r.target.offset_world());
  const AnyContactLaw law = make_contact_law(kLaw, kContact, v_in);
  Eigen::VectorXd theta = r.theta_contact;
  const BasePose base;
  std::vector<char> row(64 * static_cast<size_t>(model.n() + 2));
  const Timing t = measure(s, [&](long i) {
    long rest = i;
    char* p = row.data();
    char* const end = row.data() + row.size();
    for (int j = model.n(); j-- > 0;) {
      const double deg = -180.0 + 2.0 * static_cast<double>(rest % 180);
      rest /= 180;
      theta(j) = deg * kDeg;
      const auto c = std::to_chars(p, end, deg);
      p = c.ptr;
      *p++ = ',';
    }
    crba(model, data, base, theta);
    const double M = 1.0 / (inverse_effective_mass(model, data, r.ee, u) + target_inv_mass);
    const double F = max_force_closed_form(law, M);
    p = std::to_chars(p, end, M).ptr;
    *p++ = ',';
    p = std::to_chars(p, end, F).ptr;
    *p++ = '\n';
    escape(row.data());
    return static_cast<double>(p - row.data());
  });
  char target[96];
  std::snprintf(target, sizeof target, "%.3g points/s (>= 292k/s a thread), 0 allocs", 1.0 / t.median);
  print_row(r.name, "map point: M_ie + F_max + CSV row (to_chars)", t, target,
            r.model.n() == 3 ? 1.0 / 292e3 : 0);
  check.require_zero(r.name, "map point", t);
}

/// A serial chain of n revolute joints (axes, offsets and inertias varied deterministically).
ffsr::Model bench_chain(int n) {
  using namespace ffsr;
  ModelBuilder b("base", Inertia{400, Vector3(0.05, -0.02, 0.1), Vector3(90, 110, 100).asDiagonal()});
  std::string parent = "base";
  for (int i = 1; i <= n; ++i) {
    const std::string child = "l" + std::to_string(i);
    const double s = std::sin(1.7 * i), c = std::cos(2.3 * i);
    b.add_joint("j" + std::to_string(i), JointType::Revolute, parent,
                Pose::from_xyz_rpy(Vector3(0.3 + 0.1 * s, 0.1 * c, 0.05), Vector3(0.3 * c, 0.2 * s, 0.7 * i)),
                Vector3(s, c, 1.5), child,
                Inertia{3 + 2 * s, Vector3(0.15, 0.01 * c, 0), Vector3(0.1, 0.4, 0.4).asDiagonal()});
    parent = child;
  }
  b.add_fixed("tip_mount", parent, Pose{Vector3(0.2, 0, 0)}, "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

/// The inverse effective mass by crba + dense Cholesky and by the articulated-body recursion, on
/// serial chains of growing size: where the recursion starts to win (kArticulatedMinJoints).
void bench_crossover(const Settings& s, AllocCheck& check) {
  using namespace ffsr;
  for (int n : {3, 5, 6, 7, 8, 10, 12, 14, 28, 56}) {
    const Model model = bench_chain(n);
    Data data(model);
    const int ee = model.end_effector();
    constexpr int K = 16;
    std::vector<Eigen::VectorXd> thetas;
    for (int k = 0; k < K; ++k)
      thetas.push_back(Eigen::VectorXd::LinSpaced(n, -1.0 + 0.1 * k, 2.0 - 0.05 * k));
    const Vector3 u = Vector3(1, 2, -0.5).normalized();
    const BasePose base;
    const std::string name = "chain " + std::to_string(n);
    const Timing dense = measure(s, [&](long i) {
      crba(model, data, base, thetas[static_cast<size_t>(i % K)]);
      return inverse_effective_mass(model, data, ee, u);
    });
    const Timing aba = measure(s, [&](long i) {
      forward_kinematics(model, data, base, thetas[static_cast<size_t>(i % K)]);
      return inverse_effective_mass_articulated(model, data, ee, u);
    });
    char ratio[64];
    std::snprintf(ratio, sizeof ratio, "articulated/dense %.2f (fast path: %s)", aba.median / dense.median,
                  n >= kArticulatedMinJoints ? "articulated" : "dense");
    print_row(name, "1/m_e: crba + dense Cholesky", dense, "");
    print_row(name, "1/m_e: articulated-body recursion, O(n)", aba, ratio);
    check.require_zero(name, "inverse_effective_mass_articulated", aba);
    const ContactJoints armature{JointModel::Armature, Eigen::VectorXd::Constant(n, 0.1)};
    const Timing arm = measure(s, [&](long i) {
      return integrated_effective_mass(model, data, base, thetas[static_cast<size_t>(i % K)], ee, u, 0.005,
                                       armature);
    });
    print_row(name, "M_ie, armature joints, O(n)", arm, "");
    check.require_zero(name, "integrated_effective_mass (armature)", arm);
    Eigen::VectorXd grad(n);
    const Timing g = measure(s, [&](long i) {
      return integrated_effective_mass_gradient(model, data, base, thetas[static_cast<size_t>(i % K)], ee, u,
                                                0.005, ContactJoints{}, grad);
    });
    print_row(name, "gradient of M_ie, O(n)", g, "");
    check.require_zero(name, "integrated_effective_mass_gradient", g);
  }
}

// ---------------------------------------------------------------------------------------------
// Whole runs: the multibody CVODE contact and the capture scenarios
// ---------------------------------------------------------------------------------------------
void bench_multibody_contact(const Settings& s, const Robot& r) {
  using namespace ffsr;
  MultibodyContactResult last;
  const Timing t = measure_runs(s.contact_runs, [&] {
    last = simulate_contact(r.model, BasePose{}, r.theta_contact, r.ee, r.target, kApproachSpeed, kContact,
                            kLaw);
    return last.f_max;
  });
  print_row(r.name, "simulate_contact (multibody CVODE run)", t, "< 50 ms", 50e-3);
  std::printf("%-11s   F_max = %.1f N, M_ie = %.4f kg, %ld CVODE steps, %.0f heap allocations per run\n", "",
              last.f_max, last.integrated_effective_mass, last.steps, t.allocs);
}

struct CaptureCase {
  const char* label;
  ffsr::CaptureTask task;
  double gain;
};

ffsr::CaptureTask position_task(bool x, bool y, bool z) {
  ffsr::CaptureTask t;
  t.kind = ffsr::CaptureTask::Kind::Position;
  t.axes = {x, y, z};
  return t;
}
ffsr::CaptureTask pose_task() {
  ffsr::CaptureTask t;
  t.kind = ffsr::CaptureTask::Kind::Pose;
  return t;
}

/// The paper's capture problem for robot r: its start configuration and target, the paper's contact.
ffsr::CaptureProblem capture_problem(const Robot& r) {
  ffsr::CaptureProblem pb;
  pb.model = &r.model;
  pb.frame = r.ee;
  pb.theta = r.theta_start;
  pb.target = r.target;
  pb.contact = kContact;
  pb.law = kLaw;
  pb.approach_speed = kApproachSpeed;
  return pb;
}

/// Runs one plan_capture case (median of s.capture_runs runs) and prints it. Returns the median.
double bench_capture_case(const Settings& s, const Robot& r, double duration, const CaptureCase& c) {
  using namespace ffsr;
  const CaptureProblem pb = capture_problem(r);
  CaptureOptions opt;
  opt.duration = duration;
  opt.step = 0.1;
  opt.gain = c.gain;
  CaptureResult last;
  const Timing t = measure_runs(s.capture_runs, [&] {
    last = plan_capture(pb, c.task, opt);
    return last.M_ie;
  });
  print_row(r.name, c.label, t, "");
  std::printf(
      "%-11s   M_ie = %.4f kg, %ld RK4 steps (h = %.2f s, 4 evaluations each), %.1f allocations per step\n",
      "", last.M_ie, last.steps, opt.step, t.allocs / static_cast<double>(last.steps));
  return t.median;
}

void bench_scenarios(const Settings& s, const Robot& r3, const Robot& r7) {
  const auto xy = position_task(true, true, false), xyz = position_task(true, true, true);
  const double plain3 =
      bench_capture_case(s, r3, 180.0, {"plan_capture plain (xy position, rho = 0)", xy, 0.0});
  const double opt3 =
      bench_capture_case(s, r3, 180.0, {"plan_capture optimized (xy, rho = -0.01)", xy, -0.01});
  print_row(r3.name, "scenario: plain + optimized", {plain3 + opt3, plain3 + opt3, -1, 1}, "< 0.5 s", 0.5);
  const double plain7 =
      bench_capture_case(s, r7, 157.0, {"plan_capture plain (pose, rho = 0)", pose_task(), 0.0});
  const double pose7 =
      bench_capture_case(s, r7, 157.0, {"plan_capture optimized (pose, rho = -0.2)", pose_task(), -0.2});
  const double pos7 =
      bench_capture_case(s, r7, 157.0, {"plan_capture optimized (xyz, rho = -0.01)", xyz, -0.01});
  print_row(r7.name, "scenario pose: plain + optimized (pose)", {plain7 + pose7, plain7 + pose7, -1, 1},
            "< 2 s", 2.0);
  print_row(r7.name, "scenario position: plain + optimized (xyz)", {plain7 + pos7, plain7 + pos7, -1, 1},
            "< 2 s", 2.0);
}

#ifdef FFSR_HAVE_GLOBAL
/// Global capture optimization: the whole plan_capture_global (task-only run, search,
/// reaching run, search at the reached base pose, ...) with the scenario files' 3 deg/s limit; and
/// the multibody-force search (CVODE ranking of the local optima) at c_r = 0.3.
void bench_global(const Settings& s, const Robot& r3, const Robot& r7) {
  using namespace ffsr;
  auto run = [&](const Robot& r, double T, const CaptureTask& task, const char* target, double limit) {
    CaptureProblem pb = capture_problem(r);
    CaptureOptions opt;
    opt.duration = T;
    opt.step = 0.1;
    opt.max_joint_rate = 3.0 * M_PI / 180.0;
    GlobalCaptureResult last;
    const Timing t = measure_runs(s.capture_runs, [&] {
      last = plan_capture_global(pb, task, opt, GlobalCaptureOptions{});
      return last.run.M_ie;
    });
    print_row(r.name, "plan_capture_global (search + reaching plan)", t, target, limit);
    std::printf(
        "%-11s   M_ie = %.4f kg, gap %.3f %%, %d shooting iteration(s), %ld SLSQP evaluations, search %.3f "
        "s\n",
        "", last.run.M_ie, last.optimality_gap_percent, last.counters.shooting_iterations,
        last.counters.evaluations, last.counters.search_seconds);
    return pb;
  };
  run(r3, 180.0, position_task(true, true, false), "< 1 s", 1.0);
  CaptureProblem pb = run(r7, 157.0, position_task(true, true, true), "< 3 s", 3.0);
  pb.contact.c_r = 0.3;
  CaptureOptions opt;
  opt.duration = 157.0;
  const CaptureTask task = position_task(true, true, true);
  const CaptureSetup setup = prepare_capture(pb, task, opt);
  ManifoldSearchOptions so;
  so.objective = GlobalObjective::MultibodyForce;
  ManifoldSearchResult last;
  const Timing t = measure_runs(s.capture_runs, [&] {
    last = search_capture_manifold(pb, task, setup, pb.base, so);
    return last.best.objective;
  });
  print_row(r7.name, "multibody-force search (c_r = 0.3, xyz)", t, "", 0);
  std::printf("%-11s   CVODE F_max = %.1f N at M_ie = %.4f kg; %ld SLSQP evaluations, %ld CVODE runs\n", "",
              last.best.objective, last.best.M_ie, last.evaluations, last.objective_evaluations);
}
#endif

std::string robots_dir(const std::string& arg) {
  auto exists = [](const std::string& p) { return std::ifstream(p).good(); };
  const std::string base = arg.empty() ? std::string(FFSR_SOURCE_DIR) + "/robots" : arg;
  if (exists(base + "/paper_3dof.urdf")) return base;
  if (exists(base + "/robots/paper_3dof.urdf")) return base + "/robots";
  throw ffsr::InputError("ffsr-bench: no paper_3dof.urdf in '" + base + "' or '" + base + "/robots'");
}

/// Reads the command line into s and dir; returns an exit code when the program should stop
/// (after --help, or on an unknown option), else -1.
int parse_arguments(int argc, char** argv, Settings& s, std::string& dir) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      s.quick = true;
    } else if (a == "-h" || a == "--help") {
      std::printf(
          "usage: ffsr-bench [--quick] [DIR]\n"
          "  DIR     directory with paper_3dof.urdf and paper_7dof.urdf, or a source tree with robots/\n"
          "          (default %s/robots)\n"
          "  --quick few repetitions, one run of each scenario, no bench_contact (smoke test);\n"
          "          still fails (exit 1) when a hot path allocates per call\n",
          FFSR_SOURCE_DIR);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "ffsr-bench: error: unknown option '%s' (try --help)\n", a.c_str());
      return 2;
    } else {
      dir = a;
    }
  }
  if (s.quick) {
    s.batches = 5;
    s.batch_seconds = 2e-4;
    s.contact_runs = 1;
    s.capture_runs = 1;
  }
  return -1;
}

/// Every benchmark in turn; returns the exit status (1 when a hot path allocates per call).
int run_benchmarks(const Settings& s, const std::string& dir_arg) {
  const std::string dir = robots_dir(dir_arg);
  const Robot r3 = paper_3dof(dir);
  const Robot r7 = paper_7dof(dir);
  std::printf(
      "ffsr-bench%s: %s; median and min over %d batches of the mean time per call (~%.1f ms a batch)\n",
      s.quick ? " --quick" : "", dir.c_str(), s.batches, s.batch_seconds * 1e3);
  std::printf("heap allocations per call after set-up counted by %s\n",
              FFSR_BENCH_MALLOC_HOOK ? "interposed malloc/calloc/realloc and operator new"
                                     : "replaced operator new (malloc not interposed on this platform)");
  AllocCheck check;
  print_header(
      "hot paths (paper configurations: 3-DOF [0, 90, -90] deg, 7-DOF [0, 29, 54, 10, -10, 120, 32] deg, "
      "16 nearby poses cycled)");
  bench_hot_paths(s, r3, check);
  bench_hot_paths(s, r7, check);
  print_header("map (ffsr-optimize map, one thread; 3-DOF grid at 2 deg)");
  bench_map(s, r3, check);
  bench_map(s, r7, check);
  print_header("inverse effective mass: dense against articulated-body recursion (serial chains)");
  bench_crossover(s, check);

  std::printf("\ncontact (bench_contact.hpp; targets: closed form < 1 us, exact < 20 us)\n");
  std::fflush(stdout);
  if (s.quick)
    std::printf("  skipped with --quick\n");
  else
    bench_contact(std::cout);
  std::cout.flush();

  print_header(
      "multibody contact: whole runs (K = 1e9, alpha = 1.5, c_r = 0.9, herbert-mcwhannell, 0.2 m/s)");
  bench_multibody_contact(s, r3);
  bench_multibody_contact(s, r7);

  print_header(
      "capture scenarios: whole plan_capture runs (RK4, step 0.1 s; 3-DOF T = 180 s, 7-DOF T = 157 s)");
  bench_scenarios(s, r3, r7);
#ifdef FFSR_HAVE_GLOBAL
  print_header("global capture optimization (optimize/global.hpp; 3 deg/s joint-rate limit)");
  bench_global(s, r3, r7);
#endif

  if (!check.failures.empty()) {
    std::printf("\nFAIL: hot paths allocate per call:\n");
    for (const auto& f : check.failures) std::printf("  %s\n", f.c_str());
    return 1;
  }
  std::printf("\nallocation check: no hot path allocates per call\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Settings s;
  std::string dir_arg;
  if (const int stop = parse_arguments(argc, argv, s, dir_arg); stop >= 0) return stop;
  try {
    return run_benchmarks(s, dir_arg);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ffsr-bench: error: %s\n", e.what());
    return 1;
  }
}
