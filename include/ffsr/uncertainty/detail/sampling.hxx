// ffsr/uncertainty/detail/sampling.hxx -- bodies of ffsr/uncertainty/sampling.hpp.
#pragma once

#include <iomanip>
#include <sstream>

namespace ffsr {

namespace detail {

inline bool is_scalar_quantity(Quantity q) {
  return q == Quantity::TargetMass || q == Quantity::ApproachSpeed || q == Quantity::Stiffness ||
         q == Quantity::Restitution || q == Quantity::Exponent;
}
inline bool is_vector_quantity(Quantity q) {
  return q == Quantity::ContactOffset || q == Quantity::ContactPoint || q == Quantity::Spin ||
         q == Quantity::TargetVelocity;
}
/// A number as a person wrote it (6 significant digits), for messages about what they wrote.
inline std::string short_number(double x) {
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}

inline std::string quantity_key(Quantity q) {
  return "uncertainty." + std::string(kQuantityNames[static_cast<std::size_t>(q)]);
}

/// The physical rule of a scalar quantity (see the top of sampling.hpp).
inline bool physical_scalar(Quantity q, double x) {
  if (!std::isfinite(x)) return false;
  if (q == Quantity::Restitution) return x > 0.0 && x <= 1.0;
  return x > 0.0;  // mass, approach speed, stiffness, exponent
}

/// The spread of a normal or uniform law in the quantity's units: scale, or scale |x0| when relative.
inline double absolute_scale(const Spread& sp, double x0) {
  return sp.relative ? sp.scale * std::abs(x0) : sp.scale;
}

inline double draw_scalar(const Spread& sp, Quantity q, double x0, SampleStream& rng, int& redraws,
                          double& score) {
  if (sp.law == Spread::Law::Fixed) {
    score = 0;
    return x0;
  }
  const double s = absolute_scale(sp, x0);
  for (int k = 0; k < kMaxRedraws; ++k) {
    double x = x0, sc = 0;
    if (sp.law == Spread::Law::Normal) {
      const double z = rng.normal();
      x = x0 + s * z;
      sc = z;
    } else if (sp.law == Spread::Law::Uniform) {
      const double lo = sp.has_range ? sp.min : x0 - s, hi = sp.has_range ? sp.max : x0 + s;
      const double u = rng.uniform();
      x = lo + (hi - lo) * u;
      sc = 2.0 * u - 1.0;
    } else if (sp.law == Spread::Law::LogNormal) {
      const double z = rng.normal();
      x = x0 * std::exp(sp.scale * z);
      sc = z;
    }
    if (x >= sp.min && x <= sp.max && physical_scalar(q, x)) {
      score = sc;
      return x;
    }
    ++redraws;
  }
  FFSR_THROW(NumericalError(str(quantity_key(q), ": no physical value within the bounds in ", kMaxRedraws,
                           " draws (the law puts almost no probability there)")));
}

inline Vector3 draw_offset(const Spread& sp, SampleStream& rng, double& score) {
  Vector3 d = Vector3::Zero();
  score = 0;
  if (sp.law == Spread::Law::Fixed || sp.scale == 0.0) return d;
  if (sp.law == Spread::Law::Normal) {
    for (int k = 0; k < 3; ++k) d(k) = rng.normal();
    score = d.norm();
  } else {
    for (int k = 0; k < 3; ++k) d(k) = 2.0 * rng.uniform() - 1.0;
    score = d.cwiseAbs().maxCoeff();
  }
  return sp.scale * d;
}

inline Matrix3 draw_inertia(const Spread& sp, const Matrix3& I0, SampleStream& rng, int& redraws,
                            double& score) {
  score = 0;
  if (sp.law == Spread::Law::Fixed) return I0;
  const Eigen::SelfAdjointEigenSolver<Matrix3> es(I0);
  const Vector3& l0 = es.eigenvalues();
  const Matrix3& V = es.eigenvectors();
  for (int k = 0; k < kMaxRedraws; ++k) {
    Vector3 e;
    for (int i = 0; i < 3; ++i)
      e(i) = sp.law == Spread::Law::Normal ? sp.scale * rng.normal() : sp.scale * (2.0 * rng.uniform() - 1.0);
    const Vector3 l = l0.cwiseProduct(Vector3::Ones() + e);
    const double lmax = l.maxCoeff();
    if (!(l.minCoeff() > 0.0) || lmax > l.sum() - lmax) {  // positive moments, triangle inequality
      ++redraws;
      continue;
    }
    Matrix3 R = Matrix3::Identity();
    if (sp.axes > 0.0) {
      const Vector3 axis = rng.unit_sphere();
      R = Eigen::AngleAxisd(sp.axes * rng.uniform(), axis).toRotationMatrix();
    }
    const Matrix3 RV = R * V;
    Matrix3 I = RV * l.asDiagonal() * RV.transpose();
    I = 0.5 * (I + I.transpose()).eval();
    score = sp.scale > 0.0 ? e.cwiseAbs().maxCoeff() / sp.scale : 0.0;
    return I;
  }
  FFSR_THROW(NumericalError(str(quantity_key(Quantity::TargetInertia),
                           ": no principal moments satisfying the triangle inequality in ", kMaxRedraws,
                           " draws (spread too large)")));
}

inline Vector3 draw_normal(const Spread& sp, const Vector3& n0, SampleStream& rng, double& score) {
  score = 0;
  Vector3 n = n0.normalized();
  if (sp.law == Spread::Law::Fixed || sp.scale == 0.0) return n;
  const Vector3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  const double cos_a = std::cos(sp.scale);
  const double ct = 1.0 - rng.uniform() * (1.0 - cos_a);  // uniform on the cap
  const double st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
  double c = 0, s = 0;
  rng.unit_circle(c, s);
  score = std::acos(std::clamp(ct, -1.0, 1.0)) / sp.scale;
  return (ct * n + st * (c * e1 + s * e2)).normalized();
}

/// The checks every law of `key` passes: a finite non-negative scale, min <= max, a range's bounds finite.
inline void validate_spread_scale(const Spread& sp, const std::string& key) {
  if (!std::isfinite(sp.scale) || sp.scale < 0)
    FFSR_THROW(InputError(
        str(key, ": the spread must be a non-negative finite number, got ", short_number(sp.scale))));
  if (std::isnan(sp.min) || std::isnan(sp.max) || sp.min > sp.max)
    FFSR_THROW(InputError(
        str(key, ": min (", short_number(sp.min), ") is greater than max (", short_number(sp.max), ")")));
  if (sp.has_range && (!std::isfinite(sp.min) || !std::isfinite(sp.max)))
    FFSR_THROW(InputError(str(key, ": a uniform law needs finite min and max")));
}

/// The normal: a cone of half-angle at most 90 deg.
inline void validate_normal_spread(const Spread& sp, const std::string& key) {
  if (sp.law != Spread::Law::Cone)
    FFSR_THROW(InputError(str(key, ": the normal takes the law 'cone' (angle-deg)")));
  if (sp.scale > kPi / 2 * (1 + 1e-15))
    FFSR_THROW(InputError(str(key, ": the cone half-angle must be at most 90 deg, got ",
                         short_number(sp.scale * 180 / kPi), " deg")));
}

/// The inertia: a relative normal or uniform law that keeps the moments positive, axes in [0, 180] deg.
inline void validate_inertia_spread(const Spread& sp, const std::string& key) {
  if (sp.law != Spread::Law::Normal && sp.law != Spread::Law::Uniform)
    FFSR_THROW(InputError(str(key, ": the inertia takes a 'normal' or 'uniform' law with a relative spread")));
  if (!(sp.axes >= 0 && sp.axes <= kPi))
    FFSR_THROW(InputError(str(key, ": axes-deg must be in [0, 180], got ", short_number(sp.axes * 180 / kPi))));
  if (sp.scale >= 1.0 && sp.law == Spread::Law::Uniform)
    FFSR_THROW(InputError(str(key, ": a relative half-width of ", short_number(sp.scale),
                         " allows non-positive moments (must be < 1)")));
}

/// A vector quantity: a normal or uniform law with an absolute spread.
inline void validate_vector_spread(const Spread& sp, const std::string& key) {
  if (sp.law == Spread::Law::LogNormal)
    FFSR_THROW(InputError(str(key, ": a vector takes a 'normal' or 'uniform' law")));
  if (sp.relative || sp.has_range)
    FFSR_THROW(InputError(
        str(key, ": a vector takes an absolute spread (std or half-width), not relative or min/max")));
}

}  // namespace detail

inline void validate(const UncertaintySpec& spec) {
  if (spec.samples < 1) FFSR_THROW(InputError("uncertainty.samples: must be at least 1, got 0"));
  for (std::size_t i = 0; i < kNumQuantities; ++i) {
    const Quantity q = static_cast<Quantity>(i);
    const Spread& sp = spec.spread[i];
    const std::string key = detail::quantity_key(q);
    if (sp.law == Spread::Law::Fixed) continue;
    detail::validate_spread_scale(sp, key);
    if (q == Quantity::Normal) {
      detail::validate_normal_spread(sp, key);
      continue;
    }
    if (sp.law == Spread::Law::Cone)
      FFSR_THROW(InputError(detail::str(key, ": the law 'cone' is for the normal only")));
    if (q == Quantity::TargetInertia)
      detail::validate_inertia_spread(sp, key);
    else if (detail::is_vector_quantity(q))
      detail::validate_vector_spread(sp, key);
  }
}

inline UncertainSample draw_sample(const UncertaintySpec& spec, const UncertainNominal& nominal,
                                   std::uint64_t index) {
  using Q = Quantity;
  SampleStream rng(spec.seed, index);
  UncertainSample s;
  s.index = index;
  auto sc = [&s](Q q) -> double& { return s.score[static_cast<std::size_t>(q)]; };
  const Target& t0 = nominal.target;
  const Matrix3 R = t0.rotation();
  for (int attempt = 0; attempt < kMaxRedraws; ++attempt) {
    s.target = t0;
    s.target.mass =
        detail::draw_scalar(spec[Q::TargetMass], Q::TargetMass, t0.mass, rng, s.redraws, sc(Q::TargetMass));
    s.target.inertia =
        detail::draw_inertia(spec[Q::TargetInertia], t0.inertia, rng, s.redraws, sc(Q::TargetInertia));
    s.target.contact_offset =
        t0.contact_offset + detail::draw_offset(spec[Q::ContactOffset], rng, sc(Q::ContactOffset));
    s.target.normal = detail::draw_normal(spec[Q::Normal], t0.normal, rng, sc(Q::Normal));
    s.target.angular_velocity = t0.angular_velocity + detail::draw_offset(spec[Q::Spin], rng, sc(Q::Spin));
    s.target.velocity =
        t0.velocity + detail::draw_offset(spec[Q::TargetVelocity], rng, sc(Q::TargetVelocity));
    s.approach_speed = detail::draw_scalar(spec[Q::ApproachSpeed], Q::ApproachSpeed, nominal.approach_speed,
                                           rng, s.redraws, sc(Q::ApproachSpeed));
    s.contact.K = detail::draw_scalar(spec[Q::Stiffness], Q::Stiffness, nominal.contact.K, rng, s.redraws,
                                      sc(Q::Stiffness));
    s.contact.c_r = detail::draw_scalar(spec[Q::Restitution], Q::Restitution, nominal.contact.c_r, rng,
                                        s.redraws, sc(Q::Restitution));
    s.contact.alpha = detail::draw_scalar(spec[Q::Exponent], Q::Exponent, nominal.contact.alpha, rng,
                                          s.redraws, sc(Q::Exponent));
    // drawn last, so that the streams of the other quantities do not depend on whether it is set
    const Vector3 d = detail::draw_offset(spec[Q::ContactPoint], rng, sc(Q::ContactPoint));
    s.target.contact_offset += d;
    s.robot_offset = R * d;
    s.normal_world = R * s.target.normal;
    s.wrench << s.normal_world, s.robot_offset.cross(s.normal_world);
    const Vector3 r = R * s.target.contact_offset;
    s.approach_velocity =
        s.approach_speed - s.normal_world.dot(s.target.velocity + (R * s.target.angular_velocity).cross(r));
    if (s.approach_velocity > 0) {
      s.target_inverse_mass = s.target.inverse_mass_along_normal();
      return s;
    }
    ++s.redraws;  // the bodies would not approach: redraw the whole sample
  }
  FFSR_THROW(NumericalError(
      detail::str("uncertainty: sample ", index, " has the bodies receding (delta_dot^- <= 0) in ",
                  kMaxRedraws, " draws; increase the approach speed or narrow the spin/velocity spreads")));
}

inline Matrix3 robot_inverse_mass_matrix(const Model& model, Data& data, const BasePose& base,
                                         const Eigen::Ref<const Eigen::VectorXd>& theta, int frame) {
  crba(model, data, base, theta);
  Eigen::Matrix<double, Eigen::Dynamic, 3> Y(data.H.rows(), 3);  // columns L^-1 J_v^T e_k
  for (int k = 0; k < 3; ++k) {
    inverse_effective_mass(model, data, frame, Vector3::Unit(k));
    Y.col(k) = data.y;
  }
  return Y.transpose() * Y;
}

inline Matrix6 robot_inverse_inertia(const Model& model, Data& data, const BasePose& base,
                                     const Eigen::Ref<const Eigen::VectorXd>& theta, int frame) {
  crba(model, data, base, theta);
  return inverse_inertia_matrix(model, data, frame);
}

inline SampleForce sample_force(const Matrix6& Linv, const UncertainSample& s, std::string_view law,
                                ForceModel model) {
  SampleForce f;
  f.M_ie = 1.0 / (s.wrench.dot(Linv * s.wrench) + s.target_inverse_mass);
  f.approach_velocity = s.approach_velocity;
  const AnyContactLaw l = make_contact_law(law, s.contact, s.approach_velocity);
  if (model == ForceModel::Closed)
    f.f_max = max_force_closed_form(l, f.M_ie);
  else if (model == ForceModel::Exact)
    f.f_max = max_force_exact(l, f.M_ie);
  else
    FFSR_THROW(InputError("sample_force: the multibody force model is in ffsr/uncertainty/multibody.hpp"));
  return f;
}

inline double nearest_rank(const std::vector<double>& sorted, int percent) {
  const std::size_t n = sorted.size();
  if (n == 0) FFSR_THROW(InputError("nearest_rank: no values"));
  if (percent < 1 || percent > 100)
    FFSR_THROW(InputError(detail::str("nearest_rank: percent must be in [1, 100], got ", percent)));
  const std::size_t rank = (static_cast<std::size_t>(percent) * n + 99) / 100;  // ceil(p n / 100) >= 1
  return sorted[rank - 1];
}

inline QuantileRanks quantile_interval(std::size_t n, double q, double confidence) {
  if (n == 0) FFSR_THROW(InputError("quantile_interval: no values"));
  if (!(q > 0 && q < 1)) FFSR_THROW(InputError(detail::str("quantile_interval: q must be in (0, 1), got ", q)));
  if (!(confidence > 0 && confidence < 1))
    FFSR_THROW(InputError(detail::str("quantile_interval: confidence must be in (0, 1), got ", confidence)));
  const double nd = static_cast<double>(n), sd = std::sqrt(nd * q * (1 - q));
  // the binomial mass outside [k0, k1] is below 1e-300: the CDF starts at 0 at k0
  const auto k0 = static_cast<std::size_t>(std::max(0.0, std::floor(nd * q - 40 * sd - 40)));
  const auto k1 = static_cast<std::size_t>(std::min(nd, std::ceil(nd * q + 40 * sd + 40)));
  const double alpha = 0.5 * (1 - confidence), lnq = std::log(q), lnp = std::log1p(-q),
               lg = std::lgamma(nd + 1);
  QuantileRanks r;
  double cdf = 0, below_lower = 0;  // P(B <= k) and P(B <= l - 1)
  bool have_upper = false;
  for (std::size_t k = k0; k <= k1; ++k) {
    const double kd = static_cast<double>(k);
    cdf += std::exp(lg - std::lgamma(kd + 1) - std::lgamma(nd - kd + 1) + kd * lnq + (nd - kd) * lnp);
    // rank k + 1 has P(B <= (k + 1) - 1) = cdf
    if (cdf <= alpha && k + 1 <= n) {
      r.lower = k + 1;
      below_lower = cdf;
    }
    if (!have_upper && cdf >= 1 - alpha && k + 1 <= n) {
      r.upper = k + 1;
      r.coverage = cdf - below_lower;
      have_upper = true;
    }
  }
  if (!have_upper) r.coverage = 1.0 - below_lower;  // up to X_(n) and beyond: B <= n always
  return r;
}

inline ForceSummary summarize(const std::vector<double>& v) {
  ForceSummary s;
  s.n = v.size();
  if (s.n == 0) FFSR_THROW(InputError("summarize: no values"));
  double sum = 0;
  for (double x : v) {
    if (!std::isfinite(x)) FFSR_THROW(NumericalError(detail::str("summarize: a value is not finite (", x, ")")));
    sum += x;
  }
  s.mean = sum / static_cast<double>(s.n);
  double ss = 0;
  for (double x : v) ss += (x - s.mean) * (x - s.mean);
  s.std = s.n > 1 ? std::sqrt(ss / static_cast<double>(s.n - 1)) : 0.0;
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  s.p50 = nearest_rank(sorted, 50);
  s.p95 = nearest_rank(sorted, 95);
  s.p99 = nearest_rank(sorted, 99);
  s.max = sorted.back();
  const QuantileRanks ci = quantile_interval(s.n, 0.95);
  s.p95_ci.lower = ci.lower;
  s.p95_ci.upper = ci.upper;
  s.p95_ci.coverage = ci.coverage;
  s.p95_ci.has_lo = ci.lower != 0;
  s.p95_ci.has_hi = ci.upper != 0;
  if (ci.lower) s.p95_ci.lo = sorted[ci.lower - 1];
  if (ci.upper) s.p95_ci.hi = sorted[ci.upper - 1];
  s.order = {s.p50, s.p95, s.p99, s.p95_ci};
  return s;
}

namespace detail {

/// Standard normal CDF, accurate in the lower tail (erfc).
inline double normal_cdf(double z) { return 0.5 * std::erfc(-z * 0.7071067811865476); }
/// The standard normal's 97.5 % quantile: the half-width of a 95 % interval in standard errors.
inline constexpr double kZ975 = 1.959963984540054;
inline double normal_pdf(double z) { return 0.3989422804014327 * std::exp(-0.5 * z * z); }

/// The untruncated law of a scalar Spread about x0: CDF and density at x (scale > 0 checked by the caller).
inline LawPoint base_law(const Spread& sp, double x0, double x) {
  const double s = absolute_scale(sp, x0);
  if (sp.law == Spread::Law::Normal) {
    const double z = (x - x0) / s;
    return {normal_cdf(z), std::isfinite(z) ? normal_pdf(z) / s : 0.0};
  }
  if (sp.law == Spread::Law::Uniform) {
    const double lo = sp.has_range ? sp.min : x0 - s, hi = sp.has_range ? sp.max : x0 + s;
    if (x < lo) return {0.0, 0.0};
    if (x >= hi) return {1.0, 0.0};
    return {(x - lo) / (hi - lo), 1.0 / (hi - lo)};
  }
  // log-normal, median x0
  if (!(x > 0)) return {0.0, 0.0};
  const double z = std::log(x / x0) / sp.scale;
  return {normal_cdf(z), std::isfinite(z) ? normal_pdf(z) / (sp.scale * x) : 0.0};
}

/// Whether a scalar law has a density (a positive spread).
inline bool has_density(const Spread& sp, double x0) {
  if (sp.law == Spread::Law::Normal) return absolute_scale(sp, x0) > 0;
  if (sp.law == Spread::Law::Uniform) return sp.has_range ? sp.max > sp.min : absolute_scale(sp, x0) > 0;
  if (sp.law == Spread::Law::LogNormal) return sp.scale > 0 && x0 > 0;
  return false;
}

/// A scalar law truncated to its support after the redraws (the bounds min/max and the physical
/// rule of physical_scalar: every scalar quantity > 0, c_r <= 1), built once, evaluated often.
struct TruncatedLaw {
  const Spread& sp;
  double x0, L, U, cdf_L, Z;
  TruncatedLaw(const Spread& law, Quantity q, double nominal) : sp(law), x0(nominal) {
    if (!is_scalar_quantity(q))
      FFSR_THROW(InputError(str("scalar_law: ", quantity_key(q), " is not a scalar quantity")));
    if (!std::isfinite(x0) || !has_density(sp, x0))
      FFSR_THROW(InputError(
          str("scalar_law: ", quantity_key(q), " has no law with a spread (fixed or zero spread)")));
    L = std::max(sp.min, 0.0);
    U = q == Quantity::Restitution ? std::min(sp.max, 1.0) : sp.max;
    cdf_L = base_law(sp, x0, L).cdf;
    Z = base_law(sp, x0, U).cdf - cdf_L;
    if (!(Z > 0))
      FFSR_THROW(NumericalError(str("scalar_law: ", quantity_key(q), " puts no probability within its bounds")));
  }
  LawPoint operator()(double x) const {
    if (x <= L) return {0.0, 0.0};
    if (x >= U) return {1.0, 0.0};
    const LawPoint b = base_law(sp, x0, x);
    return {std::clamp((b.cdf - cdf_L) / Z, 0.0, 1.0), b.density / Z};
  }
};

}  // namespace detail

inline LawPoint scalar_law(const Spread& sp, Quantity q, double x0, double x) {
  if (std::isnan(x)) FFSR_THROW(InputError("scalar_law: x is NaN"));
  return detail::TruncatedLaw(sp, q, x0)(x);
}

inline bool stiffness_conditional_applies(ForceModel model, const Spread& stiffness) {
  return model != ForceModel::Multibody && stiffness.law != Spread::Law::Fixed &&
         stiffness.law != Spread::Law::Cone && detail::has_density(stiffness, 1.0);
}

namespace detail {

/// The stiffness-conditional CDF of F_max at ln q = t and its derivative in t: sample i contributes
/// P_K(K <= exp(a_i t + b_i)), a_i = alpha_i + 1, b_i = ln K_i - a_i ln F_i.
struct ConditionalCdf {
  const std::vector<double>& a;
  const std::vector<double>& b;
  const TruncatedLaw& law;
  /// C(t), dC/dt; with `h` set, also each sample's P_K (for the variance).
  std::pair<double, double> operator()(double t, std::vector<double>* h = nullptr) const {
    double c = 0, d = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const double k = std::exp(a[i] * t + b[i]);
      const LawPoint p = law(k);
      c += p.cdf;
      d += p.density * k * a[i];  // dP/dt = pdf(k) dk/dt, dk/dt = a k
      if (h) (*h)[i] = p.cdf;
    }
    const double n = static_cast<double>(a.size());
    return {c / n, d / n};
  }
};

/// Solves C(t) = p for t (C non-decreasing, 0 at -inf and 1 at +inf), from t0: expands a bracket,
/// then Newton steps kept inside it (bisection when a step leaves it or the slope vanishes).
inline double conditional_quantile(const ConditionalCdf& C, double p, double t0) {
  double lo = t0 - 0.25, hi = t0 + 0.25, step = 0.25;
  for (int k = 0; C(lo).first >= p; ++k) {
    if (k > 200) FFSR_THROW(NumericalError("summarize_stiffness_conditional: no lower bracket of the quantile"));
    hi = std::min(hi, lo);
    lo -= step;
    step *= 2;
  }
  step = 0.25;
  for (int k = 0; C(hi).first < p; ++k) {
    if (k > 200) FFSR_THROW(NumericalError("summarize_stiffness_conditional: no upper bracket of the quantile"));
    lo = std::max(lo, hi);
    hi += step;
    step *= 2;
  }
  double t = std::clamp(t0, lo, hi);
  for (int it = 0; it < 200; ++it) {
    const auto [c, d] = C(t);
    if (c < p)
      lo = t;
    else
      hi = t;
    double next = d > 0 ? t - (c - p) / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) <= 1e-14 * (1.0 + std::abs(t)) || hi - lo <= 1e-14 * (1.0 + std::abs(t)))
      return next;
    t = next;
  }
  return t;  // 200 safeguarded steps: the bracket has shrunk far below any printed digit
}

}  // namespace detail

