// ffsr/uncertainty/sampling.hpp -- uncertain targets: distributions of the target and contact
// quantities, a reproducible sampler, and the maximum contact force per sample (Eigen only).
#pragma once

#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/model/target.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

namespace ffsr {

// What is uncertain. The capture configuration (joint angles and base pose at the capture time T)
// is planned for the nominal target; what is not known is the target as it is met at T and the
// contact. A sample is the target at the capture -- its mass, inertia, contact offset r_tp, normal
// u_n, spin omega_t (target frame), linear velocity v_t -- and the contact: where the bodies touch,
// approach speed, stiffness K, restitution c_r, exponent alpha. The target's attitude at T is the
// nominal one (propagated from t = 0 by the planner), so u = R_t u_n and r = R_t r_tp change
// through u_n and r_tp only.

/// The uncertain quantities, in the order they are drawn.
enum class Quantity {
  TargetMass,
  TargetInertia,
  ContactOffset,
  Normal,
  Spin,
  TargetVelocity,
  ApproachSpeed,
  Stiffness,
  Restitution,
  Exponent,
  ContactPoint
};
inline constexpr std::size_t kNumQuantities = 11;
/// Scenario keys of the quantities ([uncertainty] table), in the order of Quantity.
inline constexpr std::array<std::string_view, kNumQuantities> kQuantityNames{
    "target-mass",    "target-inertia", "contact-offset", "normal",   "spin",         "target-velocity",
    "approach-speed", "stiffness",      "restitution",    "exponent", "contact-point"};

// The laws (Spread), with x0 the nominal value:
//   normal      x = x0 + s z          s = std, or relative-std |x0|   z ~ N(0, 1)
//   uniform     x ~ U[min, max], or U[x0 - h, x0 + h] with h = half-width, or relative |x0|
//   log-normal  x = x0 exp(sigma z)   (median x0; the law for K, which is known to a decade)
//   cone        the normal u_n: uniform on the spherical cap of half-angle a <= 90 deg about the
//               nominal normal (cos of the angle uniform in [cos a, 1], azimuth uniform)
// Any scalar law may carry bounds `min`/`max` (a bounded law: values outside are redrawn, i.e. the
// law is truncated). Vectors (contact offset, contact point, spin, velocity) take normal or uniform laws per
// component, added to the nominal vector, with absolute spreads. The inertia takes a relative
// spread of its principal moments (each scaled by 1 + e, e normal or uniform) and, optionally, a
// rotation of its principal axes by an angle uniform in [0, axes] about a uniformly random axis.

/// The law of one uncertain quantity (the laws above). Units are the quantity's own, SI,
/// except `spin` (rad/s here; the CLI takes deg/s) and the angles (rad).
struct Spread {
  enum class Law { Fixed, Normal, Uniform, LogNormal, Cone };
  Law law = Law::Fixed;
  double scale = 0;        ///< normal: std; uniform: half-width; log-normal: sigma; cone: half-angle (rad)
  bool relative = false;   ///< normal/uniform: scale is a fraction of |x0| (inertia: always relative)
  bool has_range = false;  ///< uniform: support [min, max] (absolute) instead of x0 +- scale
  double min = -std::numeric_limits<double>::infinity();  ///< bounds (all scalar laws): redraw outside
  double max = std::numeric_limits<double>::infinity();
  double axes = 0;  ///< inertia: largest rotation of the principal axes (rad)
};

/// One [uncertainty] entry per quantity (Fixed: not uncertain) plus the sample count and the seed.
struct UncertaintySpec {
  std::array<Spread, kNumQuantities> spread{};
  std::uint64_t samples = 1000;
  std::uint64_t seed = 1;
  Spread& operator[](Quantity q) { return spread[static_cast<std::size_t>(q)]; }
  const Spread& operator[](Quantity q) const { return spread[static_cast<std::size_t>(q)]; }
};

/// Throws InputError naming the quantity (`uncertainty.<name>`) for a spread that cannot be drawn:
/// negative or non-finite scale, min > max, a cone over 90 deg, a law that does not fit the
/// quantity (cone for a scalar, log-normal for a vector, ...), samples < 1.
inline void validate(const UncertaintySpec& spec);

/// The nominal quantities: the target at the capture time (attitude included), the contact
/// parameters and the approach speed.
struct UncertainNominal {
  Target target;
  ContactParams contact;
  double approach_speed = 0.2;
};

/// A drawn sample. `target` is the target at the capture (nominal attitude). `score` says how
/// extreme each quantity was: (x - x0)/std for normal laws, ln(x/x0)/sigma for log-normal, the
/// position in the support scaled to [-1, 1] for uniform laws, |dx|/std (or /half-width) for
/// vectors, angle/half-angle for the cone, the largest |e|/spread for the inertia; 0 if fixed.
struct UncertainSample {
  std::uint64_t index = 0;
  Target target;
  ContactParams contact;
  double approach_speed = 0;
  Vector3 normal_world = Vector3::UnitX();  ///< u = R_t u_n
  Vector3 robot_offset = Vector3::Zero();   ///< rho: the robot's contact point is p_e + rho (inertial frame)
  Vector6 wrench =
      (Vector6() << 1, 0, 0, 0, 0, 0).finished();  ///< s = [u; rho x u]: a unit force along u at p_e + rho
  double approach_velocity = 0;                    ///< delta_dot^- (Eq. 10-12)
  double target_inverse_mass = 0;                  ///< 1/m_t + (r x u)^T I^-1 (r x u), target frame
  int redraws = 0;                                 ///< redrawn quantities and samples (physical rules)
  std::array<double, kNumQuantities> score{};
};

// Physical or redrawn -- the redraw rule of every quantity (a sample that breaks one rule draws
// that quantity again from the same sample stream, at most kMaxRedraws times, then NumericalError):
//   target-mass     m_t > 0 (and within min/max)
//   target-inertia  principal moments > 0 and the triangle inequality I_max <= I_mid + I_min
//   normal          unit by construction (renormalized), within the cone
//   approach-speed  v_a > 0;  stiffness K > 0;  exponent alpha > 0;  restitution 0 < c_r <= 1
//   the sample      delta_dot^- > 0 (the bodies approach): otherwise the whole sample is redrawn
//                   (it depends on the target attitude only, not on the configuration, so the
//                   sample set stays common to all configurations)
inline constexpr int kMaxRedraws = 1000;

namespace detail {

/// SplitMix64 (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

}  // namespace detail

// Reproducible randomness. Sample i uses its own std::mt19937_64 seeded with
// splitmix64(seed + splitmix64(i)), so it depends on (seed, i) only: shards, threads and
// configurations draw the same numbers (common random numbers). mt19937_64 and its seeding are
// fully specified by the C++ standard; the uniform and normal transforms are ours (53-bit
// uniforms; Marsaglia's polar method; azimuths by rejection in the unit disc), because the
// std:: distributions are implementation-defined. Only std::log, std::exp and std::sqrt are used
// on the draws (sqrt is exact in IEEE 754; log and exp of a quality libm agree to the last bit on
// the platforms we know, not by a guarantee).

/// The random stream of sample `index`: mt19937_64 seeded from (seed, index) only, with our own
/// transforms (same numbers on every platform, see above).
class SampleStream {
 public:
  SampleStream(std::uint64_t seed, std::uint64_t index)
      : engine_(detail::splitmix64(seed + detail::splitmix64(index))) {}
  /// Uniform in [0, 1): the top 53 bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Standard normal, Marsaglia's polar method (the second variate is discarded, so that a draw is
  /// a function of the stream position alone).
  double normal() {
    for (;;) {
      const double a = 2.0 * uniform() - 1.0, b = 2.0 * uniform() - 1.0;
      const double s = a * a + b * b;
      if (s > 0.0 && s < 1.0) return a * std::sqrt(-2.0 * std::log(s) / s);
    }
  }
  /// A uniformly distributed unit 2-vector (cos, sin), by rejection in the unit disc.
  void unit_circle(double& c, double& s) {
    for (;;) {
      const double a = 2.0 * uniform() - 1.0, b = 2.0 * uniform() - 1.0;
      const double r2 = a * a + b * b;
      if (r2 > 1e-12 && r2 < 1.0) {
        const double r = std::sqrt(r2);
        c = a / r;
        s = b / r;
        return;
      }
    }
  }
  /// A uniformly distributed unit 3-vector.
  Vector3 unit_sphere() {
    const double z = 2.0 * uniform() - 1.0;
    double c = 0, s = 0;
    unit_circle(c, s);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * c, r * s, z};
  }

