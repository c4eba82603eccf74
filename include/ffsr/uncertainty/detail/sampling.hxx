// ffsr/uncertainty/detail/sampling.hxx -- bodies of ffsr/uncertainty/sampling.hpp.
#pragma once

#include <exception>
#include <iomanip>
#include <sstream>
#include <mutex>

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

inline double draw_scalar(const Spread& sp, Quantity q, double x0, SampleStream& rng, int& redraws, double& score) {
  if (sp.law == Spread::Law::Fixed) {
    score = 0;
    return x0;
  }
  const double s = sp.relative ? sp.scale * std::abs(x0) : sp.scale;
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
  throw NumericalError(str(quantity_key(q), ": no physical value within the bounds in ", kMaxRedraws,
                           " draws (the law puts almost no probability there)"));
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

inline Matrix3 draw_inertia(const Spread& sp, const Matrix3& I0, SampleStream& rng, int& redraws, double& score) {
  score = 0;
  if (sp.law == Spread::Law::Fixed) return I0;
  const Eigen::SelfAdjointEigenSolver<Matrix3> es(I0);
  const Vector3 l0 = es.eigenvalues();
  const Matrix3 V = es.eigenvectors();
  for (int k = 0; k < kMaxRedraws; ++k) {
    Vector3 e;
    for (int i = 0; i < 3; ++i) e(i) = sp.law == Spread::Law::Normal ? sp.scale * rng.normal() : sp.scale * (2.0 * rng.uniform() - 1.0);
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
  throw NumericalError(str(quantity_key(Quantity::TargetInertia), ": no principal moments satisfying the triangle inequality in ",
                           kMaxRedraws, " draws (spread too large)"));
}

inline Vector3 draw_normal(const Spread& sp, const Vector3& n0, SampleStream& rng, double& score) {
  score = 0;
  const Vector3 n = n0.normalized();
  if (sp.law == Spread::Law::Fixed || sp.scale == 0.0) return n;
  const Vector3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  const double cos_a = std::cos(sp.scale);
  const double ct = 1.0 - rng.uniform() * (1.0 - cos_a);  // uniform on the cap
  const double st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
  double c, s;
  rng.unit_circle(c, s);
  score = std::acos(std::clamp(ct, -1.0, 1.0)) / sp.scale;
  return (ct * n + st * (c * e1 + s * e2)).normalized();
}

}  // namespace detail

inline void validate(const UncertaintySpec& spec) {
  using detail::short_number;
  using detail::str;
  if (spec.samples < 1) throw InputError("uncertainty.samples: must be at least 1, got 0");
  for (std::size_t i = 0; i < kNumQuantities; ++i) {
    const Quantity q = static_cast<Quantity>(i);
    const Spread& sp = spec.spread[i];
    const std::string key = detail::quantity_key(q);
    if (sp.law == Spread::Law::Fixed) continue;
    if (!std::isfinite(sp.scale) || sp.scale < 0)
      throw InputError(str(key, ": the spread must be a non-negative finite number, got ", short_number(sp.scale)));
    if (std::isnan(sp.min) || std::isnan(sp.max) || sp.min > sp.max)
      throw InputError(str(key, ": min (", short_number(sp.min), ") is greater than max (", short_number(sp.max), ")"));
    if (sp.has_range && (!std::isfinite(sp.min) || !std::isfinite(sp.max)))
      throw InputError(str(key, ": a uniform law needs finite min and max"));
    if (q == Quantity::Normal) {
      if (sp.law != Spread::Law::Cone) throw InputError(str(key, ": the normal takes the law 'cone' (angle-deg)"));
      if (sp.scale > M_PI / 2 * (1 + 1e-15))
        throw InputError(str(key, ": the cone half-angle must be at most 90 deg, got ", short_number(sp.scale * 180 / M_PI), " deg"));
      continue;
    }
    if (sp.law == Spread::Law::Cone) throw InputError(str(key, ": the law 'cone' is for the normal only"));
    if (q == Quantity::TargetInertia) {
      if (sp.law != Spread::Law::Normal && sp.law != Spread::Law::Uniform)
        throw InputError(str(key, ": the inertia takes a 'normal' or 'uniform' law with a relative spread"));
      if (!(sp.axes >= 0 && sp.axes <= M_PI))
        throw InputError(str(key, ": axes-deg must be in [0, 180], got ", short_number(sp.axes * 180 / M_PI)));
      if (sp.scale >= 1.0 && sp.law == Spread::Law::Uniform)
        throw InputError(str(key, ": a relative half-width of ", short_number(sp.scale), " allows non-positive moments (must be < 1)"));
      continue;
    }
    if (detail::is_vector_quantity(q)) {
      if (sp.law == Spread::Law::LogNormal) throw InputError(str(key, ": a vector takes a 'normal' or 'uniform' law"));
      if (sp.relative || sp.has_range)
        throw InputError(str(key, ": a vector takes an absolute spread (std or half-width), not relative or min/max"));
    }
  }
}

inline UncertainSample draw_sample(const UncertaintySpec& spec, const UncertainNominal& nominal, std::uint64_t index) {
  using Q = Quantity;
  SampleStream rng(spec.seed, index);
  UncertainSample s;
  s.index = index;
  auto sc = [&s](Q q) -> double& { return s.score[static_cast<std::size_t>(q)]; };
  const Target& t0 = nominal.target;
  const Matrix3 R = t0.rotation();
  for (int attempt = 0; attempt < kMaxRedraws; ++attempt) {
    s.target = t0;
    s.target.mass = detail::draw_scalar(spec[Q::TargetMass], Q::TargetMass, t0.mass, rng, s.redraws, sc(Q::TargetMass));
    s.target.inertia = detail::draw_inertia(spec[Q::TargetInertia], t0.inertia, rng, s.redraws, sc(Q::TargetInertia));
    s.target.contact_offset = t0.contact_offset + detail::draw_offset(spec[Q::ContactOffset], rng, sc(Q::ContactOffset));
    s.target.normal = detail::draw_normal(spec[Q::Normal], t0.normal, rng, sc(Q::Normal));
    s.target.angular_velocity = t0.angular_velocity + detail::draw_offset(spec[Q::Spin], rng, sc(Q::Spin));
    s.target.velocity = t0.velocity + detail::draw_offset(spec[Q::TargetVelocity], rng, sc(Q::TargetVelocity));
    s.approach_speed = detail::draw_scalar(spec[Q::ApproachSpeed], Q::ApproachSpeed, nominal.approach_speed, rng,
                                           s.redraws, sc(Q::ApproachSpeed));
    s.contact.K = detail::draw_scalar(spec[Q::Stiffness], Q::Stiffness, nominal.contact.K, rng, s.redraws, sc(Q::Stiffness));
    s.contact.c_r = detail::draw_scalar(spec[Q::Restitution], Q::Restitution, nominal.contact.c_r, rng, s.redraws,
                                        sc(Q::Restitution));
    s.contact.alpha = detail::draw_scalar(spec[Q::Exponent], Q::Exponent, nominal.contact.alpha, rng, s.redraws,
                                          sc(Q::Exponent));
    // drawn last, so that the streams of the other quantities do not depend on whether it is set
    const Vector3 d = detail::draw_offset(spec[Q::ContactPoint], rng, sc(Q::ContactPoint));
    s.target.contact_offset += d;
    s.robot_offset = R * d;
    s.normal_world = R * s.target.normal;
    s.wrench << s.normal_world, s.robot_offset.cross(s.normal_world);
    const Vector3 r = R * s.target.contact_offset;
    s.approach_velocity = s.approach_speed - s.normal_world.dot(s.target.velocity + (R * s.target.angular_velocity).cross(r));
    if (s.approach_velocity > 0) {
      s.target_inverse_mass = s.target.inverse_mass_along_normal();
      return s;
    }
    ++s.redraws;  // the bodies would not approach: redraw the whole sample
  }
  throw NumericalError(detail::str("uncertainty: sample ", index, " has the bodies receding (delta_dot^- <= 0) in ",
                                   kMaxRedraws, " draws; increase the approach speed or narrow the spin/velocity spreads"));
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

inline SampleForce sample_force(const Matrix6& Linv, const UncertainSample& s, std::string_view law, ForceModel model) {
  SampleForce f;
  f.M_ie = 1.0 / (s.wrench.dot(Linv * s.wrench) + s.target_inverse_mass);
  f.approach_velocity = s.approach_velocity;
  const AnyContactLaw l = make_contact_law(law, s.contact, s.approach_velocity);
  if (model == ForceModel::Closed) f.f_max = max_force_closed_form(l, f.M_ie);
  else if (model == ForceModel::Exact) f.f_max = max_force_exact(l, f.M_ie);
  else throw InputError("sample_force: the multibody force model is in ffsr/uncertainty/multibody.hpp");
  return f;
}

inline double nearest_rank(const std::vector<double>& sorted, int percent) {
  const std::size_t n = sorted.size();
  if (n == 0) throw InputError("nearest_rank: no values");
  if (percent < 1 || percent > 100) throw InputError(detail::str("nearest_rank: percent must be in [1, 100], got ", percent));
  const std::size_t rank = (static_cast<std::size_t>(percent) * n + 99) / 100;  // ceil(p n / 100) >= 1
  return sorted[rank - 1];
}

inline QuantileRanks quantile_interval(std::size_t n, double q, double confidence) {
  if (n == 0) throw InputError("quantile_interval: no values");
  if (!(q > 0 && q < 1)) throw InputError(detail::str("quantile_interval: q must be in (0, 1), got ", q));
  if (!(confidence > 0 && confidence < 1))
    throw InputError(detail::str("quantile_interval: confidence must be in (0, 1), got ", confidence));
  const double nd = static_cast<double>(n), sd = std::sqrt(nd * q * (1 - q));
  // the binomial mass outside [k0, k1] is below 1e-300: the CDF starts at 0 at k0
  const auto k0 = static_cast<std::size_t>(std::max(0.0, std::floor(nd * q - 40 * sd - 40)));
  const auto k1 = static_cast<std::size_t>(std::min(nd, std::ceil(nd * q + 40 * sd + 40)));
  const double alpha = 0.5 * (1 - confidence), lnq = std::log(q), lnp = std::log1p(-q), lg = std::lgamma(nd + 1);
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
  if (s.n == 0) throw InputError("summarize: no values");
  double sum = 0;
  for (double x : v) {
    if (!std::isfinite(x)) throw NumericalError(detail::str("summarize: a value is not finite (", x, ")"));
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
  if (ci.lower) s.p95_ci.lo = sorted[ci.lower - 1];
  if (ci.upper) s.p95_ci.hi = sorted[ci.upper - 1];
  return s;
}

inline void parallel_for(std::uint64_t begin, std::uint64_t end, int threads, const std::function<void(std::uint64_t)>& f,
                         const std::function<void(std::uint64_t)>& progress) {
  if (end <= begin) return;
  std::atomic<std::uint64_t> next{begin}, done{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::exception_ptr error;
  std::uint64_t error_index = end;
  auto work = [&] {
    for (;;) {
      const std::uint64_t i = next.fetch_add(1);
      if (i >= end || stop.load()) return;
      try {
        f(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (i < error_index) {
          error_index = i;
          error = std::current_exception();
        }
        stop = true;
      }
      done.fetch_add(1);
    }
  };
  const int nt = std::max(1, threads);
  if (nt == 1 && !progress) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (int k = 0; k < nt; ++k) pool.emplace_back(work);
    if (progress) {
      while (done.load() < end - begin && !stop.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        progress(done.load());
      }
    }
    for (auto& t : pool) t.join();
    if (progress && !error) progress(done.load());
  }
  if (error) std::rethrow_exception(error);
}

inline double robust_force_p95(const Model& model, Data& data, const BasePose& base,
                               const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                               const std::vector<UncertainSample>& samples, std::string_view law) {
  if (samples.empty()) throw InputError("robust_force_p95: no samples");
  const Matrix6 Linv = robot_inverse_inertia(model, data, base, theta, frame);
  std::vector<double> f(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) f[i] = sample_force(Linv, samples[i], law, ForceModel::Exact).f_max;
  std::sort(f.begin(), f.end());
  return nearest_rank(f, 95);
}

}  // namespace ffsr
