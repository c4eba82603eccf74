// python/src/batch.cpp -- many configurations in one call: M_ie (Eq. 14) and F_max (Eq. 24 or the exact
// peak of Eq. 16) for an (N, n) array of joint configurations, on the library's thread pool
// (detail::parallel_chunks: one Data per thread, fixed chunks, so the result does not depend on the
// thread count), with the GIL released.
#include "arguments.hpp"
#include "bindings.hpp"
#include "outputs.hpp"

#include "ffsr/contact/contact_law.hpp"
#include "ffsr/detail/parallel.hpp"

#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <thread>

namespace ffsr::python {
namespace {

using namespace nb::literals;

unsigned threads_arg(int threads) {
  if (threads < 0) throw InputError(detail::str("threads must be >= 0 (0: one per core), got ", threads));
  return threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : unsigned(threads);
}

/// The arguments the batch calls share, read and checked with the GIL held.
struct Batch {
  Batch(const Model& model, nb::handle thetas, nb::handle frame_h, const Target* target_p,
        const std::string& joints_name, nb::handle armature, int threads_n, const char* where)
      : X(thetas, where, "thetas"),
        frame(frame_arg(model, frame_h, where)),
        target(target_or_default(target_p)),
        threads(threads_arg(threads_n)) {
    X.require(X.rows(), model.n());
    const ContactJoints cj = joints_arg(model, joints_name, armature, where);
    if (joints_name != "free" || !armature.is_none()) joints = cj;
  }
  MatIn X;
  int frame;
  const Target& target;
  std::optional<ContactJoints> joints;  ///< none: the paper's free joints
  unsigned threads;
};

/// M_ie of every row of the batch into M (N entries), by integrated_effective_mass's route (the O(n)
/// recursion), with one Data per thread.
void batch_mie(const Model& model, const BasePose& base, const Batch& b, double* M) {
  const auto N = static_cast<std::uint64_t>(b.X.rows());
  const Vector3 u = b.target.normal_world();
  const double inv_t = b.target.inverse_mass_along_normal();
  std::vector<std::unique_ptr<Data>> datas;
  for (unsigned t = 0; t < b.threads; ++t) datas.push_back(std::make_unique<Data>(model));
  const auto X = b.X.map();
  detail::ParallelOptions opt;
  opt.chunk = 256;
  detail::parallel_chunks(
      N, b.threads,
      [&](unsigned worker, std::uint64_t lo, std::uint64_t hi) {
        Data& d = *datas[worker];
        Eigen::VectorXd theta(model.n());
        for (std::uint64_t i = lo; i < hi; ++i) {
          theta = X.row(Eigen::Index(i)).transpose();
          M[i] = b.joints
                     ? integrated_effective_mass(model, d, base, theta, b.frame, u, inv_t, *b.joints)
                     : integrated_effective_mass(model, d, base, theta, b.frame, u, inv_t);
        }
      },
      opt);
}

/// The median time per call of integrated_effective_mass's route from C++ over the rows of `thetas` (cycled),
/// measured as bench/bench_main.cpp measures it: calls per batch calibrated to `batch_seconds`, the
/// median of `batches` batch means. For python/bench: the same call without Python, in the same process.
double time_cpp_mie(const Model& model, Data& data, const BasePose& base, const MatIn& thetas, int frame,
                    const Target& target, int batches, double batch_seconds) {
  using Clock = std::chrono::steady_clock;
  const Vector3 u = target.normal_world();
  const double inv_t = target.inverse_mass_along_normal();
  const auto X = thetas.map();
  std::vector<Eigen::VectorXd> rows;
  for (Eigen::Index i = 0; i < X.rows(); ++i) rows.emplace_back(X.row(i).transpose());
  const size_t m = rows.size();
  volatile double sink = 0;
  double acc = 0;
  auto run = [&](long n) {
    const auto t0 = Clock::now();
    for (long i = 0; i < n; ++i)
      acc += integrated_effective_mass(model, data, base, rows[size_t(i) % m], frame, u, inv_t);
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  long n = 1;
  for (;;) {
    const double dt = run(n);
    if (dt >= 0.2 * batch_seconds || n >= (1L << 26)) {
      n = std::max(1L, long(double(n) * batch_seconds / std::max(dt, 1e-9)));
      break;
    }
    n *= 4;
  }
  std::vector<double> per_call;
  for (int b = 0; b < batches; ++b) per_call.push_back(run(n) / double(n));
  sink = sink + acc;
  std::sort(per_call.begin(), per_call.end());
  return per_call[per_call.size() / 2];
}

}  // namespace

void bind_batch(nb::module_& m) {
  m.def(
      "integrated_effective_mass_batch",
      [](const Model& model, const BasePose& base, nb::handle thetas, nb::handle frame, const Target* target,
         const std::string& joints, nb::handle armature, int threads) {
        const Batch b(model, thetas, frame, target, joints, armature, threads,
                      "integrated_effective_mass_batch");
        double* M = nullptr;
        auto result = new_array(size_t(b.X.rows()), &M);
        {
          nb::gil_scoped_release release;
          batch_mie(model, base, b, M);
        }
        return result;
      },
      "model"_a, "base"_a, "thetas"_a, "frame"_a.none() = nb::none(), "target"_a.none() = nb::none(),
      "joints"_a = "free", "armature"_a.none() = nb::none(), "threads"_a = 0,
      "M_ie (Eq. 14) of every row of thetas (N, n) at one base pose, (N,), on `threads` threads (0: one per\n"
      "core), without the GIL. The same values as integrated_effective_mass row by row, whatever the thread\n"
      "count; N = 0 gives an empty array.");

  m.def(
      "max_force_batch",
      [](const Model& model, const BasePose& base, nb::handle thetas, const ContactLaw& law, nb::handle frame,
         const Target* target, bool exact, const std::string& joints, nb::handle armature, int threads) {
        const Batch b(model, thetas, frame, target, joints, armature, threads, "max_force_batch");
        const size_t N = size_t(b.X.rows());
        double *M = nullptr, *F = nullptr;
        auto m_out = new_array(N, &M);
        auto f_out = new_array(N, &F);
        {
          nb::gil_scoped_release release;
          batch_mie(model, base, b, M);
          detail::parallel_for(N, b.threads, [&](std::uint64_t i) {
            F[i] = exact ? max_force_exact(law.law, M[i]) : max_force_closed_form(law.law, M[i]);
          });
        }
        return std::make_pair(m_out, f_out);
      },
      "model"_a, "base"_a, "thetas"_a, "law"_a, "frame"_a.none() = nb::none(), "target"_a.none() = nb::none(),
      "exact"_a = false, "joints"_a = "free", "armature"_a.none() = nb::none(), "threads"_a = 0,
      "(M_ie, F_max) of every row of thetas (N, n), two (N,) arrays: M_ie (Eq. 14) and the peak force of\n"
      "`law` (a ContactLaw): the closed form of Eq. 24, or with exact=True the exact peak of Eq. 16.\n"
      "Threads and GIL as integrated_effective_mass_batch.");
}

void bind_bench_timing(nb::module_& m) {
  m.def(
      "_time_cpp_integrated_effective_mass",
      [](const Model& model, Data& data, const BasePose& base, nb::handle thetas, const Target* target,
         int batches, double batch_seconds) {
        const MatIn X(thetas, "_time_cpp_integrated_effective_mass", "thetas");
        X.require(X.rows(), model.n());
        if (X.rows() < 1 || batches < 1)
          throw InputError("_time_cpp_integrated_effective_mass: nothing to time");
        check_data(model, data, "_time_cpp_integrated_effective_mass");
        return time_cpp_mie(model, data, base, X, model.end_effector(), target_or_default(target), batches,
                            batch_seconds);
      },
      "model"_a, "data"_a, "base"_a, "thetas"_a, "target"_a.none() = nb::none(), "batches"_a = 31,
      "batch_seconds"_a = 5e-3,
      "For the bench (python/bench): the median seconds per call of integrated_effective_mass's route (the\n"
      "O(n) recursion) from C++ over the rows of thetas, timed as bench/bench_main.cpp times it, in this "
      "process.");
}

}  // namespace ffsr::python