 private:
  std::mt19937_64 engine_;
};

/// Draws the sample `index` of `spec` around `nominal` (the laws at Spread, the redraw rules at
/// kMaxRedraws). Reads spec, nominal. Pure: the same (spec, nominal, index) gives the same
/// sample. NumericalError when a rule still fails after kMaxRedraws draws.
inline UncertainSample draw_sample(const UncertaintySpec& spec, const UncertainNominal& nominal,
                                   std::uint64_t index);

/// G = J_v H^-1 J_v^T, the robot's 3x3 inverse mass matrix at the origin of `frame` (its quadratic
/// form u^T G u is the denominator of Eq. 4), from six calls of inverse_effective_mass by
/// polarization. Runs crba. Writes data.
inline Matrix3 robot_inverse_mass_matrix(const Model& model, Data& data, const BasePose& base,
                                         const Eigen::Ref<const Eigen::VectorXd>& theta, int frame);

/// The robot's 6x6 inverse inertia Lambda^-1 = J H^-1 J^T at the origin of `frame`
/// (effective_mass_gradient.hpp, inverse_inertia_matrix): a sample's robot-side inverse effective mass is
/// s^T Lambda^-1 s with s = UncertainSample::wrench (its top-left block is G). Runs crba. Writes data.
inline Matrix6 robot_inverse_inertia(const Model& model, Data& data, const BasePose& base,
                                     const Eigen::Ref<const Eigen::VectorXd>& theta, int frame);

