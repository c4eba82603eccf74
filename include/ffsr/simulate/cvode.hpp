// ffsr/simulate/cvode.hpp -- an RAII wrapper over SUNDIALS (6.x) CVODE for y' = f(t, y).
#pragma once

#include "ffsr/errors.hpp"

#include <Eigen/Core>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

// Method: BDF with Newton iteration, a dense SUNMatrix and the dense direct linear solver, the
// Jacobian by CVODE's difference quotients. Optional root functions g(t, y) with directions
// (CVodeRootInit, CVodeSetRootDirection). Integration is forward in time.
//
// Ownership: the SUNContext, the N_Vectors, the SUNMatrix, the SUNLinearSolver and the CVODE memory
// live in one heap-allocated state owned by a std::unique_ptr, each with its own deleter, so the
// Integrator is move-only, moves never invalidate the pointer CVODE holds as user data, and
// everything is freed in the right order (CVODE memory first, the context last).
//
// Errors: every SUNDIALS return flag is checked; a failure throws ffsr::IntegrationError naming the
// call, the flag (CVodeGetReturnFlagName), the time and CVODE's own message, which an error handler
// stores instead of printing it (the library never prints). The callbacks catch every C++
// exception, return -1 (unrecoverable) and the wrapper rethrows the original exception once CVODE
// has returned. A non-finite entry in f or g is an IntegrationError too. CVODE's step limit
// (Options::max_num_steps, per call of advance) is always finite, so nothing hangs.

namespace ffsr::cvode {

/// Integrator settings. Tolerances are CVODE's: the local error of y_i is kept below
/// rtol |y_i| + atol_i. Scale the problem so that y is O(1), or give per-component atol_vector.
struct Options {
  double rtol = 1e-10;          ///< relative tolerance (>= 0)
  double atol = 1e-14;          ///< scalar absolute tolerance (>= 0), unless atol_vector is set
  Eigen::VectorXd atol_vector;  ///< optional per-component absolute tolerances (size n, >= 0)
  long max_num_steps = 200000;  ///< steps per call of advance() (> 0): CV_TOO_MUCH_WORK beyond
  double max_step = 0;          ///< largest step (0: no limit)
  double initial_step = 0;      ///< first step (0: CVODE's estimate)
  int max_order = 5;            ///< BDF order limit, 1..5
};

/// ydot = f(t, y). ydot has the size of y on entry; every entry must be written.
using Rhs = std::function<void(double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                               Eigen::Ref<Eigen::VectorXd> ydot)>;
/// g = g(t, y), n_roots entries. CVODE locates the zeros of each g_i.
using Roots =
    std::function<void(double t, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g)>;

namespace detail {
struct State;
}

/// CVODE (BDF, Newton, dense) on y' = f(t, y), y(t0) = y0.
class Integrator {
 public:
  enum class Status {
    Step,     ///< step(): one internal step was taken, t() < t_stop
    Root,     ///< a root function crossed zero (in an allowed direction) at t(); see roots_found()
    Reached,  ///< t() == t_stop (step) or tout (advance)
  };

  /// Sets up CVODE. `root_directions` is empty (any crossing) or has n_roots entries in
  /// {-1 (decreasing only), 0 (any), +1 (increasing only)}. InputError for bad sizes, non-finite
  /// y0 or t0, or invalid options; IntegrationError if SUNDIALS refuses.
  Integrator(Rhs f, const Eigen::VectorXd& y0, double t0, const Options& opt = {}, int n_roots = 0,
             Roots g = {}, std::vector<int> root_directions = {});
  /// Move-only. A moved-from Integrator may only be destroyed or assigned to.
  Integrator(Integrator&&) noexcept = default;
  Integrator& operator=(Integrator&&) noexcept = default;
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;
  ~Integrator() = default;

  /// One internal step (CV_ONE_STEP), never past t_stop (CVodeSetStopTime). t_stop >= t().
  Status step(double t_stop);
  /// Integrates to tout (CV_NORMAL, stop time tout), stopping early at a root. tout >= t().
  Status advance(double tout);
  /// Restarts at (t0, y0) with the same f, g and options (CVodeReInit); counters restart.
  void reinit(double t0, const Eigen::VectorXd& y0);

