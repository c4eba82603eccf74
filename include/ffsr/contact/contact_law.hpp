// ffsr/contact/contact_law.hpp -- the Hertz contact law with hysteresis damping (Eq. 15) and its
// maximum force: the closed forms of Eq. 20, 23-25 and the exact maximum of the single-body model
// Eq. 16 (Zhang et al. 2022, Aerospace 9, 69, Section 3).
#pragma once

#include "ffsr/contact/damping.hpp"
#include "ffsr/errors.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

// Notation (the paper's): K stiffness, α exponent, c_r coefficient of restitution, δ deformation,
// δ̇ its rate, δ̇⁻ > 0 the approach velocity at first touch, M_ie the integrated effective mass
// (Eq. 14), λ = f(c_r) K / δ̇⁻ (Eq. 22) with f from a damping policy of damping.hpp.
//
// The single-body model Eq. 16, M_ie δ̈ + λ δ^α δ̇ + K δ^α = 0, has the first integral Eq. 19. With
// the dimensionless rate s = δ̇/δ̇⁻ (s = 1 at first touch, s = 0 at maximum compression) it reads
//     δ(s)^(α+1) = M_ie (α+1) δ̇⁻² G(s) / K,   G(s) = g(s)/f²,   g(s) = f(1-s) + ln((1+fs)/(1+f)),
// and G(s) -> (1-s²)/2 as f -> 0 (pure Hertz). All formulas below go through G, evaluated without
// cancellation (detail::contact_G), so c_r = 1 (f = 0) is the λ -> 0 limit, not a division by zero,
// and every quantity is continuous as c_r -> 1.
//
// The force along the contact is F(s) = K δ(s)^α (1 + f s). Its maximum lies in compression,
// s* in (0, 1), where d ln F/ds = 0; with g'(s) = -f² s/(1+fs) this is
//     (α+1) g(s) - α f s = 0,   i.e.  φ(s) = (α+1) f G(s) - α s = 0.
// φ(0) = (α+1) f G(0) > 0, φ(1) = -α < 0, and φ is decreasing and concave on [0, 1], so the root
// is unique; it is found by a bracketed Newton iteration in s or in t = 1 - s (detail::contact_peak).

namespace ffsr {

/// Parameters of the contact law Eq. 15: stiffness K [N/m^α], exponent α, restitution c_r.
struct ContactParams {
  double K = 1e9;
  double alpha = 1.5;
  double c_r = 0.9;
};

/// Throws InputError unless K > 0, α > 0 (both finite) and 0 < c_r <= 1. `where` names the caller.
inline void validate(const ContactParams& p, const char* where = "ContactParams");

/// The point of maximum force of the single-body contact (Eq. 16): F_max at δ'_max, δ̇ there.
struct ForcePeak {
  double force = 0;             ///< F_max [N]
  double deformation = 0;       ///< δ'_max [m]
  double deformation_rate = 0;  ///< δ̇ at the peak [m/s], in (0, δ̇⁻)
};

/// Hertz contact with hysteresis damping, F = K δ^α + λ δ^α δ̇ (Eq. 15), λ = f(c_r) K / δ̇⁻
/// (Eq. 22). `Damping` is a policy of damping.hpp.
///
/// Force convention: F = 0 when δ <= 0 (no contact), and F is clamped at 0 when the damping term
/// would make it negative (K + λ δ̇ < 0, fast separation): a contact pushes, it never pulls. Along
/// a trajectory of Eq. 16 the clamp is never active (1 + f s stays positive), so the closed forms
/// and the exact maximum below are unaffected by it; it only matters for arbitrary (δ, δ̇).
template <class Damping>
class HertzDamped {
 public:
  using damping_type = Damping;
  static constexpr std::string_view name = Damping::name;

  /// Validates p (see validate) and the approach velocity δ̇⁻ (> 0 and finite: the bodies approach);
  /// NumericalError when finite values overflow the law's constants λ or ζ.
  HertzDamped(const ContactParams& p, double approach_velocity);

  const ContactParams& params() const { return p_; }
  double approach_velocity() const { return v0_; }  ///< δ̇⁻ [m/s]
  double f() const { return f_; }                   ///< f(c_r) of Table 1 (Eq. 22)
  double lambda() const { return lambda_; }         ///< λ = f K / δ̇⁻ (Eq. 22)

