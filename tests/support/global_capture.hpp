// tests/support/global_capture.hpp -- the global capture runs of the paper's scenario files, shared
// by the unit tests of the global search and the paper's regressions: one global plan per robot,
// made once per process, and the checks every global run must pass.
#pragma once

#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/global.hpp"

#include <cstdio>

namespace ffsr::test::global_capture {

inline constexpr double kRate = 3.0 * M_PI / 180.0;  // max-joint-rate-deg = 3 of the paper scenario files

inline CaptureOptions options(double T) {
  CaptureOptions o;
  o.duration = T;
  o.step = 0.1;
  o.tolerance = 1e-3;
  o.max_joint_rate = kRate;
  return o;
}

inline CaptureTask position_task(bool planar) {
  CaptureTask t;
  if (planar) t.axes = {true, true, false};
  return t;
}

struct Shared {
  Model model;
  CaptureProblem pb;
  CaptureTask task;
  CaptureOptions opt;
  CaptureResult paper;  ///< the paper's method (rho of the scenario file)
  GlobalCaptureResult global;
};

/// The two runs of a scenario: the paper's method (gain -0.01 as in the scenario files, no rate
/// limit), then the global search, which also starts from the paper's capture configuration.
inline void plan_both(Shared& r) {
  CaptureOptions paper = r.opt;
  paper.gain = -0.01;
  paper.max_joint_rate = 0;
  r.paper = plan_capture(r.pb, r.task, paper);
  GlobalCaptureOptions g;
  g.extra_starts = {r.paper.theta};
  r.global = plan_capture_global(r.pb, r.task, r.opt, g);
}

/// The runs of one paper scenario (the robot of robots/`urdf`, the problem, a planar or spatial
/// position task over T seconds), made once per process.
template <CaptureProblem (*Problem)(const Model&)>
const Shared& shared_runs(const char* urdf, bool planar, double T) {
  // built in place: pb.model points to s.model (a Shared built in a local and returned would leave it
  // pointing into a dead stack frame unless the compiler elides the copy)
  static Shared s{model_from_urdf_file(kRobots + urdf), {}, position_task(planar), options(T), {}, {}};
  static const bool planned = (s.pb = Problem(s.model), plan_both(s), true);
  (void)planned;
  return s;
}

inline const Shared& shared_3dof() { return shared_runs<problem_3dof>("paper_3dof.urdf", true, 180); }
inline const Shared& shared_7dof_position() {
  return shared_runs<problem_7dof>("paper_7dof.urdf", false, 157);
}

/// The checks every global run must pass, against the run's own records and the paper's method.
inline void check_run(const Shared& s, double bound_M_ie) {
  const GlobalCaptureResult& g = s.global;
  INFO("global M_ie " << g.run.M_ie << " paper's method " << s.paper.M_ie << " optimum " << g.manifold_optimum
                      << " gap " << g.optimality_gap_percent << " % iterations "
                      << g.counters.shooting_iterations);
  CHECK(g.run.M_ie <= bound_M_ie);
  CHECK(g.run.M_ie <= s.paper.M_ie);  // never worse than the paper's method
  CHECK(g.reached_manifold_optimum);
  CHECK(g.optimality_gap_percent <= 1.0);
  CHECK(g.optimality_gap_percent >=
        -1e-6);  // the optimum is the best the search knows, the reached point among the starts
  CHECK(g.counters.shooting_iterations >= 1);
  CHECK(g.counters.shooting_iterations <= 8 * g.counters.goals_tried);
  CHECK(g.run.tracking_error <= s.opt.tolerance);
  CHECK(g.run.max_joint_rate <= kRate * (1 + 1e-9));  // the limit of the scenario
  // zero total momentum along the run (relative to the bodies' own momenta) and a still centre of mass
  CHECK(g.run.max_momentum <= 1e-9 * g.run.max_body_momentum);
  CHECK(g.run.max_com_drift <= 1e-6);
  // the objective reported is M_ie at the reached configuration and base pose (independent recomputation)
  Data d(s.model);
  const Target cap = propagate_target(s.pb.target, s.opt.duration);
  CHECK(
      g.objective ==
      Approx(integrated_effective_mass(s.model, d, g.run.base, g.run.theta, s.pb.frame, cap)).epsilon(1e-9));
  std::printf(
      "\nglobal %d-DOF: M_ie %.3f kg (paper's method %.3f), F_max %.3f kN (%.3f), rate %.3f deg/s (%.3f), "
      "gap %.3f %%, %d iterations, %ld SLSQP evaluations, search %.3f s\n",
      s.model.n(), g.run.M_ie, s.paper.M_ie, g.run.f_max_closed_form / 1e3, s.paper.f_max_closed_form / 1e3,
      g.run.max_joint_rate * 180 / M_PI, s.paper.max_joint_rate * 180 / M_PI, g.optimality_gap_percent,
      g.counters.shooting_iterations, g.counters.evaluations, g.counters.search_seconds);
}

/// capture_residual's Jacobian against central differences (h = 1e-6) at `q`, column by column:
/// O(h^2) + roundoff/h is about 1e-9, checked to 1e-7.
inline void check_residual_jacobian(const Model& m, const CaptureProblem& pb, const CaptureTask& task,
                                    const CaptureSetup& s, const BasePose& b, const Eigen::VectorXd& q) {
  Data d(m);
  Eigen::VectorXd r, rp, rm;
  Eigen::MatrixXd J;
  capture_residual(m, d, pb, task, s, b, q, r, &J);
  for (int k = 0; k < m.n(); ++k) {
    const double h = 1e-6;
    Eigen::VectorXd qp = q, qm = q;
    qp(k) += h;
    qm(k) -= h;
    capture_residual(m, d, pb, task, s, b, qp, rp, nullptr);
    capture_residual(m, d, pb, task, s, b, qm, rm, nullptr);
    const Eigen::VectorXd fd = (rp - rm) / (2 * h);
    INFO("joint " << k << " analytic " << J.col(k).transpose() << " fd " << fd.transpose());
    CHECK((J.col(k) - fd).norm() < 1e-7);
  }
}

}  // namespace ffsr::test::global_capture