  double t() const;                  ///< time of the last returned solution
  const Eigen::VectorXd& y() const;  ///< the solution at t()
  Eigen::Index size() const;         ///< number of states
  /// CVODE's internal time t_n (CVodeGetCurrentTime): the end of the last internal step, >= t()
  /// (beyond it after a root or in CV_NORMAL mode).
  double current_time() const;
  /// Dense output y(t) (CVodeGetDky, k = 0); t within the last step [t_n - h_u, t_n], with
  /// t_n = current_time() and h_u = last_step(); IntegrationError (CV_BAD_T) outside.
  Eigen::VectorXd interpolate(double t) const;
  /// CVodeGetRootInfo after Status::Root: per root function, +1 / -1 if it crossed increasing /
  /// decreasing, 0 if it did not.
  std::vector<int> roots_found() const;

  long num_steps() const;       ///< CVodeGetNumSteps
  long num_rhs_evals() const;   ///< CVodeGetNumRhsEvals (without difference-quotient Jacobians)
  long num_root_evals() const;  ///< CVodeGetNumGEvals
  double last_step() const;     ///< CVodeGetLastStep
  /// The last message CVODE passed to its error handler (errors and warnings), or "".
  const std::string& last_message() const;

 private:
  Status finish(int flag, double tret, bool one_step);
  Status run(double t_stop, bool one_step, const char* where);
  void check_target(double t_target, const char* where) const;
  std::unique_ptr<detail::State> s_;
};

// ============================================================================================
// Implementation
// ============================================================================================

namespace detail {

/// Name of a CVODE return flag; CVodeGet*ReturnFlagName return malloc'ed strings.
inline std::string flag_name(long flag, bool linear_solver = false) {
  char* p = linear_solver ? CVodeGetLinReturnFlagName(flag) : CVodeGetReturnFlagName(flag);
  std::string name = p ? p : "unknown flag";
  std::free(p);
  return name;
}

struct ContextDeleter {
  void operator()(SUNContext c) const { SUNContext_Free(&c); }
};
struct VectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix m) const { SUNMatDestroy(m); }
};
struct SolverDeleter {
  void operator()(SUNLinearSolver l) const { SUNLinSolFree(l); }
};
struct MemoryDeleter {
  void operator()(void* m) const { CVodeFree(&m); }
};

/// Everything CVODE touches. Members are destroyed in reverse order: CVODE memory, solver,
/// matrix, vectors, and the context last.
struct State {
  Rhs f;
  Roots g;
  Eigen::Index n = 0;
  int n_roots = 0;
  double t = 0;
  Eigen::VectorXd y;
  std::exception_ptr error;  // thrown inside a callback, rethrown by the wrapper
  std::string message;       // CVODE's last error or warning message

  std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter> ctx;
  std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter> y_nv, scratch_nv, atol_nv;
  std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter> A;
  std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, SolverDeleter> LS;
  std::unique_ptr<void, MemoryDeleter> mem;

  /// Throws the stored callback exception if any, else IntegrationError for a negative flag.
  void check(int flag, const char* call, bool linear_solver = false) {
    if (error) std::rethrow_exception(std::exchange(error, nullptr));
    if (flag < 0)
      throw IntegrationError(ffsr::detail::str("cvode: ", call, " failed with ",
                                               flag_name(flag, linear_solver), " (", flag, ") at t = ", t,
                                               message.empty() ? "" : ": ", message));
  }

