// ffsr/simulate/single_body.hpp -- CVODE integration of the single-body contact model, Eq. 16:
//     M_ie δ̈ = -F(δ, δ̇),   F the contact law of Eq. 15 (HertzDamped::force, with its clamp),
// from first touch (δ = 0, δ̇ = δ̇⁻) to separation (δ back to 0), located by CVODE root finding
// (Zhang et al. 2022, Section 3). It is the time-stepping reference for the closed forms
// (Eq. 20, 23-25) and for the exact maximum of contact_law.hpp.
#pragma once

#include "ffsr/contact/contact_law.hpp"
#include "ffsr/errors.hpp"
#include "ffsr/simulate/cvode.hpp"

#include <Eigen/Core>

#include <cmath>
#include <variant>
#include <vector>

// Scaling: the contact lasts milliseconds and δ is micrometres, so the integration runs in the
// natural units of the problem: length δ_ref = δ_max (Eq. 20), velocity δ̇⁻, time T = δ_ref/δ̇⁻.
// The scaled state y = (δ/δ_ref, δ̇/δ̇⁻) is O(1) along the whole contact, so plain relative and
// absolute tolerances apply; results are returned in SI units.
//
// Events (CVODE root functions, all with direction -1, i.e. crossed while decreasing):
//   dF/dt  -- the force peak. For δ > 0, dF/dt = δ^(α-1) (α δ̇ (K + λ δ̇) + λ δ δ̈); the bracket
//             is the root function, so the peak is located to CVODE's root tolerance and F there
//             is F(δ, δ̇) of the integrated state (first order insensitive to the time error);
//   δ̇      -- the maximum deformation;
//   δ      -- separation.

