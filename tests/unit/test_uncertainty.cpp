// Uncertain targets (uncertainty/): the reproducible sampler, the laws and their physical redraw rules,
// the per-sample M_ie / F_max against the library's direct computations, the summary statistics,
// and the multibody force of a sample against simulate_contact.
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/detail/parallel.hpp"
#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/uncertainty/multibody.hpp"
#include "ffsr/uncertainty/robust_objective.hpp"
#include "ffsr/uncertainty/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace test_uncertainty {

using namespace ffsr;
using ffsr::test::deg;
using ffsr::test::kRobots;

namespace {

UncertainNominal paper_nominal() {
  UncertainNominal n;  // the paper's target (Table 2 defaults of Target) and contact
  n.target.angular_velocity = Vector3(0, 0, 2.0 * M_PI / 180.0);
  n.target.attitude = Quaternion(Eigen::AngleAxisd(0.3, Vector3(1, 2, 3).normalized()));
  n.contact = {1e9, 1.5, 0.9};
  n.approach_speed = 0.2;
  return n;
}

Spread law(Spread::Law l, double scale, bool relative = false) {
  Spread s;
  s.law = l;
  s.scale = scale;
  s.relative = relative;
  return s;
}

/// A uniform law on [min, max] (the example scenario's c_r).
Spread uniform_range(double min, double max) {
  Spread s = law(Spread::Law::Uniform, 0.0);
  s.has_range = true;
  s.min = min;
  s.max = max;
  return s;
}

}  // namespace

TEST_CASE("sampler: splitmix64 test vector, mt19937_64 stream, sample i depends on (seed, i) only",
          "[uncertainty]") {
  // SplitMix64 reference output for state 0 (Steele et al. 2014; the first output of the generator).
  CHECK(detail::splitmix64(0) == 0xE220A8397B1DCDAFULL);
  // our uniform is the top 53 bits of the standard engine seeded from (seed, i)
  std::mt19937_64 ref(detail::splitmix64(7 + detail::splitmix64(42)));
  SampleStream s(7, 42);
  for (int k = 0; k < 5; ++k) CHECK(s.uniform() == static_cast<double>(ref() >> 11) / 9007199254740992.0);

  UncertaintySpec spec;
  spec.seed = 99;
  spec[Quantity::TargetMass] = law(Spread::Law::Normal, 0.1, true);
  spec[Quantity::Stiffness] = law(Spread::Law::LogNormal, 0.5);
  const UncertainNominal nom = paper_nominal();
  const UncertainSample a = draw_sample(spec, nom, 123), b = draw_sample(spec, nom, 123),
                        c = draw_sample(spec, nom, 124);
  CHECK(a.target.mass == b.target.mass);
  CHECK(a.contact.K == b.contact.K);
  CHECK(a.target.mass != c.target.mass);
  spec.seed = 100;
  CHECK(draw_sample(spec, nom, 123).target.mass != a.target.mass);
}

TEST_CASE("laws: moments of normal, uniform, log-normal and the cone within 5 standard errors",
          "[uncertainty]") {
  UncertaintySpec spec;
  spec.seed = 3;
  spec[Quantity::TargetMass] = law(Spread::Law::Normal, 0.1, true);  // 200 kg +- 20 kg
  spec[Quantity::ApproachSpeed] = law(Spread::Law::Uniform, 0.05);   // U[0.15, 0.25]
  spec[Quantity::Stiffness] = law(Spread::Law::LogNormal, 0.6);      // median 1e9
  spec[Quantity::Normal] = law(Spread::Law::Cone, 30 * M_PI / 180);
  spec[Quantity::ContactOffset] = law(Spread::Law::Normal, 0.02);
  REQUIRE_NOTHROW(validate(spec));
  const UncertainNominal nom = paper_nominal();
  const int N = 20000;
  double m1 = 0, m2 = 0, v1 = 0, lnk = 0, cos1 = 0, off2 = 0, vmin = 1, vmax = 0, max_angle = 0;
  for (int i = 0; i < N; ++i) {
    const UncertainSample s = draw_sample(spec, nom, static_cast<std::uint64_t>(i));
    m1 += s.target.mass;
    m2 += s.target.mass * s.target.mass;
    v1 += s.approach_speed;
    vmin = std::min(vmin, s.approach_speed);
    vmax = std::max(vmax, s.approach_speed);
    lnk += std::log(s.contact.K / 1e9);
    const double c = s.target.normal.dot(nom.target.normal);
    cos1 += c;
    max_angle = std::max(max_angle, std::acos(std::min(1.0, c)));
    CHECK(std::abs(s.target.normal.norm() - 1.0) < 1e-15 * 4);
    off2 += (s.target.contact_offset - nom.target.contact_offset).squaredNorm();
  }
  const double mean = m1 / N, sd = std::sqrt(m2 / N - mean * mean);
  CHECK(std::abs(mean - 200.0) < 5 * 20.0 / std::sqrt(N));
  CHECK(std::abs(sd - 20.0) < 5 * 20.0 / std::sqrt(2.0 * N));
  CHECK(std::abs(v1 / N - 0.2) < 5 * (0.1 / std::sqrt(12.0)) / std::sqrt(N));  // U[a, b]: sd (b - a)/sqrt(12)
  CHECK(vmin >= 0.15);
  CHECK(vmax < 0.25);
  CHECK(std::abs(lnk / N) < 5 * 0.6 / std::sqrt(N));  // ln K ~ N(ln 1e9, 0.6^2)
  // uniform on the cap of half-angle a: cos(theta) ~ U[cos a, 1]
  const double ca = std::cos(30 * M_PI / 180);
  CHECK(std::abs(cos1 / N - (1 + ca) / 2) < 5 * ((1 - ca) / std::sqrt(12.0)) / std::sqrt(N));
  CHECK(max_angle <= 30 * M_PI / 180 * (1 + 1e-12));
  // three independent N(0, 0.02^2) components: E|d|^2 = 3 * 0.02^2 (sd of |d|^2: sqrt(6) 0.02^2)
  CHECK(std::abs(off2 / N - 3 * 4e-4) < 5 * std::sqrt(6.0) * 4e-4 / std::sqrt(N));
}

