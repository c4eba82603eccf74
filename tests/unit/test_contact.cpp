// Tests of the contact laws (Table 1, Eq. 15-27, 32), the CVODE wrapper and the single-body
// simulation of Eq. 16 (Zhang et al. 2022, Aerospace 9, 69). Every check names its tolerance and
// where the expected value comes from.
#include "ffsr/contact/contact_law.hpp"
#include "ffsr/contact/damping.hpp"
#include "ffsr/errors.hpp"
#include "ffsr/simulate/cvode.hpp"
#include "ffsr/simulate/single_body.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace test_contact {

using namespace ffsr;
using Catch::Matchers::Contains;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

// The paper's contact parameters (Sections 5.1.1 and 5.2.1).
const ContactParams kPaper{1e9, 1.5, 0.9};

// Every law of AnyContactLaw, built by name.
std::vector<AnyContactLaw> all_laws(const ContactParams& p, double v0) {
  std::vector<AnyContactLaw> laws;
  for (std::string_view n : contact_law_names()) laws.push_back(make_contact_law(n, p, v0));
  return laws;
}

// Table 1 written out independently of damping.hpp, in the order of contact_law_names().
double table1_factor(std::size_t i, double c) {
  switch (i) {
    case 0:
      return 1.5 * (1 - c);  // Hunt-Crossley
    case 1:
      return 6 * (1 - c) / ((2 * c - 1) * (2 * c - 1) + 3);  // Herbert-McWhannell
    case 2:
      return 0.75 * (1 - c * c);  // Lankarani-Nikravesh
    case 3:
      return 0.75 * (1 - c);  // Lee-Wang
    case 4:
      return 8 * (1 - c) / (5 * c);  // Flores et al.
    case 5:
      return (1 - c * c) / c;  // Gonthier et al.
    case 6:
      return 0.75 * (1 - c * c) * std::exp(2 * (1 - c));  // Zhiying-Qishao
    case 7:
      return 1.5 * (1 - c) / c;  // Hu-Guo
    default:
      return std::nan("");
  }
}