namespace ffsr {

/// Settings of simulate_single_body.
struct SingleBodyOptions {
  /// CVODE settings for the scaled state (δ/δ_max, δ̇/δ̇⁻) in the time unit δ_max/δ̇⁻ (file comment).
  cvode::Options cvode{};
  /// Record the time series (every internal step plus the events).
  bool record_series = false;
  /// Give up (NumericalError) if the bodies have not separated after this many time units
  /// δ_max/δ̇⁻ (an elastic Hertz contact lasts about 3 of them).
  double max_scaled_duration = 1e4;
};

/// The time series of a single-body contact, SI units.
struct SingleBodySeries {
  std::vector<double> t;          ///< time since first touch [s]
  std::vector<double> force;      ///< F [N]
  std::vector<double> delta;      ///< δ [m]
  std::vector<double> delta_dot;  ///< δ̇ [m/s]
};

/// Result of simulate_single_body, SI units.
struct SingleBodyResult {
  double f_max = 0;                ///< maximum contact force [N]
  double t_at_f_max = 0;           ///< time of the force peak [s]
  double delta_at_f_max = 0;       ///< δ'_max, deformation at the force peak [m]
  double delta_dot_at_f_max = 0;   ///< δ̇ at the force peak [m/s]
  double delta_max = 0;            ///< maximum deformation (where δ̇ = 0) [m]
  double t_at_delta_max = 0;       ///< its time [s]
  double contact_duration = 0;     ///< time from first touch to separation [s]
  double separation_velocity = 0;  ///< δ̇ at separation [m/s] (negative)
  double restitution = 0;          ///< realized coefficient of restitution, -δ̇_sep/δ̇⁻
  long num_steps = 0;              ///< CVODE steps taken
  SingleBodySeries series;         ///< filled when SingleBodyOptions::record_series
};

/// Integrates Eq. 16 with `law` and M_ie > 0 from first touch to separation (see the file
/// comment). InputError for M_ie <= 0 or bad options; IntegrationError from CVODE; NumericalError
/// if no separation within max_scaled_duration.
template <class Damping>
SingleBodyResult simulate_single_body(const HertzDamped<Damping>& law, double M_ie,
                                      const SingleBodyOptions& opt = {});

/// The same for a law chosen at run time.
inline SingleBodyResult simulate_single_body(const AnyContactLaw& law, double M_ie,
                                             const SingleBodyOptions& opt = {}) {
  return std::visit([&](const auto& l) { return simulate_single_body(l, M_ie, opt); }, law);
}

// ============================================================================================
// Implementation
// ============================================================================================

namespace detail {

/// The natural units of a single-body contact (file comment) and the law in them: length
/// delta_ref = δ_max (Eq. 20), velocity v0 = δ̇⁻, time T = delta_ref / v0; the scaled acceleration
/// is -F * accel_scale.
template <class Damping>
struct SingleBodyScaling {
  const HertzDamped<Damping>* law;
  double delta_ref, v0, T, accel_scale, f, alpha;
  /// F [N] at the scaled state (x, v) = (δ/delta_ref, δ̇/v0).
  double force(double x, double v) const { return law->force(delta_ref * x, v0 * v); }
};

/// The scaling of `law` with M_ie (validates M_ie through HertzDamped::max_deformation).
template <class Damping>
SingleBodyScaling<Damping> single_body_scaling(const HertzDamped<Damping>& law, double M_ie) {
  const double delta_ref = law.max_deformation(M_ie);  // validates M_ie
  const double v0 = law.approach_velocity();
  return {&law, delta_ref, v0, delta_ref / v0, delta_ref / (M_ie * v0 * v0), law.f(), law.params().alpha};
}

/// The right-hand side of Eq. 16 in the scaled state y = (x, v): ẋ = v, v̇ = -F(x, v) accel_scale.
template <class Damping>
cvode::Rhs single_body_rhs(const SingleBodyScaling<Damping>& s) {
  return [s](double, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> ydot) {
    ydot[0] = y[1];
    ydot[1] = -s.force(y[0], y[1]) * s.accel_scale;
  };
}

/// The event functions (file comment): g0 = (dF/dt) / (δ^(α-1) K δ̇⁻) = α v (1 + f v) + f x a,
/// armed in compression only; g1 = v; g2 = x.
template <class Damping>
cvode::Roots single_body_roots(const SingleBodyScaling<Damping>& s) {
  return [s](double, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> g) {
    const double x = y[0], v = y[1];
    const double a = -s.force(x, v) * s.accel_scale;
    // Armed only in compression (v > 0), where the peak lies (at v = 0, dF/dt = λ δ^α δ̈ < 0): in
    // restitution a strongly damped contact hovers at the clamp 1 + f v = 0, where this expression
    // vanishes on an interval and CVODE's root finder would stop (CV_ILL_INPUT).
    g[0] = v > 0.0 ? s.alpha * v * (1.0 + s.f * v) + s.f * x * a : -1.0;
    g[1] = v;
    g[2] = x;
  };
}

/// Appends the integrator's current state to `series`, in SI units.
template <class Damping>
void record_single_body_sample(const SingleBodyScaling<Damping>& s, const cvode::Integrator& integ,
                               SingleBodySeries& series) {
  const double x = integ.y()[0], v = integ.y()[1];
  series.t.push_back(integ.t() * s.T);
  series.force.push_back(s.force(x, v));
  series.delta.push_back(x * s.delta_ref);
  series.delta_dot.push_back(v * s.v0);
}

/// Which events of a single-body contact have been seen.
struct SingleBodyEvents {
  bool peak = false, compressed = false;
};

/// Records the events at which CVODE stopped (roots 0: force peak, the largest kept; 1: maximum
/// deformation, the first kept; 2: separation) into `r`. Returns true at the separation, after
/// writing the duration, separation velocity, restitution and step count; a separation before
/// the peak and the maximum deformation is a NumericalError.
template <class Damping>
bool record_single_body_events(const SingleBodyScaling<Damping>& s, const cvode::Integrator& integ,
                               SingleBodyEvents& seen, SingleBodyResult& r) {
  const std::vector<int> info = integ.roots_found();
  const double x = integ.y()[0], v = integ.y()[1];
  if (info[0] != 0) {
    const double F = s.force(x, v);
    if (!seen.peak || F > r.f_max) {
      r.f_max = F;
      r.t_at_f_max = integ.t() * s.T;
      r.delta_at_f_max = x * s.delta_ref;
      r.delta_dot_at_f_max = v * s.v0;
    }
    seen.peak = true;
  }
  if (info[1] != 0 && !seen.compressed) {
    r.delta_max = x * s.delta_ref;
    r.t_at_delta_max = integ.t() * s.T;
    seen.compressed = true;
  }
  if (info[2] == 0) return false;
  if (!seen.peak || !seen.compressed)
    throw NumericalError(str("simulate_single_body: separation at t = ", integ.t() * s.T,
                             " s before the force peak or the maximum deformation was found"));
  r.contact_duration = integ.t() * s.T;
  r.separation_velocity = v * s.v0;
  r.restitution = -v;
  r.num_steps = integ.num_steps();
  return true;
}

}  // namespace detail

/// The steps: detail::single_body_scaling, single_body_rhs and single_body_roots for CVODE, then
/// record_single_body_events at each event until the separation.
template <class Damping>
SingleBodyResult simulate_single_body(const HertzDamped<Damping>& law, double M_ie,
                                      const SingleBodyOptions& opt) {
  using detail::str;
  constexpr const char* where = "simulate_single_body";
  const detail::SingleBodyScaling<Damping> s = detail::single_body_scaling(law, M_ie);
  if (!(opt.max_scaled_duration > 0.0) || !std::isfinite(opt.max_scaled_duration))
    throw InputError(
        str(where, ": max_scaled_duration must be positive and finite, got ", opt.max_scaled_duration));
  cvode::Integrator integ(detail::single_body_rhs(s), Eigen::Vector2d(0.0, 1.0), 0.0, opt.cvode, 3,
                          detail::single_body_roots(s), {-1, -1, -1});
  SingleBodyResult r;
  if (opt.record_series) detail::record_single_body_sample(s, integ, r.series);
  detail::SingleBodyEvents seen;
  // advance() returns only at events (three expected) or at the end; step() once per step.
  const long max_calls = opt.record_series ? opt.cvode.max_num_steps : 64;
  for (long call = 0; call < max_calls; ++call) {
    const auto status =
        opt.record_series ? integ.step(opt.max_scaled_duration) : integ.advance(opt.max_scaled_duration);
    if (opt.record_series) detail::record_single_body_sample(s, integ, r.series);
    if (status == cvode::Integrator::Status::Reached)
      throw NumericalError(str(where, ": no separation within ", opt.max_scaled_duration * s.T, " s (",
                               opt.max_scaled_duration, " time units delta_max/v0)"));
    if (status == cvode::Integrator::Status::Root && detail::record_single_body_events(s, integ, seen, r))
      return r;
  }
  throw IntegrationError(str(where, ": no separation after ", max_calls,
                             " calls of CVODE (max_num_steps = ", opt.cvode.max_num_steps, ")"));
}

}  // namespace ffsr
