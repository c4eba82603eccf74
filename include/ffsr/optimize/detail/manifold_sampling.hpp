// ffsr/optimize/detail/manifold_sampling.hpp -- the pieces of the capture-manifold search that do
// not depend on the residual (included by optimize/global.hpp; see docs/branches.md):
#pragma once

#include "ffsr/model/model.hpp"
#include "ffsr/spatial/spatial.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

// - the Jacobian of the orientation residual log(R_end R_e^T) (the rotation vector, angle in
//   [0, pi]): its zero set is the wanted orientation alone;
// - Halton points over the joint box (the low-discrepancy starts of the branch stage);
// - postures: two configurations that differ by whole turns of revolute joints put every link in
//   the same place (same M_ie); a posture is represented by the configuration within the limits
//   nearest to a reference (the initial configuration).
//
// Eigen only; every function reads its arguments and writes only its outputs.

namespace ffsr::detail {

/// d log(R) / d omega for R = R_end R_e^T when the end-effector turns with the inertial angular
/// velocity omega (dR_e = [omega]x R_e dt, so dR = -R [omega]x dt): -J_r^-1(phi), phi = log(R),
/// J_r^-1(phi) = E + 1/2 [phi]x + (1/a^2 - (1 + cos a) / (2 a sin a)) [phi]x^2, a = |phi| (the
/// inverse right Jacobian of SO(3)). The coefficient is 1/12 + a^2/720 near 0 and 1/pi^2 at pi.
inline Matrix3 rotation_log_rate(const Vector3& phi) {
  const double a = phi.norm();
  double c;
  if (a < 1e-4)
    c = 1.0 / 12.0 + a * a / 720.0;
  else
    c = 1.0 / (a * a) - std::cos(0.5 * a) / (2.0 * a * std::sin(0.5 * a));  // (1+cos a)/sin a = cot(a/2)
  const Matrix3 P = skew(phi);
  return -(Matrix3::Identity() + 0.5 * P + c * P * P);
}

/// The radical inverse of i in base b (the i-th Halton coordinate), in [0, 1).
inline double radical_inverse(std::uint64_t i, std::uint64_t b) {
  double f = 1.0, r = 0.0;
  const double inv = 1.0 / static_cast<double>(b);
  while (i > 0) {
    f *= inv;
    r += f * static_cast<double>(i % b);
    i /= b;
  }
  return r;
}

/// The first n primes (the Halton bases).
inline std::vector<std::uint64_t> first_primes(int n) {
  std::vector<std::uint64_t> p;
  for (std::uint64_t c = 2; static_cast<int>(p.size()) < n; ++c) {
    bool prime = true;
    for (std::uint64_t q : p)
      if (c % q == 0) {
        prime = false;
        break;
      }
    if (prime) p.push_back(c);
  }
  return p;
}

/// `count` Halton points (indices 1..count, bases the first n primes) mapped to the joint box
/// ([-pi, pi] for a joint without limits). Deterministic, the same on every platform.
inline std::vector<Eigen::VectorXd> halton_starts(const Model& model, int count) {
  const int n = model.n();
  const std::vector<std::uint64_t> bases = first_primes(n);
  std::vector<Eigen::VectorXd> out;
  out.reserve(static_cast<size_t>(std::max(count, 0)));
  for (int i = 1; i <= count; ++i) {
    Eigen::VectorXd q(n);
    for (int k = 0; k < n; ++k) {
      const Joint& j = model.joint(k);
      const double lo = std::isfinite(j.lower) ? j.lower : -M_PI,
                   hi = std::isfinite(j.upper) ? j.upper : M_PI;
      q(k) = lo + (hi - lo) * radical_inverse(static_cast<std::uint64_t>(i), bases[static_cast<size_t>(k)]);
    }
    out.push_back(std::move(q));
  }
  return out;
}

/// a - b with every revolute joint's difference taken modulo 2 pi into [-pi, pi]: zero for two
/// configurations of the same posture.
inline void posture_error(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                          Eigen::VectorXd& e) {
  e = a - b;
  for (int k = 0; k < model.n(); ++k)
    if (model.joint(k).type == JointType::Revolute) e(k) = std::remainder(e(k), 2 * M_PI);
}

/// Largest |posture_error| over the joints (rad).
inline double posture_distance(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  Eigen::VectorXd e;
  posture_error(model, a, b, e);
  return e.size() ? e.cwiseAbs().maxCoeff() : 0.0;
}

/// Moves every revolute joint of theta by whole turns to the value nearest to ref(k) within its
/// limits (a function of the posture and ref alone: the search's optima are reported, and compared
/// between runs, as the angles the joints turn to from ref, never as 446 deg for 86 deg). A joint
/// without limits takes the value within half a turn of ref(k); prismatic joints are left as
/// they are. Returns false when some joint has no value within its limits (the posture is outside
/// the joint box).
inline bool nearest_representative(const Model& model, const Eigen::VectorXd& ref, Eigen::VectorXd& theta) {
  constexpr double tol = 1e-12;
  for (int k = 0; k < model.n(); ++k) {
    const Joint& j = model.joint(k);
    if (j.type != JointType::Revolute) continue;
    const double near = ref(k) + std::remainder(theta(k) - ref(k), 2 * M_PI);  // nearest to ref
    double best = near;
    bool found = false;
    for (int w = -3; w <= 3; ++w) {  // the candidates near + 2 pi w within the limits, nearest to ref
      const double c = near + 2 * M_PI * w;
      if (c < j.lower - tol || c > j.upper + tol) continue;
      if (!found || std::abs(c - ref(k)) < std::abs(best - ref(k))) best = c;
      found = true;
    }
    if (!found) return false;
    theta(k) = std::clamp(best, j.lower, j.upper);
  }
  return true;
}

}  // namespace ffsr::detail