  N_Vector make_vector(const char* what) {
    N_Vector v = N_VNew_Serial(static_cast<sunindextype>(n), ctx.get());
    if (!v) throw IntegrationError(ffsr::detail::str("cvode: N_VNew_Serial failed for ", what));
    return v;
  }

  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
    auto* s = static_cast<State*>(user_data);
    try {
      Eigen::Map<const Eigen::VectorXd> ym(N_VGetArrayPointer(y), s->n);
      Eigen::Map<Eigen::VectorXd> yd(N_VGetArrayPointer(ydot), s->n);
      s->f(t, ym, yd);
      for (Eigen::Index i = 0; i < s->n; ++i)
        if (!std::isfinite(yd[i]))
          throw IntegrationError(ffsr::detail::str("cvode: the right-hand side returned ydot[", i,
                                                   "] = ", yd[i], " at t = ", t));
      return 0;
    } catch (...) {
      s->error = std::current_exception();
      return -1;
    }
  }

  static int roots(sunrealtype t, N_Vector y, sunrealtype* gout, void* user_data) {
    auto* s = static_cast<State*>(user_data);
    try {
      Eigen::Map<const Eigen::VectorXd> ym(N_VGetArrayPointer(y), s->n);
      Eigen::Map<Eigen::VectorXd> gm(gout, s->n_roots);
      s->g(t, ym, gm);
      for (int i = 0; i < s->n_roots; ++i)
        if (!std::isfinite(gm[i]))
          throw IntegrationError(
              ffsr::detail::str("cvode: root function ", i, " returned ", gm[i], " at t = ", t));
      return 0;
    } catch (...) {
      s->error = std::current_exception();
      return -1;
    }
  }

  static void error_handler(int /*code*/, const char* module, const char* function, char* msg,
                            void* user_data) {
    try {
      auto* s = static_cast<State*>(user_data);
      s->message =
          ffsr::detail::str(module ? module : "", "::", function ? function : "", ": ", msg ? msg : "");
    } catch (...) {  // an allocation failure while recording a message: nothing to do
    }
  }

  void load(const Eigen::VectorXd& y0) {
    std::copy(y0.data(), y0.data() + n, N_VGetArrayPointer(y_nv.get()));
    y = y0;
  }
  void store() {
    const double* p = N_VGetArrayPointer(y_nv.get());
    std::copy(p, p + n, y.data());
  }
};

inline void validate(const Options& o, Eigen::Index n) {
  using ffsr::detail::str;
  constexpr const char* w = "cvode::Integrator";
  if (!(o.rtol >= 0.0) || !std::isfinite(o.rtol))
    throw InputError(str(w, ": rtol must be finite and >= 0, got ", o.rtol));
  if (o.atol_vector.size() == 0) {
    if (!(o.atol >= 0.0) || !std::isfinite(o.atol))
      throw InputError(str(w, ": atol must be finite and >= 0, got ", o.atol));
  } else {
    ffsr::detail::require_size(o.atol_vector.size(), n, w, "atol_vector");
    for (Eigen::Index i = 0; i < n; ++i)
      if (!(o.atol_vector[i] >= 0.0) || !std::isfinite(o.atol_vector[i]))
        throw InputError(str(w, ": atol_vector[", i, "] must be finite and >= 0, got ", o.atol_vector[i]));
  }
  if (o.max_num_steps <= 0)
    throw InputError(str(w, ": max_num_steps must be positive, got ", o.max_num_steps));
  if (!(o.max_step >= 0.0) || std::isnan(o.max_step))
    throw InputError(str(w, ": max_step must be >= 0 (0: no limit), got ", o.max_step));
  if (!(o.initial_step >= 0.0) || !std::isfinite(o.initial_step))
    throw InputError(str(w, ": initial_step must be finite and >= 0 (0: automatic), got ", o.initial_step));
  if (o.max_order < 1 || o.max_order > 5)
    throw InputError(str(w, ": max_order must be in 1..5 (BDF), got ", o.max_order));
}

/// One statistic of the integrator: `get` (CVodeGetNumSteps, CVodeGetLastStep...) writes it into
/// a T; its flag is checked (IntegrationError naming `call`).
template <class T, class Getter>
T statistic(State& s, Getter get, const char* call) {
  T v = 0;
  s.check(get(s.mem.get(), &v), call);
  return v;
}

}  // namespace detail

