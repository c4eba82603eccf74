// ffsr/optimize/run_monitors.hpp -- the checks a free-floating capture run makes at every step.
#pragma once

#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/optimize/capture_problem.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

// Independent checks of the integration and of the approach: the total momentum of the commanded
// motion (zero by construction of the base velocity, Eq. 2 with h = 0), the body momenta for scale,
// the system centre of mass (it must not move when the momentum is zero: an independent check of the
// integrated state), the tracking error of the end-effector against the line reference (a run
// falling more than `divergence` behind it cannot reach the capture point), the quaternion norm
// before renormalization, finiteness of the state and the joint limits. The maxima are kept here and
// copied into the result by record(). The checks throw NumericalError (JointLimitError for a joint
// outside its limits) with messages that start with `where`.

namespace ffsr {

struct RunMonitors {
  const char* where = "plan_capture";
  /// The likely causes named when the line is lost (check_tracking).
  const char* hint = "the point may be out of reach";
  double divergence = 1e-2;  ///< m: the tracking error beyond which the line is lost
  double max_momentum = 0, max_body_momentum = 0, max_com_drift = 0, max_tracking_error = 0;
  double max_quaternion_error = 0;
  Vector3 com0 = Vector3::Zero();  ///< centre of mass at the first check_motion()
  bool have_com0 = false;
  Eigen::VectorXd vgen;  ///< [xb; theta_dot] (workspace, size 6 + n)

  RunMonitors(const Model& model, const char* where_, double divergence_)
      : where(where_), divergence(divergence_), vgen(model.nv()) {}

  /// Momentum and centre of mass of the motion (xb, theta_dot) at the state whose kinematics and
  /// composite inertias data holds (crba). Reads data.p, data.R, data.S, data.Ic. Writes vgen and
  /// the maxima; the first call fixes com0.
  void check_motion(const Model& model, const Data& data, const Vector6& xb,
                    const Eigen::VectorXd& theta_dot) {
    vgen << xb, theta_dot;
    max_momentum = std::max(max_momentum, momentum(model, data, vgen).norm());
    for_each_body_velocity(
        model, data, vgen, [&](int i, const Vector3& w, const Vector3& vc, const Vector3&) {
          const Inertia& in = model.body(i).inertia;
          max_body_momentum = std::max(max_body_momentum, in.mass * vc.norm() + (in.I * w).norm());
        });
    const Vector3 com = data.p[0] + data.Ic[0].h / data.Ic[0].m;
    if (!have_com0) {
      com0 = com;
      have_com0 = true;
    }
    max_com_drift = std::max(max_com_drift, (com - com0).norm());
  }

  /// The tracking error |e| on the constrained position rows (rows < 3 of `rows`), e = x_d(t) - p_e.
  /// Throws NumericalError when it exceeds `divergence`. Returns it.
  double check_tracking(const Vector3& e, const std::vector<int>& rows, double t) {
    double err2 = 0;
    for (int r : rows)
      if (r < 3) err2 += e(r) * e(r);
    const double err = std::sqrt(err2);
    max_tracking_error = std::max(max_tracking_error, err);
    if (err > divergence)
      FFSR_THROW(NumericalError(detail::str(where,
                                       ": the end-effector cannot follow the line to the capture point "
                                       "(tracking error ",
                                       err, " m at t = ", t, " s); ", hint)));
    return err;
  }

  /// | |q| - 1 | before renormalization (free_floating_step.hpp returns it).
  void check_quaternion(double norm_error) {
    max_quaternion_error = std::max(max_quaternion_error, norm_error);
  }

  /// The state after a step, at time t: finite, and every joint within its limits (1e-9 rad slack).
  void check_state(const Model& model, const BasePose& base, const Eigen::VectorXd& theta, double t) const {
    using detail::str;
    if (!theta.allFinite() || !base.position.allFinite())
      FFSR_THROW(NumericalError(str(where, ": the state became non-finite at t = ", t, " s")));
    for (int j = 0; j < model.n(); ++j) {
      const Joint& jt = model.joint(j);
      if (theta(j) < jt.lower - 1e-9 || theta(j) > jt.upper + 1e-9)
        FFSR_THROW(JointLimitError(str(where, ": joint '", jt.name, "' left its limits [", jt.lower, ", ",
                                  jt.upper, "] rad at t = ", t, " s (", theta(j), " rad)")));
    }
  }

  /// Copies the maxima into the result's fields of the same names.
  void record(CaptureResult& res) const {
    res.max_momentum = max_momentum;
    res.max_body_momentum = max_body_momentum;
    res.max_com_drift = max_com_drift;
    res.max_tracking_error = max_tracking_error;
    res.max_quaternion_error = max_quaternion_error;
  }
};

}  // namespace ffsr
