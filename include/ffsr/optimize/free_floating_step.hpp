// ffsr/optimize/free_floating_step.hpp -- one classical RK4 step of the free-floating robot's
// kinematic state x = (p_0, q_0, theta) (base position, unit quaternion, joint angles).
#pragma once

#include "ffsr/model/model.hpp"

#include <cmath>

// The rates come from a rate field f(t, base, theta, theta_dot, xb) that writes the joint rates
// theta_dot and the base velocity xb = [v_0; omega_0] (inertial frame, v_0 of the base frame origin;
// the capture planner takes xb from zero total momentum, xb = -H_b^-1 H_bm theta_dot, Eq. 2 and 29).
// The quaternion rate is q_dot = 1/2 [0, omega_0] (x) q. After the step the quaternion is
// renormalized; its norm error before that is returned so that a monitor can watch it.

namespace ffsr {

namespace detail {
/// q_dot = 1/2 [0, w] (x) q as coefficients (x, y, z, w), w the inertial angular velocity.
inline Eigen::Vector4d quaternion_rate(const Quaternion& q, const Vector3& w) {
  const Quaternion wq(0, w.x(), w.y(), w.z());
  return Eigen::Vector4d(0.5 * (wq * q).coeffs());
}
}  // namespace detail

/// The RK4 step with its workspace (sized at construction for n joints; step() does not allocate
/// beyond what the rate field does). Use either step(), or begin() then finish() to look at the
/// first stage (the rates at the current state, in k_theta[0] and k_base[0]) in between.
class FreeFloatingRK4 {
 public:
  explicit FreeFloatingRK4(int n) : th2_(n) {
    for (Eigen::VectorXd& k : k_theta) k.resize(n);
  }

  /// First stage: f at (t, base, theta). Writes k_theta[0], k_base[0] (and the quaternion rate).
  template <class RateField>
  void begin(RateField& f, double t, const BasePose& base, const Eigen::VectorXd& theta) {
    f(t, base, theta, k_theta[0], k_base[0]);
    k_q_[0] = detail::quaternion_rate(base.orientation, k_base[0].tail<3>());
  }

  /// Stages 2-4 and the update of (base, theta) by h; begin() at the same state first. The
  /// quaternion is renormalized; returns | |q| - 1 | before that. Reads and writes base, theta.
  template <class RateField>
  double finish(RateField& f, double t, double h, BasePose& base, Eigen::VectorXd& theta) {
    stage(base, theta, 0, 0.5 * h);
    f(t + 0.5 * h, b2_, th2_, k_theta[1], k_base[1]);
    k_q_[1] = detail::quaternion_rate(b2_.orientation, k_base[1].tail<3>());
    stage(base, theta, 1, 0.5 * h);
    f(t + 0.5 * h, b2_, th2_, k_theta[2], k_base[2]);
    k_q_[2] = detail::quaternion_rate(b2_.orientation, k_base[2].tail<3>());
    stage(base, theta, 2, h);
    f(t + h, b2_, th2_, k_theta[3], k_base[3]);
    k_q_[3] = detail::quaternion_rate(b2_.orientation, k_base[3].tail<3>());
    base.position += h / 6 * (k_base[0] + 2 * k_base[1] + 2 * k_base[2] + k_base[3]).head<3>();
    base.orientation.coeffs() += h / 6 * (k_q_[0] + 2 * k_q_[1] + 2 * k_q_[2] + k_q_[3]);
    theta += h / 6 * (k_theta[0] + 2 * k_theta[1] + 2 * k_theta[2] + k_theta[3]);
    const double quaternion_error = std::abs(base.orientation.norm() - 1.0);
    base.orientation.normalize();
    return quaternion_error;
  }

  /// begin() and finish(): one step of length h from t.
  template <class RateField>
  double step(RateField& f, double t, double h, BasePose& base, Eigen::VectorXd& theta) {
    begin(f, t, base, theta);
    return finish(f, t, h, base, theta);
  }

  Eigen::VectorXd k_theta[4];  ///< joint rates of the four stages
  Vector6 k_base[4];           ///< base velocities of the four stages

 private:
  /// The intermediate state x + a k_i (the quaternion not normalized, as in plain RK4).
  void stage(const BasePose& b, const Eigen::VectorXd& th, int i, double a) {
    b2_.position = b.position + a * k_base[i].head<3>();
    b2_.orientation.coeffs() = b.orientation.coeffs() + a * k_q_[i];
    th2_ = th + a * k_theta[i];
  }
  Eigen::Vector4d k_q_[4];
  BasePose b2_;
  Eigen::VectorXd th2_;
};

}  // namespace ffsr