inline Integrator::Integrator(Rhs f, const Eigen::VectorXd& y0, double t0, const Options& opt, int n_roots,
                              Roots g, std::vector<int> root_directions)
    : s_(std::make_unique<detail::State>()) {
  using ffsr::detail::str;
  constexpr const char* w = "cvode::Integrator";
  if (!f) throw InputError(str(w, ": the right-hand side f is empty"));
  if (y0.size() == 0) throw InputError(str(w, ": y0 is empty"));
  ffsr::detail::require_finite_all(y0, w, "y0");
  ffsr::detail::require_finite(t0, w, "t0");
  detail::validate(opt, y0.size());
  if (n_roots < 0) throw InputError(str(w, ": n_roots must be >= 0, got ", n_roots));
  if (n_roots > 0 && !g) throw InputError(str(w, ": n_roots = ", n_roots, " but g is empty"));
  if (!root_directions.empty()) {
    ffsr::detail::require_size(static_cast<long>(root_directions.size()), n_roots, w, "root_directions");
    for (int d : root_directions)
      if (d < -1 || d > 1) throw InputError(str(w, ": root directions must be -1, 0 or 1, got ", d));
  }

  detail::State& s = *s_;
  s.f = std::move(f);
  s.g = std::move(g);
  s.n = y0.size();
  s.n_roots = n_roots;
  s.t = t0;

  SUNContext ctx = nullptr;
  if (SUNContext_Create(nullptr, &ctx) != 0 || !ctx)
    throw IntegrationError("cvode: SUNContext_Create failed");
  s.ctx.reset(ctx);
  s.y_nv.reset(s.make_vector("y"));
  s.scratch_nv.reset(s.make_vector("dense output"));
  s.load(y0);

  s.mem.reset(CVodeCreate(CV_BDF, s.ctx.get()));
  if (!s.mem) throw IntegrationError("cvode: CVodeCreate failed");
  void* mem = s.mem.get();
  s.check(CVodeSetErrHandlerFn(mem, &detail::State::error_handler, &s), "CVodeSetErrHandlerFn");
  s.check(CVodeInit(mem, &detail::State::rhs, t0, s.y_nv.get()), "CVodeInit");
  s.check(CVodeSetUserData(mem, &s), "CVodeSetUserData");
  if (opt.atol_vector.size() == 0) {
    s.check(CVodeSStolerances(mem, opt.rtol, opt.atol), "CVodeSStolerances");
  } else {
    s.atol_nv.reset(s.make_vector("atol"));
    std::copy(opt.atol_vector.data(), opt.atol_vector.data() + s.n, N_VGetArrayPointer(s.atol_nv.get()));
    s.check(CVodeSVtolerances(mem, opt.rtol, s.atol_nv.get()), "CVodeSVtolerances");
  }
  s.A.reset(SUNDenseMatrix(static_cast<sunindextype>(s.n), static_cast<sunindextype>(s.n), s.ctx.get()));
  if (!s.A) throw IntegrationError("cvode: SUNDenseMatrix failed");
  s.LS.reset(SUNLinSol_Dense(s.y_nv.get(), s.A.get(), s.ctx.get()));
  if (!s.LS) throw IntegrationError("cvode: SUNLinSol_Dense failed");
  s.check(CVodeSetLinearSolver(mem, s.LS.get(), s.A.get()), "CVodeSetLinearSolver", true);
  s.check(CVodeSetMaxNumSteps(mem, opt.max_num_steps), "CVodeSetMaxNumSteps");
  s.check(CVodeSetMaxOrd(mem, opt.max_order), "CVodeSetMaxOrd");
  if (opt.max_step > 0.0) s.check(CVodeSetMaxStep(mem, opt.max_step), "CVodeSetMaxStep");
  if (opt.initial_step > 0.0) s.check(CVodeSetInitStep(mem, opt.initial_step), "CVodeSetInitStep");
  if (n_roots > 0) {
    s.check(CVodeRootInit(mem, n_roots, &detail::State::roots), "CVodeRootInit");
    if (!root_directions.empty())
      s.check(CVodeSetRootDirection(mem, root_directions.data()), "CVodeSetRootDirection");
    // A root function that is zero at t0 (e.g. a gap that opens from zero) is expected here.
    s.check(CVodeSetNoInactiveRootWarn(mem), "CVodeSetNoInactiveRootWarn");
  }
}