TEST_CASE("physical or redrawn: inertia triangle inequality, 0 < c_r <= 1, mass > 0, bounds",
          "[uncertainty]") {
  UncertaintySpec spec;
  spec.seed = 11;
  UncertainNominal nom = paper_nominal();
  nom.target.inertia = Vector3(60, 100, 150).asDiagonal();  // close to the triangle limit (150 < 160)
  spec[Quantity::TargetInertia] = law(Spread::Law::Normal, 0.3, true);
  spec[Quantity::TargetInertia].axes = 20 * M_PI / 180;
  spec[Quantity::TargetMass] = law(Spread::Law::Normal, 0.6, true);  // often negative before the rule
  spec[Quantity::Restitution] = law(Spread::Law::Normal, 0.2);       // around 0.9: often > 1
  spec[Quantity::Stiffness] = law(Spread::Law::LogNormal, 1.0);
  spec[Quantity::Stiffness].min = 5e8;  // a bounded law
  spec[Quantity::Stiffness].max = 2e9;
  REQUIRE_NOTHROW(validate(spec));
  int redraws = 0;
  for (std::uint64_t i = 0; i < 3000; ++i) {
    const UncertainSample s = draw_sample(spec, nom, i);
    redraws += s.redraws;
    REQUIRE_NOTHROW(s.target.validate("sample"));  // SPD, triangle inequality, mass > 0
    CHECK(s.target.mass > 0);
    CHECK(s.contact.c_r > 0);
    CHECK(s.contact.c_r <= 1);
    CHECK(s.contact.K >= 5e8);
    CHECK(s.contact.K <= 2e9);
    CHECK(s.approach_velocity > 0);
    // the rotated inertia keeps the drawn moments: trace = sum of moments, symmetric
    CHECK((s.target.inertia - s.target.inertia.transpose()).norm() == 0.0);
  }
  CHECK(redraws > 100);  // the rules were exercised
}

TEST_CASE("per-sample M_ie and F_max agree with the direct library computation", "[uncertainty]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  Data data(m);
  BasePose base;
  base.orientation = Quaternion(Eigen::AngleAxisd(0.2, Vector3(0, 1, 1).normalized()));
  const Eigen::VectorXd theta = deg({10, 80, 95, -70, 85, 100, 5});
  const int frame = m.end_effector();
  const Matrix6 G = robot_inverse_inertia(m, data, base, theta, frame);
  CHECK((G - G.transpose()).norm() <= 1e-15 * G.norm());
  UncertaintySpec spec;
  spec.seed = 5;
  spec[Quantity::Normal] = law(Spread::Law::Cone, 40 * M_PI / 180);
  spec[Quantity::TargetInertia] = law(Spread::Law::Uniform, 0.2, true);
  spec[Quantity::ContactOffset] = law(Spread::Law::Uniform, 0.05);
  spec[Quantity::Restitution] = uniform_range(0.6, 0.95);
  const UncertainNominal nom = paper_nominal();
  for (std::uint64_t i = 0; i < 20; ++i) {
    const UncertainSample s = draw_sample(spec, nom, i);
    // Eq. 14 through the target's attitude, with a fresh crba: independent of G
    const double M_ie = integrated_effective_mass(m, data, base, theta, frame, s.target);
    const Vector3 u = s.target.normal_world();
    const double v_in = approach_velocity(u, Vector3(s.approach_speed * u), s.target.velocity,
                                          s.target.angular_velocity_world(), s.target.offset_world());
    const SampleForce f = sample_force(G, s, "herbert-mcwhannell", ForceModel::Exact);
    CHECK(f.M_ie == Approx(M_ie).epsilon(1e-12));
    CHECK(f.approach_velocity == Approx(v_in).epsilon(1e-12));
    CHECK(f.f_max == Approx(max_force_exact(make_contact_law("herbert-mcwhannell", s.contact, v_in), M_ie))
                         .epsilon(1e-10));
    const SampleForce c = sample_force(G, s, "herbert-mcwhannell", ForceModel::Closed);
    CHECK(c.f_max ==
          Approx(max_force_closed_form(make_contact_law("herbert-mcwhannell", s.contact, v_in), M_ie))
              .epsilon(1e-10));
  }
  // the robust objective is the nearest-rank 95th percentile of those forces
  std::vector<UncertainSample> set;
  std::vector<double> f;
  for (std::uint64_t i = 0; i < 40; ++i) {
    set.push_back(draw_sample(spec, nom, i));
    f.push_back(sample_force(G, set.back(), "hunt-crossley", ForceModel::Exact).f_max);
  }
  std::sort(f.begin(), f.end());
  CHECK(robust_force_p95(m, data, base, theta, frame, set, "hunt-crossley") ==
        f[37]);  // ceil(0.95 * 40) = 38th
}