// Two quantities move the contact point, and they differ in what they move:
//   contact-offset  e: the lever arm r_tp + e from the target's centre of mass to the contact point
//                   (the centre of mass is not where it was estimated); the point where the bodies
//                   touch is the planned one, the end-effector's point p_e.
//   contact-point   d: the point where the bodies touch is displaced by d (target frame) from the
//                   planned one -- the grasp feature is not where it was seen, so it meets another
//                   point of the end-effector's contact surface. Both bodies see it: the lever arm is
//                   r_tp + d and the robot is struck at p_e + rho, rho = R_t d. The robot's inverse
//                   effective mass there is s^T Lambda^-1 s with s = [u; rho x u] and Lambda^-1 =
//                   J H^-1 J^T its 6x6 inverse inertia at p_e: the end-effector's rotational
//                   compliance enters, which depends on the configuration (the nominal M_ie does not
//                   see it).
// Per sample (Eq. 10-14, 20-25):
//   M_ie = 1 / (s^T Lambda^-1 s + 1/m_t + (r_tp x u_n)^T I_t^-1 (r_tp x u_n)),  s = [u; rho x u]
//          (rho = 0 without contact-point: s^T Lambda^-1 s = u^T G u, G = J_v H^-1 J_v^T),
//   delta_dot^- = v_a - u . (v_t + omega x r)   (the robot's contact point moves at v_a along u,
//                                                Eq. 10-12),
//   F_max = closed form (Eq. 24) or the exact peak of Eq. 16, or a multibody CVODE run
//   (uncertainty/multibody.hpp).
// Lambda^-1 is a property of the configuration, computed once (robot_inverse_inertia); a sample
// then costs a 6-vector quadratic form and the peak of Eq. 16 -- 1e5 samples take well under a
// second.

/// How F_max is computed per sample: Eq. 24 (closed), the exact peak of Eq. 16 (exact), or the
/// multibody CVODE reference (uncertainty/multibody.hpp; not available from this header).
enum class ForceModel { Closed, Exact, Multibody };

/// M_ie, delta_dot^- and F_max of one sample for a configuration with inverse inertia Lambda^-1
/// (robot_inverse_inertia; closed or exact force model). `law` names the damping law (Table 1).
struct SampleForce {
  double M_ie = 0, approach_velocity = 0, f_max = 0;
};
inline SampleForce sample_force(const Matrix6& Linv, const UncertainSample& s, std::string_view law,
                                ForceModel model);