// F along the single-body contact as a function of s = δ̇/δ̇⁻ (Eq. 19 into Eq. 15).
double force_at_rate(const AnyContactLaw& law, double M, double s) {
  const double v0 = approach_velocity(law);
  return std::visit([&](const auto& l) { return l.force(l.deformation(M, s * v0), s * v0); }, law);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Table 1 and the law itself
// ---------------------------------------------------------------------------------------------

TEST_CASE("damping factors follow Table 1 and vanish at c_r = 1", "[contact]") {
  const auto names = contact_law_names();
  REQUIRE(names.size() == 8);
  const std::array<std::string_view, 8> expected{
      "hunt-crossley", "herbert-mcwhannell", "lankarani-nikravesh", "lee-wang",
      "flores",        "gonthier",           "zhiying-qishao",      "hu-guo"};
  for (std::size_t i = 0; i < 8; ++i) {
    CHECK(names[i] == expected[i]);
    for (double c : {0.1, 0.3, 0.5, 0.9, 0.99, 1.0}) {
      const auto law = make_contact_law(names[i], ContactParams{1e9, 1.5, c}, 0.2);
      INFO(names[i] << " c_r = " << c);
      CHECK(contact_law_name(law) == names[i]);
      // Table 1 re-typed independently; tolerance 1e-15 relative (rounding of the same formula).
      CHECK(damping_factor(law) == Approx(table1_factor(i, c)).epsilon(1e-15).margin(0));
      // Eq. 22: λ = f K / δ̇⁻ (identity, 1e-15).
      CHECK(lambda(law) == Approx(table1_factor(i, c) * 1e9 / 0.2).epsilon(1e-15).margin(0));
    }
  }
}

TEST_CASE("the force of Eq. 15: zero without contact, clamped at zero, never pulls", "[contact]") {
  const HertzDamped<HuntCrossley> law({1e9, 1.5, 0.5}, 0.2);  // f = 0.75, λ = 3.75e9
  // No contact: F = 0 for δ <= 0 whatever δ̇.
  CHECK(law.force(0.0, 0.2) == 0.0);
  CHECK(law.force(-1e-6, -0.2) == 0.0);
  // Eq. 15 by hand: δ = 1e-5, δ̇ = 0.1: K δ^1.5 (1 + λ δ̇ / K); tolerance 1e-14 relative.
  const double d = 1e-5;
  CHECK(law.force(d, 0.1) == Approx(1e9 * std::pow(d, 1.5) * (1 + 0.75 * 0.1 / 0.2)).epsilon(1e-14));
  // K + λ δ̇ < 0 for δ̇ < -K/λ = -0.2667 m/s: clamped to exactly zero (documented choice).
  CHECK(law.force(d, -0.3) == 0.0);
  CHECK(law.force(d, -0.26) > 0.0);
}

// ---------------------------------------------------------------------------------------------
// Tables 3 and 6: the closed form at the paper's own M_ie values
// ---------------------------------------------------------------------------------------------

// ---------------------------------------------------------------------------------------------
// The closed forms Eq. 20, 23-25 and their λ -> 0 limit
// ---------------------------------------------------------------------------------------------

TEST_CASE("closed forms agree: K δ_max^α = F'_max (Eq. 23) = ζ M^(α/(α+1)) (Eq. 24)", "[contact]") {
  for (double c : {0.1, 0.5, 0.9, 0.999, 1.0}) {
    for (double alpha : {1.0, 1.5, 2.0}) {
      for (const auto& law : all_laws({1e9, alpha, c}, 0.2)) {
        for (double M : {0.1, 1.0, 21.093, 1e3}) {
          INFO(contact_law_name(law) << " c_r = " << c << " alpha = " << alpha << " M = " << M);
          const double dmax = max_deformation(law, M);
          const double est = max_force_estimate(law, M);
          // Identities; tolerance 1e-14 relative (a few roundings of pow).
          CHECK(rel(1e9 * std::pow(dmax, alpha), est) < 1e-14);
          CHECK(rel(zeta(law) * std::pow(M, alpha / (alpha + 1)), est) < 1e-14);
          CHECK(rel(max_force_closed_form(law, M), est) < 1e-14);
          // Eq. 27: dF_max/dM = α ζ /(α+1) M^(-1/(α+1)), against a central difference (1e-7).
          const double h = 1e-4 * M;
          const double dF = (max_force_closed_form(law, M + h) - max_force_closed_form(law, M - h)) / (2 * h);
          CHECK(rel(dF, alpha * zeta(law) / (alpha + 1) * std::pow(M, -1 / (alpha + 1))) < 1e-7);
        }
      }
    }
  }
}

TEST_CASE("Eq. 20 and Eq. 25 as printed (with λ and ln) agree with the implementation", "[contact]") {
  // The paper's formulas typed literally; fine where f is not small (no cancellation in the log).
  const double K = 1e9, a = 1.5, v0 = 0.2, M = 3.0;
  for (double c : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    for (const auto& law : all_laws({K, a, c}, v0)) {
      INFO(contact_law_name(law) << " c_r = " << c);
      const double lam = lambda(law), f = damping_factor(law);
      const double d20 =
          std::pow(M * (a + 1) / (lam * lam) * (lam * v0 + K * std::log(K / (lam * v0 + K))), 1 / (a + 1));
      const double z25 = std::pow(K, 1 / (a + 1)) *
                         std::pow((a + 1) * v0 * v0 / (f * f) * (f + std::log(1 / (f + 1))), a / (a + 1));
      // Cancellation in λ δ̇⁻ + K ln(...) costs about log10(1/f) digits: tolerance 1e-11.
      CHECK(rel(max_deformation(law, M), d20) < 1e-11);
      CHECK(rel(zeta(law), z25) < 1e-11);
    }
  }
}

TEST_CASE("c_r = 1 is the pure Hertz limit, continuous as c_r -> 1", "[contact]") {
  const double K = 1e9, a = 1.5, v0 = 0.2, M = 5.0;
  // Pure Hertz (λ = 0): δ_max = (M (α+1) δ̇⁻² / (2K))^(1/(α+1)) from energy conservation.
  const double d_hertz = std::pow(M * (a + 1) * v0 * v0 / (2 * K), 1 / (a + 1));
  for (const auto& law : all_laws({K, a, 1.0}, v0)) {
    INFO(contact_law_name(law));
    CHECK(damping_factor(law) == 0.0);
    CHECK(rel(max_deformation(law, M), d_hertz) < 1e-15);
    CHECK(rel(max_force_exact(law, M), K * std::pow(d_hertz, a)) < 1e-15);
    CHECK(exact_peak(law, M).deformation_rate == 0.0);
    CHECK(relative_error(law) == 0.0);
    CHECK_FALSE(std::signbit(relative_error(law)));  // +0: the outputs print it as 0, not -0
  }
  // c_r = 1 - 1e-12 against c_r = 1: relative agreement 1e-9 (the change is O(f) ~ 1e-12).
  const auto at1 = all_laws({K, a, 1.0}, v0);
  const auto near1 = all_laws({K, a, 1.0 - 1e-12}, v0);
  for (std::size_t i = 0; i < at1.size(); ++i) {
    INFO(contact_law_name(at1[i]));
    CHECK(damping_factor(near1[i]) > 0.0);
    CHECK(rel(max_deformation(near1[i], M), max_deformation(at1[i], M)) < 1e-9);
    CHECK(rel(zeta(near1[i]), zeta(at1[i])) < 1e-9);
    CHECK(rel(max_force_exact(near1[i], M), max_force_exact(at1[i], M)) < 1e-9);
    CHECK(rel(exact_peak(near1[i], M).deformation, exact_peak(at1[i], M).deformation) < 1e-9);
    CHECK(std::abs(relative_error(near1[i])) < 1e-9);  // ξ in percent, -> 0
  }
}

TEST_CASE("G(s) = g(s)/f² of Eq. 19: series and log1p branches against long double", "[contact]") {
  // Reference: g(s) = f(1-s) + ln((1+fs)/(1+f)) in long double, only where f >= 0.05 so that its
  // own cancellation (about 1/f) leaves ~1e-17 accuracy. Tolerance 1e-13 relative.
  for (double f : {0.05, 0.2, 0.33, 0.5, 1.0, 3.0, 14.4}) {
    for (double s = -0.3; s < 0.999; s += 0.0371) {
      if (1 + f * s <= 0) continue;
      const long double F = f, S = s;
      const long double g = F * (1 - S) + std::log1p(F * S) - std::log1p(F);
      const double G = static_cast<double>(g / (F * F));
      INFO("f = " << f << " s = " << s);
      CHECK(rel(detail::contact_G(f, s), G) < 1e-13);
    }
  }
  // Small f: G(s) = (1-s²)/2 - f(1-s³)/3 + f²(1-s⁴)/4 - ... (the series in f of the brief).
  for (double f : {0.0, 1e-12, 1e-6, 1e-3}) {
    for (double s : {0.0, 0.3, 0.9, 0.999999}) {
      const double ref = (1 - s * s) / 2 - f * (1 - s * s * s) / 3 + f * f * (1 - std::pow(s, 4)) / 4 -
                         f * f * f * (1 - std::pow(s, 5)) / 5;
      INFO("f = " << f << " s = " << s);
      CHECK(rel(detail::contact_G(f, s), ref) < 1e-10);  // 1 - s^k loses digits near s = 1
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Figures 3-6: the exact maximum and the relative error ξ (Eq. 21)
// ---------------------------------------------------------------------------------------------

TEST_CASE("the exact maximum: above the closed form, above a dense scan, stationary", "[contact]") {
  const double M = 5.0;
  for (double c : {0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 1.0}) {
    for (const auto& law : all_laws({1e9, 1.5, c}, 0.2)) {
      INFO(contact_law_name(law) << " c_r = " << c);
      const ForcePeak pk = exact_peak(law, M);
      // F_max >= F'_max (the maximum over the contact includes s = 0); rounding 1e-14.
      CHECK(pk.force >= max_force_estimate(law, M) * (1 - 1e-14));
      CHECK(pk.force >= max_force_closed_form(law, M) * (1 - 1e-14));
      // A dense scan of F(s), s in [0, 1], 1e5 + 1 points, never exceeds F_max beyond rounding.
      double scan = 0;
      for (int i = 0; i <= 100000; ++i) scan = std::max(scan, force_at_rate(law, M, i / 100000.0));
      CHECK(scan <= pk.force * (1 + 1e-14));
      CHECK(scan >= pk.force * (1 - 1e-8));  // and gets close to it (grid 1e-5, quadratic peak)
      // Stationarity: central difference of F(s) at s*, step 1e-5: |dF/ds| < 1e-7 F_max, whereas
      // at s = 0 the slope is f F (Eq. 15), i.e. f F'_max.
      const double s = pk.deformation_rate / 0.2;
      if (s > 1e-5) {
        const double dF = (force_at_rate(law, M, s + 1e-5) - force_at_rate(law, M, s - 1e-5)) / 2e-5;
        CHECK(std::abs(dF) < 1e-7 * pk.force);
        // and (α+1) g(s) - α f s = 0 there (the stationarity condition), relative to α f s: 1e-12.
        const double f = damping_factor(law);
        const double phi = 2.5 * f * detail::contact_G(f, s) - 1.5 * s;
        CHECK(std::abs(phi) < 1e-12 * 1.5 * s);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// CVODE integration of the single-body model Eq. 16
// ---------------------------------------------------------------------------------------------

TEST_CASE("exact maximum vs CVODE integration of Eq. 16, all laws", "[contact][cvode]") {
  const double M = 5.0, v0 = 0.2;
  double worst = 0;
  for (double c : {0.3, 0.5, 0.7, 0.9, 0.99, 1.0}) {
    for (const auto& law : all_laws({1e9, 1.5, c}, v0)) {
      INFO(contact_law_name(law) << " c_r = " << c);
      const SingleBodyResult sim = simulate_single_body(law, M);
      const ForcePeak pk = exact_peak(law, M);
      // Tolerance 1e-6 relative; CVODE runs at rtol 1e-10.
      CHECK(rel(sim.f_max, pk.force) < 1e-6);
      worst = std::max(worst, rel(sim.f_max, pk.force));
      // δ_max of Eq. 20 is exact for Eq. 16: 1e-6 relative.
      CHECK(rel(sim.delta_max, max_deformation(law, M)) < 1e-6);
      // Where the peak is: δ'_max to 1e-6 relative, δ̇ there to 1e-6 of δ̇⁻.
      CHECK(rel(sim.delta_at_f_max, pk.deformation) < 1e-6);
      CHECK(std::abs(sim.delta_dot_at_f_max - pk.deformation_rate) < 1e-6 * v0);
      CHECK(sim.t_at_f_max <= sim.t_at_delta_max * (1 + 1e-9));
      CHECK(sim.contact_duration > sim.t_at_delta_max);
      CHECK(sim.restitution > 0.0);
      CHECK(sim.restitution <= 1.0 + 1e-6);
      // The separation speed is the end of the trajectory Eq. 19: δ(δ̇_sep) = 0, i.e. g(s_sep) = 0.
      const double f = damping_factor(law), s_sep = sim.separation_velocity / v0;
      CHECK(std::abs(detail::contact_G(f, s_sep)) < 1e-7);
    }
  }
  INFO("largest relative deviation exact vs CVODE: " << worst);
  CHECK(worst < 1e-6);
}

TEST_CASE("c_r = 1: CVODE conserves energy (separation speed = approach speed)", "[contact][cvode]") {
  for (const auto& law : all_laws({1e9, 1.5, 1.0}, 0.2)) {
    INFO(contact_law_name(law));
    const SingleBodyResult sim = simulate_single_body(law, 3.0);
    // Energy: ½ M δ̇_sep² = ½ M δ̇⁻² (no damping), tolerance 1e-6 relative.
    CHECK(sim.separation_velocity == Approx(-0.2).epsilon(1e-6));
    CHECK(sim.restitution == Approx(1.0).epsilon(1e-6));
    // Elastic Hertz: the impact is symmetric, duration = 2 t(δ_max), 1e-6 relative.
    CHECK(sim.contact_duration == Approx(2 * sim.t_at_delta_max).epsilon(1e-6));
    // Known Hertz duration: t_c = 2 (δ_max/δ̇⁻) ∫_0^1 dx/sqrt(1 - x^(5/2)) = 2 · 1.4716 δ_max/δ̇⁻
    // (the integral is B(2/5, 1/2)/(5/2) = 1.47161...); tolerance 1e-4 relative on the constant.
    const double d_max = max_deformation(law, 3.0);
    CHECK(sim.contact_duration / (d_max / 0.2) == Approx(2 * 1.4716).epsilon(1e-4));
  }
}

TEST_CASE("single-body time series on request", "[contact][cvode]") {
  const HertzDamped<HerbertMcWhannell> law(kPaper, 0.2);
  SingleBodyOptions opt;
  opt.record_series = true;
  const SingleBodyResult sim = simulate_single_body(law, 5.0, opt);
  const auto& s = sim.series;
  REQUIRE(s.t.size() > 10);
  REQUIRE(s.force.size() == s.t.size());
  REQUIRE(s.delta.size() == s.t.size());
  CHECK(s.t.front() == 0.0);
  CHECK(s.t.back() == Approx(sim.contact_duration).epsilon(1e-12));
  CHECK(std::is_sorted(s.t.begin(), s.t.end()));
  // No sample above the located peak (beyond the integration tolerance 1e-8), none negative.
  CHECK(*std::max_element(s.force.begin(), s.force.end()) <= sim.f_max * (1 + 1e-8));
  CHECK(*std::min_element(s.force.begin(), s.force.end()) >= 0.0);
  // Every sample lies on the law (Eq. 15), identity 1e-14.
  for (std::size_t i = 0; i < s.t.size(); ++i)
    CHECK(s.force[i] == Approx(law.force(s.delta[i], s.delta_dot[i])).epsilon(1e-14).margin(1e-300));
  // Same peak as without series (1e-9).
  CHECK(sim.f_max == Approx(simulate_single_body(law, 5.0).f_max).epsilon(1e-9));
}

// ---------------------------------------------------------------------------------------------
// Input validation
// ---------------------------------------------------------------------------------------------

TEST_CASE("bad contact inputs are InputErrors that name the parameter", "[contact]") {
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  auto make = [](ContactParams p, double v0) { return make_contact_law("hunt-crossley", p, v0); };
  CHECK_THROWS_WITH(make({-1e9, 1.5, 0.9}, 0.2), Contains("stiffness K") && Contains("-1000000000"));
  CHECK_THROWS_WITH(make({0.0, 1.5, 0.9}, 0.2), Contains("stiffness K"));
  CHECK_THROWS_WITH(make({inf, 1.5, 0.9}, 0.2), Contains("stiffness K"));
  CHECK_THROWS_WITH(make({nan, 1.5, 0.9}, 0.2), Contains("stiffness K"));
  CHECK_THROWS_WITH(make({1e9, 0.0, 0.9}, 0.2), Contains("exponent alpha"));
  CHECK_THROWS_WITH(make({1e9, -1.5, 0.9}, 0.2), Contains("exponent alpha"));
  CHECK_THROWS_WITH(make({1e9, nan, 0.9}, 0.2), Contains("exponent alpha"));
  CHECK_THROWS_WITH(make({1e9, 1.5, 0.0}, 0.2), Contains("restitution c_r") && Contains("got 0"));
  CHECK_THROWS_WITH(make({1e9, 1.5, 1.1}, 0.2), Contains("restitution c_r") && Contains("1.1"));
  CHECK_THROWS_WITH(make({1e9, 1.5, -0.5}, 0.2), Contains("restitution c_r"));
  CHECK_THROWS_WITH(make({1e9, 1.5, nan}, 0.2), Contains("restitution c_r"));
  CHECK_THROWS_WITH(make({1e9, 1.5, 0.9}, -0.1), Contains("approach velocity") && Contains("receding"));
  CHECK_THROWS_WITH(make({1e9, 1.5, 0.9}, 0.0), Contains("approach velocity"));
  CHECK_THROWS_WITH(make({1e9, 1.5, 0.9}, nan), Contains("approach velocity"));
  CHECK_THROWS_AS(make({-1e9, 1.5, 0.9}, 0.2), InputError);
  CHECK_THROWS_AS(make({1e9, 1.5, 0.9}, -0.1), InputError);
  CHECK_THROWS_AS((HertzDamped<Flores>({1e9, 1.5, 0.0}, 0.2)), InputError);  // f would be inf

  const auto law = make({1e9, 1.5, 0.9}, 0.2);
  for (double M : {0.0, -1.0, nan, inf}) {
    CHECK_THROWS_WITH(max_force_closed_form(law, M), Contains("M_ie"));
    CHECK_THROWS_WITH(max_force_exact(law, M), Contains("M_ie"));
    CHECK_THROWS_WITH(max_deformation(law, M), Contains("M_ie"));
    CHECK_THROWS_AS(max_force_estimate(law, M), InputError);
    CHECK_THROWS_AS(simulate_single_body(law, M), InputError);
  }
  // A rate the contact never reaches (faster than the approach).
  CHECK_THROWS_AS(std::get<0>(law).deformation(1.0, 0.3), InputError);

  // Unknown name: the message lists every valid one.
  try {
    make_contact_law("hertz", kPaper, 0.2);
    FAIL("no exception for an unknown law");
  } catch (const InputError& e) {
    const std::string msg = e.what();
    CHECK_THAT(msg, Contains("'hertz'"));
    for (std::string_view n : contact_law_names()) CHECK_THAT(msg, Contains(std::string(n)));
  }
  // Eq. 32.
  CHECK(model_accuracy(0.834e3, 0.844e3) == Approx(100 * (1 - 0.01 / 0.844)).epsilon(1e-12));
  CHECK_THROWS_AS(model_accuracy(1.0, 0.0), InputError);
  CHECK_THROWS_AS(model_accuracy(nan, 1.0), InputError);
}

// ---------------------------------------------------------------------------------------------
// The CVODE wrapper
// ---------------------------------------------------------------------------------------------

namespace {
struct MyError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// y'' = -y as a first-order system: y = (sin t, cos t) from (0, 1).
void oscillator(double, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> yd) {
  yd[0] = y[1];
  yd[1] = -y[0];
}
}  // namespace

TEST_CASE("cvode: harmonic oscillator with a root", "[cvode]") {
  cvode::Roots g = [](double, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> out) {
    out[0] = y[0];  // sin t: zero at 0 (ignored), π (decreasing), 2π (increasing)
  };
  cvode::Integrator integ(oscillator, Eigen::Vector2d(0, 1), 0.0, {}, 1, g, {-1});
  REQUIRE(integ.advance(10.0) == cvode::Integrator::Status::Root);
  // Root at t = π (exact solution), tolerance 1e-8.
  CHECK(integ.t() == Approx(kPi).epsilon(1e-8));
  CHECK(integ.roots_found() == std::vector<int>{-1});
  CHECK(integ.y()[1] == Approx(-1.0).epsilon(1e-8));
  // Dense output inside the last step matches sin/cos to 1e-8 (absolute).
  CHECK(integ.current_time() >= integ.t());
  const double tm = integ.current_time() - 0.5 * integ.last_step();
  const Eigen::VectorXd ym = integ.interpolate(tm);
  CHECK(std::abs(ym[0] - std::sin(tm)) < 1e-8);
  CHECK(std::abs(ym[1] - std::cos(tm)) < 1e-8);
  CHECK_THROWS_AS(integ.interpolate(integ.t() - 5.0), IntegrationError);  // outside the last step
  // The increasing crossing at 2π is skipped (direction -1); the next decreasing one is 3π.
  CHECK(integ.advance(10.0) == cvode::Integrator::Status::Root);
  CHECK(integ.t() == Approx(3 * kPi).epsilon(1e-8));
  CHECK(integ.advance(10.0) == cvode::Integrator::Status::Reached);
  CHECK(integ.t() == 10.0);
  CHECK(integ.y()[0] == Approx(std::sin(10.0)).margin(1e-8));
  CHECK(integ.num_steps() > 0);
  CHECK(integ.num_rhs_evals() >= integ.num_steps());

  // Step mode never passes the stop time and ends exactly on it.
  cvode::Integrator stepper(oscillator, Eigen::Vector2d(0, 1), 0.0);
  int n = 0;
  cvode::Integrator::Status st{};
  while ((st = stepper.step(1.0)) == cvode::Integrator::Status::Step && n < 100000) {
    CHECK(stepper.t() < 1.0);
    ++n;
  }
  CHECK(st == cvode::Integrator::Status::Reached);
  CHECK(stepper.t() == 1.0);
  CHECK(stepper.y()[0] == Approx(std::sin(1.0)).margin(1e-9));

  // Move-only, and a moved integrator carries on.
  cvode::Integrator moved = std::move(stepper);
  CHECK(moved.advance(2.0) == cvode::Integrator::Status::Reached);
  CHECK(moved.y()[0] == Approx(std::sin(2.0)).margin(1e-9));
  // reinit restarts from a new state.
  moved.reinit(0.0, Eigen::Vector2d(1, 0));
  moved.advance(1.0);
  CHECK(moved.y()[0] == Approx(std::cos(1.0)).margin(1e-9));
  // Per-component absolute tolerances.
  cvode::Options o;
  o.atol_vector = Eigen::Vector2d(1e-12, 1e-12);
  cvode::Integrator sv(oscillator, Eigen::Vector2d(0, 1), 0.0, o);
  sv.advance(3.0);
  CHECK(sv.y()[0] == Approx(std::sin(3.0)).margin(1e-8));
}

TEST_CASE("cvode: an exception in the right-hand side propagates unchanged", "[cvode]") {
  cvode::Rhs throwing_later = [](double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                                 Eigen::Ref<Eigen::VectorXd> yd) {
    if (t > 0.5) throw MyError("boom at t > 0.5");
    oscillator(t, y, yd);
  };
  cvode::Integrator a(throwing_later, Eigen::Vector2d(0, 1), 0.0);
  CHECK_THROWS_AS(a.advance(1.0), MyError);
  CHECK_THROWS_WITH(cvode::Integrator(throwing_later, Eigen::Vector2d(0, 1), 0.0).advance(1.0),
                    "boom at t > 0.5");
  // Throwing on the very first evaluation, and in step mode.
  cvode::Rhs always = [](double, const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd>) {
    throw MyError("always");
  };
  cvode::Integrator b(always, Eigen::Vector2d(0, 1), 0.0);
  CHECK_THROWS_AS(b.step(1.0), MyError);
  // A throwing root function too.
  cvode::Roots bad_root = [](double t, const Eigen::Ref<const Eigen::VectorXd>&,
                             Eigen::Ref<Eigen::VectorXd> g) {
    if (t > 0.1) throw MyError("root");
    g[0] = 1;
  };
  cvode::Integrator c(oscillator, Eigen::Vector2d(0, 1), 0.0, {}, 1, bad_root);
  CHECK_THROWS_AS(c.advance(1.0), MyError);
  // A non-finite derivative is an IntegrationError that says so.
  cvode::Rhs nan_rhs = [](double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                          Eigen::Ref<Eigen::VectorXd> yd) {
    oscillator(t, y, yd);
    if (t > 0.2) yd[1] = std::nan("");
  };
  cvode::Integrator d(nan_rhs, Eigen::Vector2d(0, 1), 0.0);
  CHECK_THROWS_WITH(d.advance(1.0), Contains("ydot[1]") && Contains("nan"));
}

TEST_CASE("cvode: failures are IntegrationErrors naming the flag", "[cvode]") {
  cvode::Options few;
  few.max_num_steps = 5;
  cvode::Integrator a(oscillator, Eigen::Vector2d(0, 1), 0.0, few);
  CHECK_THROWS_AS(a.advance(100.0), IntegrationError);
  CHECK_THROWS_WITH(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, few).advance(100.0),
                    Contains("CV_TOO_MUCH_WORK") && Contains("at t = "));
  cvode::Options tight;
  tight.rtol = 1e-30;
  tight.atol = 1e-300;
  CHECK_THROWS_WITH(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, tight).advance(1.0),
                    Contains("CV_TOO_MUCH_ACC"));
  // Bad options and arguments are InputErrors.
  cvode::Options o;
  o.max_num_steps = 0;
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, o), InputError);
  o = {};
  o.rtol = -1;
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, o), InputError);
  o = {};
  o.max_order = 6;
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, o), InputError);
  o = {};
  o.atol_vector = Eigen::Vector3d::Constant(1e-10);
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, o), InputError);
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, std::nan("")), 0.0), InputError);
  CHECK_THROWS_AS(cvode::Integrator({}, Eigen::Vector2d(0, 1), 0.0), InputError);
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, {}, 2, {}), InputError);
  cvode::Roots g = [](double, const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> out) {
    out[0] = y[0];
  };
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, {}, 1, g, {-1, 1}), InputError);
  CHECK_THROWS_AS(cvode::Integrator(oscillator, Eigen::Vector2d(0, 1), 0.0, {}, 1, g, {2}), InputError);
  cvode::Integrator b(oscillator, Eigen::Vector2d(0, 1), 1.0);
  CHECK_THROWS_AS(b.advance(0.5), InputError);  // forward only
  CHECK_THROWS_AS(b.step(std::nan("")), InputError);
  CHECK_THROWS_AS(b.reinit(0.0, Eigen::Vector3d::Zero()), InputError);
}