TEST_CASE(
    "multibody force of a sample: same M_ie and delta_dot^- as the closed path, peak near the exact one",
    "[uncertainty]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  Data data(m);
  const BasePose base;
  const Eigen::VectorXd theta = deg({30, 60, 45});
  const int frame = m.end_effector();
  UncertaintySpec spec;
  spec.seed = 8;
  spec[Quantity::TargetMass] = law(Spread::Law::Normal, 0.1, true);
  spec[Quantity::Spin] = law(Spread::Law::Normal, 0.5 * M_PI / 180);
  UncertainNominal nom = paper_nominal();
  nom.target.attitude = Quaternion::Identity();  // the planar robot: normal in its plane
  const Matrix6 G = robot_inverse_inertia(m, data, base, theta, frame);
  for (std::uint64_t i = 0; i < 2; ++i) {
    const UncertainSample s = draw_sample(spec, nom, i);
    const SampleForce mb = sample_force_multibody(m, base, theta, frame, s, "herbert-mcwhannell");
    const SampleForce ex = sample_force(G, s, "herbert-mcwhannell", ForceModel::Exact);
    CHECK(mb.M_ie == Approx(ex.M_ie).epsilon(1e-10));
    CHECK(mb.approach_velocity == Approx(ex.approach_velocity).epsilon(1e-9));
    // the paper's Table 3: single-body vs multibody agree to better than 1 % on this robot
    CHECK(mb.f_max == Approx(ex.f_max).epsilon(0.01));
  }
  // the bodies touching 5-15 cm away from the end-effector's point: the multibody run, which
  // integrates the robot struck at that point, still agrees with Lambda^-1 at p_e and s = [u; rho x u]
  // (the rotational compliance changes F_max far more than the 1 % tolerance)
  UncertaintySpec point;
  point.seed = 9;
  point[Quantity::ContactPoint] = law(Spread::Law::Uniform, 0.15);
  int moved = 0;
  for (std::uint64_t i = 0; i < 3; ++i) {
    const UncertainSample s = draw_sample(point, nom, i);
    INFO("sample " << i << " rho " << s.robot_offset.transpose());
    CHECK((s.wrench.tail<3>() - s.robot_offset.cross(s.normal_world)).norm() < 1e-15);
    const SampleForce mb = sample_force_multibody(m, base, theta, frame, s, "herbert-mcwhannell");
    const SampleForce ex = sample_force(G, s, "herbert-mcwhannell", ForceModel::Exact);
    UncertainSample at_pe = s;
    at_pe.wrench.tail<3>().setZero();
    const SampleForce ex0 = sample_force(G, at_pe, "herbert-mcwhannell", ForceModel::Exact);
    CHECK(mb.M_ie == Approx(ex.M_ie).epsilon(1e-10));
    CHECK(mb.f_max == Approx(ex.f_max).epsilon(0.01));
    moved += std::abs(ex.f_max / ex0.f_max - 1) > 0.03;
  }
  CHECK(moved >= 2);
}

TEST_CASE(
    "p95 confidence interval: ranks from the binomial law, coverage at least 95 % on draws of a known law",
    "[uncertainty]") {
  // the ranks against binomial sums by the product recurrence (no lgamma), for a few n
  for (std::size_t n : {72u, 100u, 1000u, 4003u}) {
    // cdf[k] = P(B <= k), B ~ Bin(n, 0.95): ln P(B = k) by the ratio recurrence from ln P(B = 0)
    std::vector<long double> cdf(n + 1);
    long double ln_pmf = static_cast<long double>(n) * std::log(0.05L), acc = 0;
    for (std::size_t k = 0; k <= n; ++k) {
      acc += std::exp(ln_pmf);
      cdf[k] = acc;
      ln_pmf += std::log(static_cast<long double>(n - k) / static_cast<long double>(k + 1) * 19.0L);
    }
    // X_(r) <= xi iff B >= r: the lower bound fails with P(B <= l - 1), the upper with P(B >= u)
    std::size_t l = 0, u = 0;
    for (std::size_t r = 1; r <= n; ++r) {
      if (cdf[r - 1] <= 0.025L) l = r;
      if (!u && cdf[r - 1] >= 0.975L) u = r;
    }
    const QuantileRanks q = quantile_interval(n, 0.95);
    INFO("n " << n);
    CHECK(q.lower == l);
    CHECK(q.upper == u);
    CHECK(q.coverage >= 0.95);
    CHECK(q.coverage == Approx(static_cast<double>(cdf[u - 1] - cdf[l - 1])).epsilon(1e-9));
  }
  // too few samples for an upper bound: P(B <= n - 1) = 1 - 0.95^n < 0.975 below n = 72
  CHECK(quantile_interval(71, 0.95).upper == 0);
  CHECK(quantile_interval(72, 0.95).upper == 72);
  CHECK(quantile_interval(20, 0.95).lower > 0);
  const ForceSummary few = summarize(std::vector<double>(20, 1.0));
  CHECK(few.p95_ci.upper == 0);
  CHECK(few.p95_ci.hi == 0.0);
  CHECK_THROWS_AS(quantile_interval(0, 0.95), InputError);
  CHECK_THROWS_AS(quantile_interval(10, 1.0), InputError);

  // coverage: 4000 sets of 1000 uniform draws (true p95 = 0.95); the interval holds it in at least
  // 95 % of the sets up to the simulation's noise (standard error 0.35 %)
  int covered = 0;
  const int sets = 4000;
  for (int k = 0; k < sets; ++k) {
    SampleStream rng(2024, static_cast<std::uint64_t>(k));
    std::vector<double> v(1000);
    for (double& x : v) x = rng.uniform();
    const ForceSummary sm = summarize(v);
    REQUIRE(sm.p95_ci.lower > 0);
    REQUIRE(sm.p95_ci.upper > sm.p95_ci.lower);
    covered += sm.p95_ci.lo <= 0.95 && 0.95 < sm.p95_ci.hi;
  }
  const double coverage = static_cast<double>(covered) / sets;
  INFO("coverage " << coverage << " (nominal " << quantile_interval(1000, 0.95).coverage << ")");
  CHECK(coverage > 0.94);
  CHECK(coverage < 0.975);
}