namespace detail {

/// Each sample's conditional CDF P_K,i at the estimate t = ln p95, their mean C and the slope C'
/// there: what the delta method needs (n >= 2).
struct ConditionalAtP95 {
  std::vector<double> h;
  double c = 0, d = 0;
};

/// summarize_stiffness_conditional, and the state of its estimate at p95 when `at` is given.
inline ForceSummary conditional_summary(const std::vector<double>& f, const std::vector<double>& K,
                                        const std::vector<double>& alpha, const Spread& stiffness, double K0,
                                        ConditionalAtP95* at) {
  const std::size_t n = f.size();
  if (K.size() != n || alpha.size() != n)
    FFSR_THROW(InputError(detail::str("summarize_stiffness_conditional: ", n, " forces, ", K.size(),
                                 " stiffnesses and ", alpha.size(), " exponents")));
  if (!(K0 > 0) || !std::isfinite(K0))
    FFSR_THROW(InputError(
        detail::str("summarize_stiffness_conditional: the nominal stiffness must be positive, got ", K0)));
  const TruncatedLaw law(stiffness, Quantity::Stiffness, K0);  // InputError for a law without spread
  ForceSummary s = summarize(f);  // mean, std, max and the order statistics; checks f finite
  std::vector<double> a(n), b(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(f[i] > 0) || !(K[i] > 0) || !std::isfinite(K[i]) || !(alpha[i] > 0) || !std::isfinite(alpha[i]))
      FFSR_THROW(InputError(detail::str("summarize_stiffness_conditional: sample ", i, " has F_max ", f[i], ", K ",
                                   K[i], ", alpha ", alpha[i], " (all must be positive and finite)")));
    a[i] = alpha[i] + 1.0;
    b[i] = std::log(K[i]) - a[i] * std::log(f[i]);
  }
  const ConditionalCdf C{a, b, law};
  s.estimator = ForceSummary::Estimator::StiffnessConditional;
  s.p50 = std::exp(conditional_quantile(C, 0.50, std::log(s.order.p50)));
  const double t95 = conditional_quantile(C, 0.95, std::log(s.order.p95));
  s.p95 = std::exp(t95);
  s.p99 = std::exp(conditional_quantile(C, 0.99, std::log(s.order.p99)));
  // delta method: Var(t^) ~ Var(P_K,i(t)) / (n C'(t)^2)
  s.p95_ci = {};
  s.p95_ci.coverage = 0.95;
  if (n >= 2) {
    ConditionalAtP95 local;
    ConditionalAtP95& st = at ? *at : local;
    st.h.resize(n);
    std::tie(st.c, st.d) = C(t95, &st.h);
    double var = 0;
    for (double x : st.h) var += (x - st.c) * (x - st.c);
    var /= static_cast<double>(n - 1);
    if (st.d > 0) {
      const double se = std::sqrt(var / static_cast<double>(n)) / st.d;
      s.p95_ci.log_standard_error = se;
      s.p95_ci.lo = std::exp(t95 - kZ975 * se);
      s.p95_ci.hi = std::exp(t95 + kZ975 * se);
      s.p95_ci.has_lo = s.p95_ci.has_hi = true;
    }
  }
  return s;
}

}  // namespace detail