// fuzz finding ../shared/findings/fuzz_numeric-xi-inf.bin (Hu-Guo, K = 2.3e-307, α = 5.7e-320,
// c_r = 4.4e-18): with a tiny exponent the force peak sits next to first touch, t* = 1 - s* ~ α.
// Solved in s it rounded to s* = 1, where G = 0: ξ came out as -inf and the exact peak as F = 0.
// The peak is now solved in t where t* < 1/2. Independent limit: as α -> 0 the factor
// (G(0)/G*)^(α/(α+1)) -> 1 and s* -> 1, so F'/F -> 1/(1+f) and ξ -> 100 f/(1+f).
TEST_CASE("the force peak next to first touch (tiny exponent) is found, and ξ is finite", "[contact][fuzz]") {
  // f·G written without the underflow of G equals f times G where G is a normal number
  for (double f : {1e-6, 0.1, 1.5, 1e3, 3e17})
    for (double t : {1e-12, 1e-3, 0.3, 0.9, 1.0})
      CHECK(rel(detail::contact_fG_lost(f, t), f * detail::contact_G_lost(f, t)) < 1e-13);
  for (double c_r : {0.5, 0.9, 4.394556650046182e-18}) {
    for (double alpha : {1e-3, 1e-8, 1e-13, 1e-17, 1e-100, 5.7035e-320}) {
      for (double K : {1e9, 2.2634620632562607e-307}) {
        const ContactParams p{K, alpha, c_r};
        const auto law = make_contact_law("hu-guo", p, 0.2052);
        const double f = damping_factor(law);
        INFO("c_r = " << c_r << ", alpha = " << alpha << ", K = " << K << ", f = " << f);
        const double xi = relative_error(law);
        REQUIRE(std::isfinite(xi));
        CHECK(xi > 0.0);
        CHECK(xi <= 100.0);  // 100 f/(1+f) rounds to 100 for f = 3.4e17
        if (alpha <= 1e-13) CHECK(rel(xi, 100.0 * f / (1.0 + f)) < 1e-9);
        const detail::PeakRate pk = detail::contact_peak(f, alpha);
        CHECK(pk.t > 0.0);
        CHECK(pk.s + pk.t == Approx(1.0).epsilon(1e-15));
        // a maximum of ln F(t) = α/(α+1) ln G(t) + ln(1 + f(1-t)): not below its neighbours
        auto lnF = [&](double t) {
          return alpha / (alpha + 1.0) * detail::contact_log_G_lost(f, t) + std::log1p(f * (1.0 - t));
        };
        for (double d : {1e-3, 1e-6})
          CHECK(lnF(pk.t) >= std::max(lnF(pk.t * (1 - d)), lnF(std::min(1.0, pk.t * (1 + d)))) -
                                 1e-14 * std::max(1.0, std::abs(lnF(pk.t))));  // rounding of ln F
        if (K == 1e9 && alpha < 1e-300) {
          // δ at the peak (~t* ~ 1e-320 m) is not representable: an error, never F = 0
          CHECK_THROWS_AS(exact_peak(law, 5.8158), NumericalError);
        } else if (K == 1e9) {
          const ForcePeak peak = exact_peak(law, 5.8158);
          CHECK(peak.force > 0.0);
          CHECK(std::isfinite(peak.force));
          CHECK(peak.force >= max_force_estimate(law, 5.8158) * (1 - 1e-14));
        }
      }
    }
  }
}

