// STAND-IN workload (standin.h): exercises what the onboard core will, so that the targets can be proven
// before the core drops in: Eigen dynamic matrices and a std::vector allocated at initialisation, an
// LDLT factorisation and solve, matrix-vector products and libm (sin, cos, sqrt, atan2) in a noexcept,
// allocation-free step. The numbers mean nothing: a damped 7-degree-of-freedom system
// M(q) qdd = -K sin(q) - D qd driven by a slow input, integrated with semi-implicit Euler.
#include "standin.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cmath>
#include <new>
#include <vector>

namespace {

constexpr int kDof = 7;
constexpr double kDt = 1e-3;

}  // namespace

struct ffsr_standin {
  // Sized once in init: Eigen allocates dynamic storage on construction or resize only, and every step
  // writes into these with noalias() or in place, so the step never allocates.
  Eigen::MatrixXd base_mass;   // constant SPD part of the mass matrix
  Eigen::MatrixXd mass;        // this tick's mass matrix
  Eigen::LDLT<Eigen::MatrixXd> factor;
  Eigen::VectorXd q, qd, force, qdd, momentum;
  std::vector<double> energy_history;  // ring buffer
  long tick = 0;

  ffsr_standin()
      : base_mass(kDof, kDof), mass(kDof, kDof), factor(kDof), q(kDof), qd(kDof), force(kDof), qdd(kDof),
        momentum(kDof), energy_history(64, 0.0) {}
};

extern "C" ffsr_standin* ffsr_standin_init(void) {
  ffsr_standin* const s = new (std::nothrow) ffsr_standin();
  if (s == nullptr) return nullptr;
  Eigen::MatrixXd a(kDof, kDof);
  for (int i = 0; i < kDof; ++i)
    for (int j = 0; j < kDof; ++j) a(i, j) = std::sin(1.0 + i + 2.0 * j) / (1.0 + i + j);
  s->base_mass.noalias() = a * a.transpose();
  s->base_mass.diagonal().array() += 2.0;
  for (int i = 0; i < kDof; ++i) {
    s->q(i) = 0.3 * (i + 1) - 1.0;
    s->qd(i) = 0.1 * std::cos(2.0 * i);
  }
  return s;
}

extern "C" int ffsr_standin_step(ffsr_standin* s, ffsr_standin_output* out) noexcept {
  const double t = kDt * static_cast<double>(++s->tick);
  // Configuration-dependent mass matrix, kept symmetric positive definite.
  s->mass = s->base_mass;
  for (int i = 0; i < kDof; ++i) {
    const double c = std::cos(s->q(i));
    s->mass(i, i) += 0.5 * c * c;
    if (i + 1 < kDof) {
      const double coupling = 0.1 * std::sin(s->q(i) - s->q(i + 1));
      s->mass(i, i + 1) += coupling;
      s->mass(i + 1, i) += coupling;
    }
  }
  for (int i = 0; i < kDof; ++i)
    s->force(i) = -4.0 * std::sin(s->q(i)) - 0.2 * s->qd(i) + 0.5 * std::sin(0.7 * t + i);
  s->factor.compute(s->mass);
  s->qdd = s->factor.solve(s->force);
  s->qd += kDt * s->qdd;
  s->q += kDt * s->qd;
  for (int i = 0; i < kDof; ++i) s->q(i) = std::atan2(std::sin(s->q(i)), std::cos(s->q(i)));  // wrap
  s->momentum.noalias() = s->mass * s->qd;
  const double energy = 0.5 * s->qd.dot(s->momentum);
  s->energy_history[static_cast<std::size_t>(s->tick) % s->energy_history.size()] = energy;
  double mean_energy = 0.0;
  for (const double e : s->energy_history) mean_energy += e;
  mean_energy /= static_cast<double>(s->energy_history.size());

  for (int i = 0; i < kDof; ++i) {
    out->values[i] = s->q(i);
    out->values[kDof + i] = s->qd(i);
  }
  out->values[14] = energy;
  out->values[15] = std::sqrt(mean_energy) + std::atan2(s->momentum(0), s->momentum(1));
  return s->factor.info() == Eigen::Success ? 0 : 1;
}

extern "C" void ffsr_standin_free(ffsr_standin* s) { delete s; }