TEST_CASE("summary: nearest-rank percentiles, mean and deviation of 1..100 -- parallel_for = serial",
          "[uncertainty]") {
  std::vector<double> v;
  for (int k = 100; k >= 1; --k) v.push_back(k);
  const ForceSummary s = summarize(v);
  CHECK(s.n == 100);
  CHECK(s.p50 == 50);
  CHECK(s.p95 == 95);
  CHECK(s.p99 == 99);
  CHECK(s.max == 100);
  CHECK(s.mean == 50.5);
  CHECK(s.std ==
        Approx(std::sqrt(100.0 * 101.0 / 12.0)).epsilon(1e-14));  // sd (n - 1) of 1..n: sqrt(n(n+1)/12)
  CHECK(nearest_rank(std::vector<double>{1, 2, 3}, 50) == 2);     // ceil(1.5) = 2nd
  CHECK_THROWS_AS(summarize({1.0, std::nan("")}), NumericalError);

  UncertaintySpec spec;
  spec[Quantity::TargetMass] = law(Spread::Law::Normal, 0.1, true);
  const UncertainNominal nom = paper_nominal();
  std::vector<double> serial(500), threaded(500);
  detail::parallel_for(500, 1, [&](std::uint64_t i) { serial[i] = draw_sample(spec, nom, i).target.mass; });
  detail::parallel_for(500, 2, [&](std::uint64_t i) { threaded[i] = draw_sample(spec, nom, i).target.mass; });
  CHECK(serial == threaded);
  CHECK_THROWS_AS(detail::parallel_for(100, 2,
                                       [](std::uint64_t i) {
                                         if (i == 37) throw InputError("x");
                                       }),
                  InputError);
}