/// Summary of F_max over a sample set: mean, standard deviation (n - 1), the 50th, 95th and 99th
/// percentiles and the maximum. The mean, deviation and maximum are those of the sample. The
/// percentiles come from one of two estimators:
///  - OrderStatistics (summarize): nearest rank, the p-th percentile is the ceil(p n)-th smallest value;
///  - StiffnessConditional (summarize_stiffness_conditional): the percentiles of the mixture of the
///    samples' laws of F_max given everything but the stiffness (see there); much less scatter when
///    K is uncertain, and the same law.
/// `order` always holds the order statistics. Sums run in the order given (callers pass the values
/// by sample index), so a merged set of shards gives the same digits as one run.
struct ForceSummary {
  enum class Estimator { OrderStatistics, StiffnessConditional };
  std::size_t n = 0;
  double mean = 0, std = 0, p50 = 0, p95 = 0, p99 = 0, max = 0;
  Estimator estimator = Estimator::OrderStatistics;
  /// 95 % confidence interval of the 95th percentile of the law (not of the sample).
  ///  OrderStatistics: the order statistics of ranks `lower` and `upper` (quantile_interval),
  ///    distribution-free; a bound whose rank would be outside 1..n does not exist (has_lo/has_hi
  ///    false, value 0) -- no upper bound below n = 72.
  ///  StiffnessConditional: p95 exp(-+1.96 se), se the delta-method standard error of ln p95
  ///    (asymptotic; ranks 0, coverage 0.95 nominal); none for n < 2.
  struct Interval {
    std::size_t lower = 0, upper = 0;  ///< 1-based ranks (order statistics), 0: none
    double lo = 0, hi = 0;             ///< the bounds
    bool has_lo = false, has_hi = false;
    double coverage = 0;            ///< P(lo <= true p95 < hi) (order statistics: >= 0.95 when both exist)
    double log_standard_error = 0;  ///< StiffnessConditional: the standard error of ln p95
  } p95_ci;
  /// The order statistics of the sample, whatever the estimator.
  struct Order {
    double p50 = 0, p95 = 0, p99 = 0;
    Interval p95_ci;
  } order;
};
inline ForceSummary summarize(const std::vector<double>& values_by_index);

/// The law of a scalar quantity exactly as draw_sample draws it -- the law of `sp` about the nominal
/// x0, truncated to its bounds min/max and to the quantity's physical rule (the redraws) -- at x:
/// its CDF and its density. InputError for a Fixed law, a vector quantity, or a degenerate spread
/// (zero scale: no density); NumericalError when the truncation leaves no probability.
struct LawPoint {
  double cdf = 0, density = 0;
};
inline LawPoint scalar_law(const Spread& sp, Quantity q, double x0, double x);

/// Whether summarize_stiffness_conditional applies: the single-body force models (closed, exact)
/// and a stiffness with a non-degenerate law.
inline bool stiffness_conditional_applies(ForceModel model, const Spread& stiffness);

/// Percentiles of F_max conditional on the stiffness (a Rao-Blackwellized estimator).
///
/// The single-body models scale exactly with K: in the dimensionless form of Eq. 19 (contact_law.hpp)
/// the peak is at a rate s* that depends on f(c_r) and alpha only, and
///     F_max = K^(1/(alpha+1)) [M_ie (alpha+1) delta_dot^-2 G(s*)]^(alpha/(alpha+1)) (1 + f s*),
/// and Eq. 24 scales the same way. So sample i, drawn with stiffness K_i and exponent alpha_i, gives
/// F_max = c_i K^(1/(alpha_i+1)) for any K, c_i = F_i / K_i^(1/(alpha_i+1)). K is drawn independently
/// of the other quantities (and the whole-sample redraw, delta_dot^- <= 0, does not involve it), so
///     P(F_max <= q | sample i without K) = P_K(K <= (q / c_i)^(alpha_i+1)),
/// and the CDF estimate C(q) = mean_i P_K(K <= (q/F_i)^(alpha_i+1) K_i) is unbiased for the law's
/// CDF, with less variance than the fraction of samples below q (it averages over K instead of
/// drawing it). The p-quantile solves C(q) = p (safeguarded Newton in ln q, from the order statistic);
/// it converges to the same law's quantile. On the 7-DOF example the 95th percentile from 1000
/// samples scatters by 0.3-0.4 % instead of 1.6-1.8 % (bench/bench_robust.cpp).
/// `stiffness` is the law of K about its nominal K0 (scalar_law); f, K, alpha are per sample, by
/// index. InputError for mismatched sizes, a degenerate law, or a non-positive or non-finite value.
inline ForceSummary summarize_stiffness_conditional(const std::vector<double>& f_by_index,
                                                    const std::vector<double>& K_by_index,
                                                    const std::vector<double>& alpha_by_index,
                                                    const Spread& stiffness, double K0);