  /// F(δ, δ̇) of Eq. 15 [N]; 0 for δ <= 0 and clamped at 0 (never pulls). NaN propagates;
  /// NumericalError when finite δ, δ̇ give a force past double precision.
  double force(double delta, double delta_dot) const;

  /// δ as a function of δ̇ along the single-body contact (Eq. 19) [m]. Requires M_ie > 0 and a rate
  /// reached by the contact (|δ̇| <= δ̇⁻ and not past separation), else InputError.
  double deformation(double M_ie, double delta_dot) const;

  /// δ_max, the deformation at δ̇ = 0 (Eq. 20) [m].
  double max_deformation(double M_ie) const;
  /// F'_max = K δ_max^α, the force at maximum deformation (Eq. 23) [N].
  double max_force_estimate(double M_ie) const;
  /// ζ of Eq. 25 [N/kg^(α/(α+1))]; independent of M_ie.
  double zeta() const { return zeta_; }
  /// F_max = ζ M_ie^(α/(α+1)) (Eq. 24) [N]; equal to max_force_estimate up to rounding.
  double max_force_closed_form(double M_ie) const;

  /// The exact maximum of F along the single-body contact (Figure 3, "*"), with δ'_max and δ̇ there.
  ForcePeak exact_peak(double M_ie) const;
  /// exact_peak(M_ie).force [N].
  double max_force_exact(double M_ie) const { return exact_peak(M_ie).force; }

  /// ξ = (F_max - F'_max)/F_max × 100 (Eq. 21), in percent. Depends on f(c_r) and α only.
  double relative_error() const;

 private:
  double delta_from_G(double M_ie, double G) const;  // (M (α+1) δ̇⁻² G / K)^(1/(α+1))