TEST_CASE("validate: bad spreads name the key", "[uncertainty]") {
  auto msg = [](const UncertaintySpec& s) {
    try {
      validate(s);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  UncertaintySpec s;
  s[Quantity::TargetMass] = law(Spread::Law::Normal, -0.1, true);
  CHECK_THAT(msg(s), Catch::Contains("uncertainty.target-mass") && Catch::Contains("non-negative"));
  s = {};
  s[Quantity::Restitution] = law(Spread::Law::Uniform, 0);
  s[Quantity::Restitution].has_range = true;
  s[Quantity::Restitution].min = 0.9;
  s[Quantity::Restitution].max = 0.6;
  CHECK_THAT(msg(s), Catch::Contains("uncertainty.restitution") && Catch::Contains("greater than max"));
  s = {};
  s[Quantity::Normal] = law(Spread::Law::Cone, 100 * M_PI / 180);
  CHECK_THAT(msg(s), Catch::Contains("uncertainty.normal") && Catch::Contains("90 deg"));
  s = {};
  s.samples = 0;
  CHECK_THAT(msg(s), Catch::Contains("uncertainty.samples"));
  s = {};
  s[Quantity::Spin] = law(Spread::Law::LogNormal, 0.1);
  CHECK_THAT(msg(s), Catch::Contains("uncertainty.spin"));
}

// ------------------------------------------------------------------------------------------------
// the robust objective of the global search: CVaR_95 of the exact F_max and its gradient
// ------------------------------------------------------------------------------------------------

TEST_CASE(
    "the exact force peak scales as M^(alpha/(alpha+1)) for the eight laws (the robust objective's premise)",
    "[uncertainty][robust]") {
  for (std::string_view name : contact_law_names())
    for (const ContactParams& cp :
         {ContactParams{1e9, 1.5, 0.9}, ContactParams{3e7, 1.0, 0.3}, ContactParams{5e10, 2.2, 0.6}})
      for (double v : {0.01, 0.2, 1.0}) {
        const AnyContactLaw law = make_contact_law(name, cp, v);
        const double f1 = max_force_exact(law, 1.0), p = cp.alpha / (cp.alpha + 1.0);
        for (double M : {1e-3, 0.37, 12.5, 4e3}) {
          INFO(name << " K " << cp.K << " alpha " << cp.alpha << " c_r " << cp.c_r << " v " << v << " M "
                    << M);
          CHECK(max_force_exact(law, M) == Approx(f1 * std::pow(M, p)).epsilon(1e-10));
        }
      }
}

TEST_CASE("robust objective: CVaR_95 and p95 against the per-sample forces, its gradient against differences",
          "[uncertainty][robust]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  Data data(m);
  const int frame = m.end_effector();
  BasePose base;
  base.orientation = Quaternion(Eigen::AngleAxisd(0.2, Vector3(0, 1, 1).normalized()));
  Eigen::VectorXd theta(7);
  theta << 0.3, 0.9, -0.4, 0.7, 0.2, 1.1, -0.5;
  UncertaintySpec spec;
  spec[Quantity::TargetMass] = law(Spread::Law::Normal, 0.1, true);
  spec[Quantity::TargetInertia] = law(Spread::Law::Normal, 0.2);
  spec[Quantity::ContactOffset] = law(Spread::Law::Normal, 0.02);
  spec[Quantity::Normal] = law(Spread::Law::Cone, 5.0 * M_PI / 180.0);
  spec[Quantity::Stiffness] = law(Spread::Law::LogNormal, std::log(10.0) / 2.0);
  spec[Quantity::Exponent] = law(Spread::Law::Uniform, 0.1, true);
  spec[Quantity::Restitution] = uniform_range(0.6, 0.95);
  spec.seed = 11;
  const UncertainNominal nom = paper_nominal();
  std::vector<UncertainSample> set;
  for (std::uint64_t i = 0; i < 237; ++i) set.push_back(draw_sample(spec, nom, i));
  RobustForceObjective obj(set, "gonthier");
  REQUIRE(obj.tail_count() == 12u);  // ceil(237 / 20)

  // the value: the mean of the 12 largest exact peaks, each solved directly
  const Matrix6 G = robot_inverse_inertia(m, data, base, theta, frame);
  std::vector<double> f;
  for (const auto& s : set) f.push_back(sample_force(G, s, "gonthier", ForceModel::Exact).f_max);
  std::sort(f.begin(), f.end());
  double cvar = 0;
  for (size_t k = f.size() - 12; k < f.size(); ++k) cvar += f[k];
  cvar /= 12;
  const auto v = obj.value(G);
  CHECK(v.cvar95 == Approx(cvar).epsilon(1e-10));
  CHECK(v.p95 == Approx(f[225]).epsilon(1e-10));  // nearest rank ceil(0.95 * 237) = 226, index 225
  CHECK(v.p95 == Approx(robust_force_p95(m, data, base, theta, frame, set, "gonthier")).epsilon(1e-10));
  CHECK(v.cvar95 >= v.p95);

  // the gradient against central differences of the value
  Eigen::VectorXd g(7);
  const double c0 = obj.value_and_gradient(m, data, base, theta, frame, g);
  CHECK(c0 == Approx(cvar).epsilon(1e-10));
  for (int k = 0; k < 7; ++k) {
    const double h = 1e-6;
    Eigen::VectorXd tp = theta, tm = theta;
    tp(k) += h;
    tm(k) -= h;
    const double fp = obj.value(robot_inverse_inertia(m, data, base, tp, frame)).cvar95;
    const double fm = obj.value(robot_inverse_inertia(m, data, base, tm, frame)).cvar95;
    INFO("joint " << k);
    CHECK(g(k) == Approx((fp - fm) / (2 * h)).epsilon(1e-5).margin(1e-6 * std::abs(c0)));
  }
  CHECK_THROWS_AS(RobustForceObjective({}, "gonthier"), InputError);
}

// Why a robust capture configuration differs from the nominal one only through the normal and the
// point where the bodies touch: the configuration enters every sample's exact peak
// F_i = c_i M_i^(alpha_i/(alpha_i+1)) only through g = s_i^T Lambda^-1(theta) s_i, s_i = [u_i; rho_i x u_i]
// (M_i = 1 / (g + t_i), t_i the target side). With the normal known and the contact point the
// planned one, s_i = [u_0; 0] for all i, so every F_i falls as g rises, and so do CVaR_95, p95 and the
// nominal M_ie = 1/(g + t_0): they rank configurations identically and share their minimizer -- the
// target's mass, inertia, centre of mass (contact-offset), spin and the contact parameters cannot
// make a robust optimum differ. Checked here over pairs of random configurations; with a 30 deg
// normal cone, or the contact point uncertain by 2 cm, some pairs rank differently.
TEST_CASE(
    "robust objective: with the normal and the contact point known, CVaR_95 and p95 rank configurations as "
    "the nominal M_ie does",
    "[uncertainty][robust]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  Data data(m);
  const int frame = m.end_effector();
  BasePose base;
  UncertaintySpec spec;  // every quantity of the example scenario but the normal, and wider
  spec[Quantity::TargetMass] = law(Spread::Law::Uniform, 0.3, true);
  spec[Quantity::TargetInertia] = law(Spread::Law::Uniform, 0.4);
  spec[Quantity::ContactOffset] = law(Spread::Law::Uniform, 0.1);
  spec[Quantity::Spin] = law(Spread::Law::Normal, 1.0 * M_PI / 180.0);
  spec[Quantity::Stiffness] = law(Spread::Law::LogNormal, 0.587);
  spec[Quantity::Exponent] = law(Spread::Law::Uniform, 0.1, true);
  spec[Quantity::Restitution] = uniform_range(0.6, 0.95);
  spec.seed = 5;
  const UncertainNominal nom = paper_nominal();
  const Vector3 u0 = nom.target.normal_world();
  const double t0 = nom.target.inverse_mass_along_normal();

  auto rank_flips = [&](const UncertaintySpec& sp) {
    std::vector<UncertainSample> set;
    for (std::uint64_t i = 0; i < 400; ++i) set.push_back(draw_sample(sp, nom, i));
    RobustForceObjective obj(set, "hunt-crossley");
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> U(-M_PI, M_PI);
    struct Row {
      double M, cvar, p95;
    };
    std::vector<Row> rows;
    for (int k = 0; k < 150; ++k) {
      Eigen::VectorXd theta(7);
      for (int j = 0; j < 7; ++j) theta(j) = U(rng);
      const Matrix6 G = robot_inverse_inertia(m, data, base, theta, frame);
      const auto v = obj.value(G);
      rows.push_back({1.0 / (u0.dot(G.topLeftCorner<3, 3>() * u0) + t0), v.cvar95, v.p95});
    }
    int cvar_flips = 0, p95_flips = 0, pairs = 0;
    for (size_t a = 0; a < rows.size(); ++a)
      for (size_t b = 0; b < rows.size(); ++b) {
        if (!(rows[a].M < rows[b].M * (1 - 1e-12))) continue;
        ++pairs;
        cvar_flips += !(rows[a].cvar < rows[b].cvar);
        p95_flips += !(rows[a].p95 <= rows[b].p95);
      }
    INFO("pairs " << pairs << ", CVaR flips " << cvar_flips << ", p95 flips " << p95_flips);
    CHECK(pairs > 10000);
    return std::pair<int, int>(cvar_flips, p95_flips);
  };

  const auto known = rank_flips(spec);
  CHECK(known.first == 0);
  CHECK(known.second == 0);
  // every sample's normal is then the nominal one (the premise above)
  for (std::uint64_t i = 0; i < 20; ++i) CHECK((draw_sample(spec, nom, i).normal_world - u0).norm() < 1e-15);

  UncertaintySpec cone = spec;
  cone[Quantity::Normal] = law(Spread::Law::Cone, 30.0 * M_PI / 180.0);
  const auto uncertain = rank_flips(cone);
  CHECK(uncertain.first > 0);

  // where the bodies touch uncertain by 2 cm (normal known): the end-effector's rotational compliance
  // enters the samples (s_i = [u_0; rho_i x u_0]), which the nominal M_ie does not see
  UncertaintySpec point = spec;
  point[Quantity::ContactPoint] = law(Spread::Law::Uniform, 0.02);
  const auto moved = rank_flips(point);
  CHECK(moved.first > 0);
  CHECK(moved.second > 0);
}

TEST_CASE(
    "the single-body F_max scales as K^(1/(alpha+1)), closed and exact, eight laws (the conditional "
    "estimator's premise)",
    "[uncertainty][robust]") {
  for (std::string_view name : contact_law_names())
    for (const ContactParams& cp : {ContactParams{1e9, 1.5, 0.9}, ContactParams{3e7, 1.0, 0.3},
                                    ContactParams{5e10, 2.2, 0.6}, ContactParams{2e8, 0.7, 1.0}})
      for (double v : {0.01, 0.2, 1.0}) {
        const double a = 1.0 / (cp.alpha + 1.0);
        const AnyContactLaw l1 = make_contact_law(name, cp, v);
        for (double ratio : {1e-3, 0.31, 7.0, 2e3}) {
          const AnyContactLaw l2 = make_contact_law(name, {cp.K * ratio, cp.alpha, cp.c_r}, v);
          INFO(name << " K " << cp.K << " alpha " << cp.alpha << " c_r " << cp.c_r << " v " << v << " ratio "
                    << ratio);
          CHECK(max_force_exact(l2, 3.7) ==
                Approx(max_force_exact(l1, 3.7) * std::pow(ratio, a)).epsilon(1e-10));
          CHECK(max_force_closed_form(l2, 3.7) ==
                Approx(max_force_closed_form(l1, 3.7) * std::pow(ratio, a)).epsilon(1e-10));
        }
      }
}

TEST_CASE(
    "scalar_law: the CDF of the truncated law is the sampler's (Kolmogorov-Smirnov), its density the CDF's "
    "slope",
    "[uncertainty]") {
  struct Case {
    const char* what;
    Quantity q;
    Spread sp;
    double x0;
  };
  Spread bounded_lognormal = law(Spread::Law::LogNormal, 0.587);
  bounded_lognormal.min = 5e8;
  bounded_lognormal.max = 4e9;
  Spread wide_normal = law(Spread::Law::Normal, 0.6, true);  // 4.8 % of the draws below K = 0: redrawn
  Spread capped_uniform = law(Spread::Law::Uniform, 0.5, true);
  capped_uniform.max = 1.2e9;
  Spread restitution_normal = law(Spread::Law::Normal, 0.1);  // about 16 % above c_r = 1: redrawn
  const std::vector<Case> cases{
      {"log-normal K", Quantity::Stiffness, law(Spread::Law::LogNormal, 0.587), 1e9},
      {"log-normal K within [5e8, 4e9]", Quantity::Stiffness, bounded_lognormal, 1e9},
      {"normal K, relative 0.6, K > 0", Quantity::Stiffness, wide_normal, 1e9},
      {"uniform K +-50 %, capped at 1.2e9", Quantity::Stiffness, capped_uniform, 1e9},
      {"uniform K in [2e8, 3e9]", Quantity::Stiffness, uniform_range(2e8, 3e9), 1e9},
      {"normal c_r 0.9 +- 0.1, c_r <= 1", Quantity::Restitution, restitution_normal, 0.9},
      {"uniform c_r in [0.6, 0.95]", Quantity::Restitution, uniform_range(0.6, 0.95), 0.9},
  };
  const int N = 20000;
  for (const Case& c : cases) {
    INFO(c.what);
    UncertaintySpec spec;
    spec.seed = 11;
    spec[c.q] = c.sp;
    REQUIRE_NOTHROW(validate(spec));
    UncertainNominal nom = paper_nominal();
    nom.contact.K = c.q == Quantity::Stiffness ? c.x0 : nom.contact.K;
    nom.contact.c_r = c.q == Quantity::Restitution ? c.x0 : nom.contact.c_r;
    std::vector<double> x(N);
    for (int i = 0; i < N; ++i) {
      const UncertainSample s = draw_sample(spec, nom, static_cast<std::uint64_t>(i));
      x[static_cast<std::size_t>(i)] = c.q == Quantity::Stiffness ? s.contact.K : s.contact.c_r;
    }
    std::sort(x.begin(), x.end());
    double ks = 0;
    for (int i = 0; i < N; ++i) {
      const double F = scalar_law(c.sp, c.q, c.x0, x[static_cast<std::size_t>(i)]).cdf;
      ks = std::max({ks, std::abs(F - i / double(N)), std::abs(F - (i + 1) / double(N))});
    }
    CHECK(ks < 1.63 / std::sqrt(double(N)));  // the 1 % critical value of the KS statistic
    // the density is the slope of the CDF (central differences) inside the support
    for (double p : {0.1, 0.5, 0.9}) {
      const double xm = x[static_cast<std::size_t>(p * N)], h = 1e-6 * xm;
      const double slope =
          (scalar_law(c.sp, c.q, c.x0, xm + h).cdf - scalar_law(c.sp, c.q, c.x0, xm - h).cdf) / (2 * h);
      CHECK(scalar_law(c.sp, c.q, c.x0, xm).density == Approx(slope).epsilon(1e-5));
    }
    CHECK(scalar_law(c.sp, c.q, c.x0, 0.0).cdf == 0.0);
    CHECK(scalar_law(c.sp, c.q, c.x0, x.front()).cdf < 1e-3);
    CHECK(scalar_law(c.sp, c.q, c.x0, x.back()).cdf > 1 - 1e-3);
  }
  CHECK_THROWS_AS(scalar_law(Spread{}, Quantity::Stiffness, 1e9, 1e9), InputError);  // fixed
  CHECK_THROWS_AS(scalar_law(law(Spread::Law::Normal, 0.0), Quantity::Stiffness, 1e9, 1e9),
                  InputError);  // no spread
  CHECK_THROWS_AS(scalar_law(law(Spread::Law::Normal, 0.1), Quantity::Spin, 0.0, 0.0),
                  InputError);  // a vector
  Spread nowhere = law(Spread::Law::Uniform, 0.1, true);
  nowhere.min = 2e9;  // U[0.9e9, 1.1e9] above 2e9: nothing left
  CHECK_THROWS_AS(scalar_law(nowhere, Quantity::Stiffness, 1e9, 1e9), NumericalError);
}

namespace {

/// F = c K^(1/(alpha+1)) for every sample: the law of F is the law of K mapped, so its quantiles are
/// known exactly.
std::vector<double> forces_of_stiffness(const std::vector<double>& K, double c, double alpha) {
  std::vector<double> f(K.size());
  for (std::size_t i = 0; i < K.size(); ++i) f[i] = c * std::pow(K[i], 1.0 / (alpha + 1.0));
  return f;
}

}  // namespace

TEST_CASE("stiffness-conditional percentiles: exact when F_max depends on K alone, whatever the sample",
          "[uncertainty][robust]") {
  const double z95 = 1.6448536269514722, z99 = 2.3263478740408408, alpha = 1.5, c = 3.0e-2;
  for (std::size_t n : {1u, 7u, 1000u}) {
    INFO("n = " << n);
    std::mt19937_64 rng(5 + n);
    std::normal_distribution<double> z;
    std::vector<double> K(n), A(n, alpha);
    for (double& k : K) k = 1e9 * std::exp(0.587 * z(rng));
    const Spread ln = law(Spread::Law::LogNormal, 0.587);
    const ForceSummary s = summarize_stiffness_conditional(forces_of_stiffness(K, c, alpha), K, A, ln, 1e9);
    CHECK(s.estimator == ForceSummary::Estimator::StiffnessConditional);
    const double a = 1.0 / (alpha + 1.0);
    CHECK(s.p50 == Approx(c * std::pow(1e9, a)).epsilon(1e-12));
    CHECK(s.p95 == Approx(c * std::pow(1e9 * std::exp(0.587 * z95), a)).epsilon(1e-12));
    CHECK(s.p99 == Approx(c * std::pow(1e9 * std::exp(0.587 * z99), a)).epsilon(1e-12));
    if (n >= 2) {  // every sample gives the same conditional law: no variance left
      CHECK(s.p95_ci.has_lo);
      CHECK(s.p95_ci.log_standard_error < 1e-12);
    }
    // a uniform law on [2e8, 3e9] capped at 2.5e9: the p-quantile of K is 2e8 + p (2.5e9 - 2e8)
    Spread u = uniform_range(2e8, 3e9);
    u.max = 2.5e9;
    std::uniform_real_distribution<double> U(2e8, 2.5e9);
    for (double& k : K) k = U(rng);
    const ForceSummary su = summarize_stiffness_conditional(forces_of_stiffness(K, c, 0.8), K,
                                                            std::vector<double>(n, 0.8), u, 1e9);
    CHECK(su.p95 == Approx(c * std::pow(2e8 + 0.95 * 2.3e9, 1.0 / 1.8)).epsilon(1e-12));
    CHECK(su.p50 == Approx(c * std::pow(2e8 + 0.50 * 2.3e9, 1.0 / 1.8)).epsilon(1e-12));
  }
}

TEST_CASE(
    "stiffness-conditional percentiles: unbiased, less scatter than order statistics, the delta-method "
    "interval covers 95 %",
    "[uncertainty][robust]") {
  // ln F = ln c + ln K / (alpha + 1) with ln c ~ N(0, 0.1^2) and ln K ~ N(ln 1e9, 0.587^2): ln F is
  // normal, so the law's 95th percentile is known in closed form.
  const double sc = 0.1, sk = 0.587, alpha = 1.5, a = 1.0 / (alpha + 1.0), z95 = 1.6448536269514722;
  const double mu = a * std::log(1e9), sd = std::sqrt(sc * sc + a * a * sk * sk);
  const double truth = std::exp(mu + sd * z95);
  const Spread ln = law(Spread::Law::LogNormal, sk);
  const int sets = 400, n = 1000;
  std::mt19937_64 rng(2026);
  std::normal_distribution<double> z;
  double sum_c = 0, sum2_c = 0, sum_o = 0, sum2_o = 0;
  int covered = 0;
  std::vector<double> K(n), f(n), A(n, alpha);
  for (int k = 0; k < sets; ++k) {
    for (int i = 0; i < n; ++i) {
      K[i] = 1e9 * std::exp(sk * z(rng));
      f[i] = std::exp(sc * z(rng)) * std::pow(K[i], a);
    }
    const ForceSummary s = summarize_stiffness_conditional(f, K, A, ln, 1e9);
    const double ec = std::log(s.p95 / truth), eo = std::log(s.order.p95 / truth);
    sum_c += ec;
    sum2_c += ec * ec;
    sum_o += eo;
    sum2_o += eo * eo;
    REQUIRE(s.p95_ci.has_lo);
    REQUIRE(s.p95_ci.has_hi);
    covered += s.p95_ci.lo <= truth && truth < s.p95_ci.hi;
    // the order statistics are those of summarize
    CHECK(s.order.p95 == summarize(f).p95);
  }
  const double mean_c = sum_c / sets, rms_c = std::sqrt(sum2_c / sets), rms_o = std::sqrt(sum2_o / sets);
  INFO("conditional: bias " << mean_c << ", rms " << rms_c << "; order statistics: bias " << sum_o / sets
                            << ", rms " << rms_o << "; coverage " << covered << "/" << sets);
  CHECK(std::abs(mean_c) < 4 * rms_c / std::sqrt(double(sets)));  // unbiased to the sampling error
  CHECK(rms_c < 0.4 * rms_o);     // here the stiffness carries 86 % of the variance of ln F
  CHECK(covered >= 0.92 * sets);  // nominal 95 %: 380 of 400, binomial sd 4.4
  CHECK(covered <= 0.98 * sets);
}

TEST_CASE(
    "paired p95 ratio of two configurations: exact for a scaled force, covers 95 % on a known law, narrower "
    "than unpaired",
    "[uncertainty][robust]") {
  const double sc = 0.1, sk = 0.587, alpha = 1.5, a = 1.0 / (alpha + 1.0), z95 = 1.6448536269514722;
  const Spread ln = law(Spread::Law::LogNormal, sk);
  // b = lambda a on every sample: the ratio is lambda and nothing varies between the two estimates
  {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> z;
    std::vector<double> K(500), fa(500), fb(500), A(500, alpha);
    for (std::size_t i = 0; i < K.size(); ++i) {
      K[i] = 1e9 * std::exp(sk * z(rng));
      fa[i] = std::exp(sc * z(rng)) * std::pow(K[i], a);
      fb[i] = 0.97 * fa[i];
    }
    const PercentileRatio r = compare_p95_stiffness_conditional(fa, fb, K, A, ln, 1e9);
    CHECK(r.ratio == Approx(0.97).epsilon(1e-12));
    REQUIRE(r.has_interval);
    CHECK(r.log_standard_error < 1e-9);
  }
  // ln F_a = ln c + ln K / (alpha + 1), ln F_b = ln F_a + 0.02 + 0.05 z': both normal, so the true
  // ratio of the 95th percentiles is known in closed form
  const double sb = 0.05, shift = 0.02;
  const double sa_tot = std::sqrt(sc * sc + a * a * sk * sk),
               sb_tot = std::sqrt(sc * sc + sb * sb + a * a * sk * sk);
  const double truth = std::exp(shift + z95 * (sb_tot - sa_tot));
  const int sets = 400, n = 1000;
  std::mt19937_64 rng(2027);
  std::normal_distribution<double> z;
  std::vector<double> K(n), fa(n), fb(n), A(n, alpha);
  int covered = 0;
  double paired = 0, unpaired = 0;
  for (int k = 0; k < sets; ++k) {
    for (int i = 0; i < n; ++i) {
      K[i] = 1e9 * std::exp(sk * z(rng));
      fa[i] = std::exp(sc * z(rng)) * std::pow(K[i], a);
      fb[i] = fa[i] * std::exp(shift + sb * z(rng));
    }
    const PercentileRatio r = compare_p95_stiffness_conditional(fa, fb, K, A, ln, 1e9);
    REQUIRE(r.has_interval);
    covered += r.lo <= truth && truth < r.hi;
    const ForceSummary a1 = summarize_stiffness_conditional(fa, K, A, ln, 1e9);
    const ForceSummary b1 = summarize_stiffness_conditional(fb, K, A, ln, 1e9);
    CHECK(r.ratio == Approx(b1.p95 / a1.p95).epsilon(1e-14));
    paired += r.log_standard_error;
    unpaired += std::hypot(a1.p95_ci.log_standard_error, b1.p95_ci.log_standard_error);
  }
  INFO("coverage " << covered << "/" << sets << "; mean standard error of ln ratio: paired " << paired / sets
                   << ", unpaired " << unpaired / sets);
  CHECK(covered >= 0.92 * sets);  // nominal 95 %: 380 of 400, binomial sd 4.4
  CHECK(covered <= 0.98 * sets);
  CHECK(paired < 0.6 * unpaired);  // what the samples share cancels
  // the two configurations must share the samples
  CHECK_THROWS_AS(compare_p95_stiffness_conditional(fa, std::vector<double>(3, 1.0), K, A, ln, 1e9),
                  InputError);
}

TEST_CASE("stiffness-conditional percentiles: bad inputs", "[uncertainty][robust]") {
  const Spread ln = law(Spread::Law::LogNormal, 0.5);
  const std::vector<double> one{1.0}, two{1.0, 2.0};
  CHECK_THROWS_AS(summarize_stiffness_conditional(two, one, two, ln, 1e9), InputError);
  CHECK_THROWS_AS(summarize_stiffness_conditional(one, one, one, Spread{}, 1e9), InputError);
  CHECK_THROWS_AS(summarize_stiffness_conditional(one, one, one, ln, -1.0), InputError);
  CHECK_THROWS_AS(summarize_stiffness_conditional({0.0}, one, one, ln, 1e9), InputError);
  CHECK_THROWS_AS(summarize_stiffness_conditional(one, {-1.0}, one, ln, 1e9), InputError);
  CHECK_THROWS_AS(summarize_stiffness_conditional({std::nan("")}, one, one, ln, 1e9), NumericalError);
  CHECK_FALSE(stiffness_conditional_applies(ForceModel::Multibody, ln));
  CHECK_FALSE(stiffness_conditional_applies(ForceModel::Exact, Spread{}));
  CHECK_FALSE(stiffness_conditional_applies(ForceModel::Exact, law(Spread::Law::LogNormal, 0.0)));
  CHECK(stiffness_conditional_applies(ForceModel::Closed, ln));
}

}  // namespace test_uncertainty