TEST_CASE("finite inputs whose arithmetic overflows are NumericalErrors, not NaN or inf", "[contact][fuzz]") {
  // the values of the fuzz_numeric finding tests/data/fuzz_regressions/fuzz_numeric/approach_velocity_nan:
  // omega_t x r passes 1e308 in y and z, and u . (...) multiplies the infinite y by u_y = 0 (NaN)
  const Eigen::Vector3d u(6.663691e-317, 0.0, 1.0), v_e(0.0, 0.0, 0.0),
      v_t(200.0, 100.0, 3.893880265755862e-308), omega_t(-9.255963143549733e+61, -4.783214422640232e+300,
                                                         4.228978974595545e+159),
      r(-3.197300970554343e+168, 1.27855629e-314, 8.1387e-320);
  CHECK_THROWS_AS(approach_velocity(u, v_e, v_t, omega_t, r), NumericalError);
  CHECK_THROWS_WITH(approach_velocity(u, v_e, v_t, omega_t, r),
                    Contains("approach_velocity") && Contains("overflows"));
  // the same failure from the README's values (Python: ffsr.approach_velocity([1,0,0], ...))
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), zero = Eigen::Vector3d::Zero();
  const Eigen::Vector3d spin(0, 0, 1e200);
  CHECK_THROWS_AS(approach_velocity(x, 0.2 * x, zero, spin, 1e200 * x), NumericalError);
  CHECK_THROWS_AS(approach_velocity(x, 1e308 * x, -1e308 * x, zero, zero), NumericalError);  // v_e - v_t
  CHECK(approach_velocity(x, 1e300 * x, zero, Eigen::Vector3d(0, 0, 1e150), 1e150 * x) ==
        1e300);  // large but representable: omega_t x r = 1e300 along y is finite, u_y = 0 drops it
  // the law's constants and its force
  CHECK_THROWS_AS(make_contact_law("hunt-crossley", {1e9, 1.5, 0.9}, 1e200), NumericalError);  // zeta
  CHECK_THROWS_AS(make_contact_law("flores", {1e9, 1.5, 1e-320}, 0.2), NumericalError);         // f(c_r)
  const AnyContactLaw law = make_contact_law("hunt-crossley", kPaper, 0.2);
  CHECK_THROWS_AS(force(law, 1e300, 0.0), NumericalError);    // K delta^alpha
  CHECK_THROWS_AS(force(law, 1e-3, 1e305), NumericalError);   // K + lambda delta_dot
  CHECK(std::isnan(force(law, 1e-3, std::nan(""))));          // NaN still propagates
  CHECK(force(law, 1e-3, 0.1) > 0.0);
}

}  // namespace test_contact