  ContactParams p_;
  double v0_;
  double f_;
  double lambda_;
  double G0_;    // G(0)
  double zeta_;  // Eq. 25
};

/// Run-time choice of the law (the CLI's `--model NAME`). One entry per policy of damping.hpp.
using AnyContactLaw = std::variant<HertzDamped<HuntCrossley>, HertzDamped<HerbertMcWhannell>,
                                   HertzDamped<LankaraniNikravesh>, HertzDamped<LeeWang>, HertzDamped<Flores>,
                                   HertzDamped<Gonthier>, HertzDamped<ZhiyingQishao>, HertzDamped<HuGuo>>;

/// Number of laws in AnyContactLaw.
inline constexpr std::size_t num_contact_laws = std::variant_size_v<AnyContactLaw>;

/// The names of the laws, in the order of AnyContactLaw (Table 1).
constexpr std::array<std::string_view, num_contact_laws> contact_law_names();

/// Builds the law called `name` (one of contact_law_names()); InputError for an unknown name (the
/// message lists the valid ones) or invalid parameters.
inline AnyContactLaw make_contact_law(std::string_view name, const ContactParams& p,
                                      double approach_velocity);

// The common methods on the run-time choice (each a std::visit of the member of the same name).
inline std::string_view contact_law_name(const AnyContactLaw& law);
inline double force(const AnyContactLaw& law, double delta, double delta_dot);
inline double damping_factor(const AnyContactLaw& law);  ///< f(c_r)
inline double lambda(const AnyContactLaw& law);
inline double approach_velocity(const AnyContactLaw& law);
inline double max_deformation(const AnyContactLaw& law, double M_ie);
inline double max_force_estimate(const AnyContactLaw& law, double M_ie);
inline double zeta(const AnyContactLaw& law);
inline double max_force_closed_form(const AnyContactLaw& law, double M_ie);
inline ForcePeak exact_peak(const AnyContactLaw& law, double M_ie);
inline double max_force_exact(const AnyContactLaw& law, double M_ie);
inline double relative_error(const AnyContactLaw& law);

/// δ̇⁻ = u·(v_e - (v_t + ω_t × r)) (Eq. 10-12): the initial normal relative velocity at the contact
/// point, positive when the end-effector and the target approach. u is the contact normal (unit,
/// pointing from the end-effector into the target), v_e the end-effector velocity, v_t and ω_t the
/// target's linear and angular velocity, r = r_tp from the target's mass centre to the contact
/// point; all in the inertial frame. InputError for non-finite entries or |u| not 1 (to 1e-9);
/// NumericalError when the products of finite entries overflow double precision.
inline double approach_velocity(const Eigen::Vector3d& u, const Eigen::Vector3d& v_e,
                                const Eigen::Vector3d& v_t, const Eigen::Vector3d& omega_t,
                                const Eigen::Vector3d& r);

/// Model accuracy of Eq. 32, in percent: (1 - |F_model - F_exact| / F_exact) × 100.
/// InputError unless both are finite and F_exact > 0; NumericalError if the result overflows.
inline double model_accuracy(double F_model, double F_exact);

// ============================================================================================
// Implementation
// ============================================================================================

namespace detail {

/// ln(1 - w) for w = f t/(1+f) (t = 1 - s): log1p(-w) while w < 1/2, else ln(1 + f s) - ln(1 + f),
/// which stays exact where w rounds to 1 (f ~ 1e17 at t = 1: ln(1-w) = -ln(1+f), not -inf).
inline double contact_log1m_w(double f, double t, double w) {
  return w < 0.5 ? std::log1p(-w) : std::log1p(f * (1.0 - t)) - std::log1p(f);
}

/// G = g/f² of Eq. 19 (see the file comment) as a function of t = 1 - s, the rate lost since first
/// touch, for f >= 0 and 0 <= t < 1 + 1/f. Taking t rather than s keeps full relative precision
/// next to first touch (s -> 1), where the force peak sits when α is tiny or f huge.
/// With u = t/(1+f) and w = f u: g = (1+f) w + ln(1-w), so G = u - Σ_{k>=2} f^(k-2) u^k / k.
/// The series (used when f u <= 1/4, always when f is small) has no cancellation and gives the
/// f -> 0 limit (1-s²)/2 exactly; otherwise log1p is accurate (f u > 1/4 means f > 1/3).
inline double contact_G_lost(double f, double t) {
  const double u = t / (1.0 + f);
  const double w = f * u;
  if (w <= 0.25) {
    double p = u * u;  // f^(k-2) u^k for k = 2
    double sum = 0.5 * p;
    for (int k = 3; k < 64 && p != 0.0; ++k) {  // 0.25^k: below 1e-17 by k = 28
      p *= w;
      const double term = p / k;
      sum += term;
      if (term <= 1e-18 * sum) break;
    }
    return u - sum;
  }
  return ((1.0 + f) * w + contact_log1m_w(f, t, w)) / (f * f);
}

/// f·G as a function of t (see contact_G_lost), f > 0: the term of the peak condition. Written with
/// w = f t/(1+f), which stays representable where G itself underflows (t ~ 1e-320 with f ~ 1e17):
/// f G = w - u Σ_{k>=2} w^(k-1)/k (series, w <= 1/4), else ((1+f) w + ln(1-w))/f.
inline double contact_fG_lost(double f, double t) {
  const double u = t / (1.0 + f);
  const double w = f / (1.0 + f) * t;
  if (w <= 0.25) {
    double p = w;  // w^(k-1) for k = 2
    double sum = 0.5 * p;
    for (int k = 3; k < 64 && p != 0.0; ++k) {
      p *= w;
      const double term = p / k;
      sum += term;
      if (term <= 1e-18 * sum) break;
    }
    return w - u * sum;
  }
  return ((1.0 + f) * w + contact_log1m_w(f, t, w)) / f;
}

/// G(s) = contact_G_lost(f, 1 - s), for s with 1 + f s > 0.
inline double contact_G(double f, double s) { return contact_G_lost(f, 1.0 - s); }

/// ln G as a function of t = 1 - s (t > 0): log of contact_G_lost, and where G underflows the
/// double range (t below ~1e-300: a peak within rounding of first touch) ln u + ln(1 - u/2 ...)
/// with ln u = ln t - ln(1+f), so that ratios of G stay finite.
inline double contact_log_G_lost(double f, double t) {
  const double G = contact_G_lost(f, t);
  if (G >= std::numeric_limits<double>::min()) return std::log(G);
  const double u = t / (1.0 + f);  // G = u (1 - u/2 - ...), u tiny here
  return std::log(t) - std::log1p(f) + std::log1p(-0.5 * u);
}

/// Where the force maximum lies: s* = δ̇/δ̇⁻ at the peak and t* = 1 - s*, the rate lost since first
/// touch, each to full relative precision (whichever is below 1/2 is the one solved for, the other
/// is 1 minus it, exact to rounding).
struct PeakRate {
  double s;  ///< s* in [0, 1)
  double t;  ///< t* = 1 - s* in (0, 1]
};

/// The root of φ(s) = (α+1) f G(s) - α s (file comment). φ is decreasing and concave in s on [0, 1]
/// (φ(0) > 0 > φ(1) = -α), so the root is unique. It is solved in s when it lies in s <= 1/2, and in
/// t = 1 - s otherwise, where ψ(t) = φ(1 - t) is increasing and concave: a root next to first touch
/// (t* ~ α(1+f)/((α+1)f) for tiny α) would round to s = 1 (G = 0, F = 0: a lost peak) if solved in s.
/// Newton's method started on the side where the tangent stays on the near side of the root (right
/// of it in s, at φ(0)/α or 1/2; left of it in t, at 0) moves monotonically onto it; a bisection step
/// guards the bracket anyway. At most 200 iterations; NumericalError if not converged (not expected).
/// f = 0 gives s* = 0 (pure Hertz: the peak is at δ_max).
inline PeakRate contact_peak(double f, double alpha) {
  if (f == 0.0) return {0.0, 1.0};
  // dG/ds = -s/(1+fs): φ'(s) = -(α+1) f s/(1+fs) - α, ψ'(t) = -φ'(1-t).
  auto phi = [&](double s, double t) { return (alpha + 1.0) * contact_fG_lost(f, t) - alpha * s; };
  auto slope = [&](double s) { return (alpha + 1.0) * f * s / (1.0 + f * s) + alpha; };  // |φ'(s)|
  const bool near_touch = phi(0.5, 0.5) > 0.0;  // φ(1/2) > 0: the root is at s > 1/2, t < 1/2
  // x is the variable solved for (t near touch, else s); v(x) its φ with the sign that makes it
  // increasing in x: near touch ψ(t), else -φ(s). Bracket [lo, hi] with v(lo) < 0 < v(hi).
  auto v = [&](double x) { return near_touch ? phi(1.0 - x, x) : -phi(x, 1.0 - x); };
  double lo = 0.0, hi = 0.5;
  double x = near_touch ? 0.0 : std::min(phi(0.0, 1.0) / alpha, 0.5);
  for (int it = 0; it < 200; ++it) {
    const double vx = v(x);
    if (vx == 0.0) break;
    if (vx < 0.0)
      lo = x;
    else
      hi = x;
    const double dv = slope(near_touch ? 1.0 - x : x);
    double next = x - vx / dv;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    // converged to rounding (a few units of the last place also among subnormals, for tiny α)
    const bool done = std::abs(next - x) <= 2.0 * std::numeric_limits<double>::epsilon() * next +
                                                4.0 * std::numeric_limits<double>::denorm_min();
    x = next;
    if (done) return near_touch ? PeakRate{1.0 - x, x} : PeakRate{x, 1.0 - x};
  }
  if (v(x) != 0.0) FFSR_THROW(NumericalError(str("contact_peak: no convergence for f = ", f, ", alpha = ", alpha)));
  return near_touch ? PeakRate{1.0 - x, x} : PeakRate{x, 1.0 - x};
}

/// The dimensionless rate s* in [0, 1) of the force maximum (see contact_peak).
inline double contact_peak_rate(double f, double alpha) { return contact_peak(f, alpha).s; }

/// Returns x; throws NumericalError when a result computed from finite, valid arguments is not finite
/// (it overflows double precision, e.g. M_ie = 1e300 kg).
inline double require_finite_result(double x, std::string_view where, const char* what, double M_ie) {
  if (!std::isfinite(x))
    FFSR_THROW(NumericalError(str(where, ": ", what, " is not representable (", x, ") for M_ie = ", M_ie, " kg")));
  return x;
}

inline void require_positive_mass(double M_ie, std::string_view where) {
  if (!(M_ie > 0.0) || !std::isfinite(M_ie))
    FFSR_THROW(InputError(str(where, ": integrated effective mass M_ie must be positive and finite, got ", M_ie)));
}

template <std::size_t... I>
constexpr std::array<std::string_view, num_contact_laws> contact_law_names_impl(std::index_sequence<I...>) {
  return {std::variant_alternative_t<I, AnyContactLaw>::name...};
}

template <std::size_t I = 0>
AnyContactLaw make_contact_law_impl(std::string_view name, const ContactParams& p, double v0) {
  if constexpr (I < num_contact_laws) {
    using Law = std::variant_alternative_t<I, AnyContactLaw>;
    if (Law::name == name) return AnyContactLaw(std::in_place_index<I>, p, v0);
    return make_contact_law_impl<I + 1>(name, p, v0);
  } else {
    std::string valid;
    for (std::string_view n : contact_law_names()) {
      if (!valid.empty()) valid += ", ";
      valid += n;
    }
    FFSR_THROW(InputError(str("make_contact_law: unknown contact law '", name, "'; valid names: ", valid)));
  }
}

}  // namespace detail

inline void validate(const ContactParams& p, const char* where) {
  if (!(p.K > 0.0) || !std::isfinite(p.K))
    FFSR_THROW(InputError(detail::str(where, ": stiffness K must be positive and finite, got ", p.K)));
  if (!(p.alpha > 0.0) || !std::isfinite(p.alpha))
    FFSR_THROW(InputError(detail::str(where, ": exponent alpha must be positive and finite, got ", p.alpha)));
  if (!(p.c_r > 0.0 && p.c_r <= 1.0))
    FFSR_THROW(InputError(
        detail::str(where, ": coefficient of restitution c_r must satisfy 0 < c_r <= 1, got ", p.c_r)));
}

template <class Damping>
HertzDamped<Damping>::HertzDamped(const ContactParams& p, double approach_velocity) : p_(p) {
  using detail::str;
  const std::string where = "contact law " + std::string(Damping::name);  // no stream (onboard images)
  validate(p, where.c_str());
  if (!std::isfinite(approach_velocity))
    FFSR_THROW(InputError(str(where, ": approach velocity must be finite, got ", approach_velocity)));
  if (!(approach_velocity > 0.0))
    FFSR_THROW(InputError(
        str(where, ": approach velocity must be positive (the bodies approach), got ", approach_velocity,
            approach_velocity < 0.0 ? ": the bodies are receding" : ": the bodies do not approach")));
  v0_ = approach_velocity;
  f_ = Damping::factor(p.c_r);
  if (!(f_ >= 0.0) || !std::isfinite(f_))  // a tiny c_r (1e-320) overflows f = 8 (1 - c_r) / (5 c_r)
    FFSR_THROW(NumericalError(str(where, ": damping factor f(c_r) = ", f_, " for c_r = ", p.c_r)));
  lambda_ = f_ * p.K / v0_;
  G0_ = detail::contact_G(f_, 0.0);
  // Eq. 25 written with G(0) = h(f)/f²: ζ = K^(1/(α+1)) ((α+1) δ̇⁻² G(0))^(α/(α+1)).
  const double a = p.alpha;
  zeta_ = std::pow(p.K, 1.0 / (a + 1.0)) * std::pow((a + 1.0) * v0_ * v0_ * G0_, a / (a + 1.0));
  // Finite inputs can still overflow the law's constants (an approach velocity of 1e200 m/s, or
  // K = 1e300 with a tiny approach velocity): an error, not a law that answers inf or NaN.
  if (!std::isfinite(lambda_) || !std::isfinite(zeta_))
    FFSR_THROW(NumericalError(
        str(where, ": the parameters overflow double precision (lambda = f K / approach velocity = ", lambda_,
            ", zeta = ", zeta_, " for K = ", p.K, ", alpha = ", p.alpha, ", approach velocity ",
            approach_velocity, ")")));
}

template <class Damping>
double HertzDamped<Damping>::force(double delta, double delta_dot) const {
  if (delta <= 0.0) return 0.0;
  const double g = p_.K + lambda_ * delta_dot;  // the force is pushing while K + λ δ̇ > 0
  if (!(g > 0.0)) return g <= 0.0 ? 0.0 : g;    // never pulls; NaN propagates
  const double P = std::pow(delta, p_.alpha);
  const double F = P == 0.0 ? 0.0 : P * g;  // δ^α underflowing to 0 times a huge g is 0, not NaN
  if (std::isinf(F) && std::isfinite(delta) && std::isfinite(delta_dot))
    FFSR_THROW(NumericalError(detail::str(name, ": the force overflows double precision at delta = ", delta,
                                     " m, delta_dot = ", delta_dot, " m/s")));
  return F;
}

template <class Damping>
double HertzDamped<Damping>::delta_from_G(double M_ie, double G) const {
  const double a = p_.alpha;
  return std::pow(M_ie * (a + 1.0) * v0_ * v0_ * G / p_.K, 1.0 / (a + 1.0));
}

template <class Damping>
double HertzDamped<Damping>::deformation(double M_ie, double delta_dot) const {
  detail::require_positive_mass(M_ie, name);
  const double s = delta_dot / v0_;
  const double G = (s >= -1.0 && s <= 1.0 && 1.0 + f_ * s > 0.0) ? detail::contact_G(f_, s) : -1.0;
  if (!(G >= 0.0))
    FFSR_THROW(InputError(detail::str(name, ": deformation: delta_dot = ", delta_dot,
                                 " is not reached during a contact with approach velocity ", v0_)));
  return detail::require_finite_result(delta_from_G(M_ie, G), name, "deformation", M_ie);
}

template <class Damping>
double HertzDamped<Damping>::max_deformation(double M_ie) const {
  detail::require_positive_mass(M_ie, name);
  return detail::require_finite_result(delta_from_G(M_ie, G0_), name, "delta_max", M_ie);
}

template <class Damping>
double HertzDamped<Damping>::max_force_estimate(double M_ie) const {
  return detail::require_finite_result(p_.K * std::pow(max_deformation(M_ie), p_.alpha), name, "F'_max",
                                       M_ie);
}

template <class Damping>
double HertzDamped<Damping>::max_force_closed_form(double M_ie) const {
  detail::require_positive_mass(M_ie, name);
  return detail::require_finite_result(zeta_ * std::pow(M_ie, p_.alpha / (p_.alpha + 1.0)), name, "F_max",
                                       M_ie);
}

template <class Damping>
ForcePeak HertzDamped<Damping>::exact_peak(double M_ie) const {
  detail::require_positive_mass(M_ie, name);
  const auto [s, t] = detail::contact_peak(f_, p_.alpha);
  ForcePeak pk;
  pk.deformation = delta_from_G(M_ie, detail::contact_G_lost(f_, t));
  pk.deformation_rate = s * v0_;
  pk.force = p_.K * std::pow(pk.deformation, p_.alpha) * (1.0 + f_ * s);
  // δ(t*) underflowing to 0 (a peak within ~1e-300 of first touch) would report F = 0: not an answer.
  if (!(pk.deformation > 0.0))
    FFSR_THROW(NumericalError(
        detail::str(name, ": the force peak is too close to first touch to be represented (f = ", f_,
                    ", alpha = ", p_.alpha, ", M_ie = ", M_ie, " kg)")));
  detail::require_finite_result(pk.deformation, name, "deformation at the force peak", M_ie);
  detail::require_finite_result(pk.force, name, "exact F_max", M_ie);
  return pk;
}

template <class Damping>
double HertzDamped<Damping>::relative_error() const {
  // ξ = 1 - F'/F = 1 - (G(0)/G(s*))^(α/(α+1)) / (1 + f s*), as -expm1(ln) for accuracy near f = 0.
  // ln(G(0)/G(s*)) as log1p of the relative difference while G(s*) is a normal number; from the
  // logarithms when the peak is so close to first touch that G(s*) underflows (tiny α).
  const double a = p_.alpha;
  const auto [s, t] = detail::contact_peak(f_, a);
  const double Gs = detail::contact_G_lost(f_, t);
  const double ln_G_ratio = Gs >= std::numeric_limits<double>::min()
                                ? std::log1p((G0_ - Gs) / Gs)
                                : std::log(G0_) - detail::contact_log_G_lost(f_, t);
  const double ln_ratio = a / (a + 1.0) * ln_G_ratio - std::log1p(f_ * s);
  // + 0.0: at c_r = 1 (f = 0) the product is -0, which would print as "-0"; zero has no sign here
  const double xi = -100.0 * std::expm1(ln_ratio) + 0.0;
  if (!std::isfinite(xi))
    FFSR_THROW(NumericalError(detail::str(name, ": xi is not representable for f = ", f_, ", alpha = ", a)));
  return xi;
}

constexpr std::array<std::string_view, num_contact_laws> contact_law_names() {
  return detail::contact_law_names_impl(std::make_index_sequence<num_contact_laws>{});
}

inline AnyContactLaw make_contact_law(std::string_view name, const ContactParams& p,
                                      double approach_velocity) {
  return detail::make_contact_law_impl(name, p, approach_velocity);
}

namespace detail {
/// Evaluates `quantity` (a generic lambda taking the law) on the law the variant holds: the one
/// dispatch behind the run-time functions below, each the law's member of the same name.
template <class Quantity>
decltype(auto) visit_law(const AnyContactLaw& law, Quantity&& quantity) {
  return std::visit(std::forward<Quantity>(quantity), law);
}
}  // namespace detail

inline std::string_view contact_law_name(const AnyContactLaw& law) {
  return detail::visit_law(law, [](const auto& l) { return l.name; });
}
inline double force(const AnyContactLaw& law, double delta, double delta_dot) {
  return detail::visit_law(law, [&](const auto& l) { return l.force(delta, delta_dot); });
}
inline double damping_factor(const AnyContactLaw& law) {
  return detail::visit_law(law, [](const auto& l) { return l.f(); });
}
inline double lambda(const AnyContactLaw& law) {
  return detail::visit_law(law, [](const auto& l) { return l.lambda(); });
}
inline double approach_velocity(const AnyContactLaw& law) {
  return detail::visit_law(law, [](const auto& l) { return l.approach_velocity(); });
}
inline double max_deformation(const AnyContactLaw& law, double M_ie) {
  return detail::visit_law(law, [&](const auto& l) { return l.max_deformation(M_ie); });
}
inline double max_force_estimate(const AnyContactLaw& law, double M_ie) {
  return detail::visit_law(law, [&](const auto& l) { return l.max_force_estimate(M_ie); });
}
inline double zeta(const AnyContactLaw& law) {
  return detail::visit_law(law, [](const auto& l) { return l.zeta(); });
}
inline double max_force_closed_form(const AnyContactLaw& law, double M_ie) {
  return detail::visit_law(law, [&](const auto& l) { return l.max_force_closed_form(M_ie); });
}
inline ForcePeak exact_peak(const AnyContactLaw& law, double M_ie) {
  return detail::visit_law(law, [&](const auto& l) { return l.exact_peak(M_ie); });
}
inline double max_force_exact(const AnyContactLaw& law, double M_ie) {
  return detail::visit_law(law, [&](const auto& l) { return l.max_force_exact(M_ie); });
}
inline double relative_error(const AnyContactLaw& law) {
  return detail::visit_law(law, [](const auto& l) { return l.relative_error(); });
}

inline double approach_velocity(const Eigen::Vector3d& u, const Eigen::Vector3d& v_e,
                                const Eigen::Vector3d& v_t, const Eigen::Vector3d& omega_t,
                                const Eigen::Vector3d& r) {
  constexpr const char* where = "approach_velocity";
  detail::require_finite_all(u, where, "normal u");
  detail::require_finite_all(v_e, where, "end-effector velocity v_e");
  detail::require_finite_all(v_t, where, "target velocity v_t");
  detail::require_finite_all(omega_t, where, "target angular velocity omega_t");
  detail::require_finite_all(r, where, "contact point offset r");
  if (std::abs(u.norm() - 1.0) > 1e-9)
    FFSR_THROW(InputError(detail::str(where, ": normal u must be a unit vector, |u| = ", u.norm())));
  const Eigen::Vector3d v_tp = v_t + omega_t.cross(r);  // Eq. 12
  const double v = u.dot(v_e - v_tp);
  // finite inputs whose products pass 1e308 (omega_t x r) give inf, or NaN from 0 * inf in the dot
  if (!std::isfinite(v)) {
    auto largest = [](const Eigen::Vector3d& x) { return x.cwiseAbs().maxCoeff(); };
    FFSR_THROW(NumericalError(detail::str(where, ": the relative velocity overflows double precision (largest ",
                                     "entries: v_e ", largest(v_e), ", v_t ", largest(v_t), ", omega_t ",
                                     largest(omega_t), ", r ", largest(r), ")")));
  }
  return v;
}

inline double model_accuracy(double F_model, double F_exact) {
  detail::require_finite(F_model, "model_accuracy", "F_model");
  if (!(F_exact > 0.0) || !std::isfinite(F_exact))
    FFSR_THROW(InputError(detail::str("model_accuracy: F_exact must be positive and finite, got ", F_exact)));
  const double accuracy = (1.0 - std::abs(F_model - F_exact) / F_exact) * 100.0;  // Eq. 32
  if (!std::isfinite(accuracy))  // |F_model - F_exact| / F_exact overflows, e.g. F_exact = 1e-310 N
    FFSR_THROW(NumericalError(detail::str("model_accuracy: the accuracy is not representable for F_model = ",
                                     F_model, ", F_exact = ", F_exact)));
  return accuracy;
}

}  // namespace ffsr