inline void Integrator::check_target(double t_target, const char* where) const {
  ffsr::detail::require_finite(t_target, where, "target time");
  if (t_target < s_->t)
    throw InputError(ffsr::detail::str(where, ": target time ", t_target, " is behind the current time ",
                                       s_->t, " (integration is forward only)"));
}

inline Integrator::Status Integrator::finish(int flag, double tret, bool one_step) {
  s_->t = tret;
  s_->store();
  s_->check(flag, "CVode");
  if (flag == CV_ROOT_RETURN) return Status::Root;
  if (flag == CV_TSTOP_RETURN) return Status::Reached;
  return one_step ? Status::Step : Status::Reached;
}

/// Integrates towards t_stop (never past it): one internal step (CV_ONE_STEP) or up to t_stop or
/// the next root (CV_NORMAL). Reads and writes the CVODE memory and s_->t, s_->y (finish).
inline Integrator::Status Integrator::run(double t_stop, bool one_step, const char* where) {
  check_target(t_stop, where);
  if (t_stop == s_->t) return Status::Reached;
  s_->check(CVodeSetStopTime(s_->mem.get(), t_stop), "CVodeSetStopTime");
  sunrealtype tret = s_->t;
  const int flag = CVode(s_->mem.get(), t_stop, s_->y_nv.get(), &tret, one_step ? CV_ONE_STEP : CV_NORMAL);
  return finish(flag, tret, one_step);
}

inline Integrator::Status Integrator::step(double t_stop) {
  return run(t_stop, true, "cvode::Integrator::step");
}

inline Integrator::Status Integrator::advance(double tout) {
  return run(tout, false, "cvode::Integrator::advance");
}

inline void Integrator::reinit(double t0, const Eigen::VectorXd& y0) {
  constexpr const char* w = "cvode::Integrator::reinit";
  ffsr::detail::require_size(y0.size(), s_->n, w, "y0");
  ffsr::detail::require_finite_all(y0, w, "y0");
  ffsr::detail::require_finite(t0, w, "t0");
  s_->load(y0);
  s_->t = t0;
  s_->check(CVodeReInit(s_->mem.get(), t0, s_->y_nv.get()), "CVodeReInit");
}

inline double Integrator::t() const { return s_->t; }
inline const Eigen::VectorXd& Integrator::y() const { return s_->y; }
inline Eigen::Index Integrator::size() const { return s_->n; }
inline const std::string& Integrator::last_message() const { return s_->message; }

inline Eigen::VectorXd Integrator::interpolate(double t) const {
  ffsr::detail::require_finite(t, "cvode::Integrator::interpolate", "t");
  s_->check(CVodeGetDky(s_->mem.get(), t, 0, s_->scratch_nv.get()), "CVodeGetDky");
  const double* p = N_VGetArrayPointer(s_->scratch_nv.get());
  return Eigen::Map<const Eigen::VectorXd>(p, s_->n);
}

inline std::vector<int> Integrator::roots_found() const {
  std::vector<int> info(static_cast<std::size_t>(s_->n_roots), 0);
  if (s_->n_roots > 0) s_->check(CVodeGetRootInfo(s_->mem.get(), info.data()), "CVodeGetRootInfo");
  return info;
}

inline long Integrator::num_steps() const {
  return detail::statistic<long>(*s_, CVodeGetNumSteps, "CVodeGetNumSteps");
}
inline long Integrator::num_rhs_evals() const {
  return detail::statistic<long>(*s_, CVodeGetNumRhsEvals, "CVodeGetNumRhsEvals");
}
inline long Integrator::num_root_evals() const {
  return detail::statistic<long>(*s_, CVodeGetNumGEvals, "CVodeGetNumGEvals");
}
inline double Integrator::current_time() const {
  return detail::statistic<sunrealtype>(*s_, CVodeGetCurrentTime, "CVodeGetCurrentTime");
}
inline double Integrator::last_step() const {
  return detail::statistic<sunrealtype>(*s_, CVodeGetLastStep, "CVodeGetLastStep");
}

}  // namespace ffsr::cvode