/// Two configurations on the same samples (common random numbers): the ratio of their
/// stiffness-conditional 95th percentiles, p95(b) / p95(a), with a paired 95 % interval.
/// Delta method on the pair: each estimate t = ln p95 solves C(t) = 0.95 and moves by
/// -(C^(t) - 0.95) / C'(t), so t_b - t_a has the per-sample influence
///     psi_i = (P_a,i(t_a) - C_a) / C_a' - (P_b,i(t_b) - C_b) / C_b'
/// (P_i the sample's conditional CDF, summarize_stiffness_conditional), and Var(t_b - t_a) ~ Var(psi) / n.
/// The samples are shared, so what moves both estimates alike cancels: the paired interval is much
/// narrower than the two single intervals together when the configurations see the samples alike.
/// Arguments as summarize_stiffness_conditional, with f_a and f_b by index on the same samples;
/// InputError for mismatched sizes and the inputs it refuses. No interval for n < 2.
struct PercentileRatio {
  double ratio = 1;       ///< p95(b) / p95(a)
  double lo = 0, hi = 0;  ///< its 95 % interval (paired delta method)
  bool has_interval = false;
  double log_standard_error = 0;  ///< of ln ratio
};
inline PercentileRatio compare_p95_stiffness_conditional(const std::vector<double>& f_a_by_index,
                                                         const std::vector<double>& f_b_by_index,
                                                         const std::vector<double>& K_by_index,
                                                         const std::vector<double>& alpha_by_index,
                                                         const Spread& stiffness, double K0);

/// A distribution-free confidence interval of the q-quantile xi_q of a continuous law from n
/// independent draws: with B ~ Binomial(n, q) the number of draws below xi_q, the order statistics
/// X_(l) and X_(u) bracket it, P(X_(l) <= xi_q < X_(u)) = P(l <= B <= u - 1). l is the largest rank
/// with P(B <= l - 1) <= (1 - confidence)/2 and u the smallest with P(B <= u - 1) >=
/// (1 + confidence)/2 (binomial terms from lgamma), so the coverage is at least `confidence`; a rank
/// outside 1..n is returned as 0 (no bound: too few samples, e.g. no upper bound of p95 at 95 % below n = 72).
struct QuantileRanks {
  std::size_t lower = 0, upper = 0;
  double coverage = 0;  ///< P(l <= B <= u - 1) with the missing bounds taken as 0 and n + 1
};
inline QuantileRanks quantile_interval(std::size_t n, double q, double confidence = 0.95);

/// The nearest-rank percentile of `sorted` (ascending): the ceil(percent n / 100)-th smallest value,
/// in integer arithmetic (no rounding question at p n = integer). percent in [1, 100].
inline double nearest_rank(const std::vector<double>& sorted, int percent);

/// The robust objective: the 95th percentile (nearest rank) of the exact F_max over a fixed sample
/// set, for the capture configuration (base, theta). Cost: one crba and the samples' peaks.
/// A search that calls it with the same samples compares configurations on common random numbers.
inline double robust_force_p95(const Model& model, Data& data, const BasePose& base,
                               const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                               const std::vector<UncertainSample>& samples, std::string_view law);

}  // namespace ffsr

#include "ffsr/uncertainty/detail/sampling.hxx"