inline ForceSummary summarize_stiffness_conditional(const std::vector<double>& f,
                                                    const std::vector<double>& K,
                                                    const std::vector<double>& alpha, const Spread& stiffness,
                                                    double K0) {
  return detail::conditional_summary(f, K, alpha, stiffness, K0, nullptr);
}

inline PercentileRatio compare_p95_stiffness_conditional(const std::vector<double>& f_a,
                                                         const std::vector<double>& f_b,
                                                         const std::vector<double>& K,
                                                         const std::vector<double>& alpha,
                                                         const Spread& stiffness, double K0) {
  const std::size_t n = f_a.size();
  if (f_b.size() != n)
    FFSR_THROW(InputError(detail::str("compare_p95_stiffness_conditional: ", n, " and ", f_b.size(),
                                 " forces: the two configurations must share the samples")));
  detail::ConditionalAtP95 A, B;
  const double pa = detail::conditional_summary(f_a, K, alpha, stiffness, K0, &A).p95;
  const double pb = detail::conditional_summary(f_b, K, alpha, stiffness, K0, &B).p95;
  PercentileRatio r;
  r.ratio = pb / pa;
  if (n < 2 || !(A.d > 0) || !(B.d > 0)) return r;
  // psi_i has mean zero: C is the mean of the h_i
  double var = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double psi = (A.h[i] - A.c) / A.d - (B.h[i] - B.c) / B.d;
    var += psi * psi;
  }
  var /= static_cast<double>(n - 1);
  r.log_standard_error = std::sqrt(var / static_cast<double>(n));
  r.lo = r.ratio * std::exp(-detail::kZ975 * r.log_standard_error);
  r.hi = r.ratio * std::exp(detail::kZ975 * r.log_standard_error);
  r.has_interval = true;
  return r;
}

inline double robust_force_p95(const Model& model, Data& data, const BasePose& base,
                               const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                               const std::vector<UncertainSample>& samples, std::string_view law) {
  if (samples.empty()) FFSR_THROW(InputError("robust_force_p95: no samples"));
  const Matrix6 Linv = robot_inverse_inertia(model, data, base, theta, frame);
  std::vector<double> f(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i)
    f[i] = sample_force(Linv, samples[i], law, ForceModel::Exact).f_max;
  std::sort(f.begin(), f.end());
  return nearest_rank(f, 95);
}

}  // namespace ffsr
