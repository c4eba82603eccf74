// The paper's contact forces: the approach velocities (Eq. 10-12), the closed-form F_max columns of
// Tables 3 and 6, the CVODE multibody F_max and the model accuracy (Eq. 32), and Figures 3-6 (the
// exact maximum and the relative error xi, Eq. 21).
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/contact/contact_law.hpp"
#include "ffsr/contact/damping.hpp"
#include "ffsr/errors.hpp"
#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "ffsr/simulate/single_body.hpp"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace test_paper_contact {

using namespace ffsr;
using ffsr::test::deg, ffsr::test::kPaperContact, ffsr::test::kRobots, ffsr::test::paper_target;

namespace {

constexpr double kDeg = M_PI / 180.0;

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

// The paper's contact parameters (Sections 5.1.1 and 5.2.1).
const ContactParams& kPaper = kPaperContact;

/// The closed-form F_max (Herbert-McWhannell, the paper's contact) at each row's M_ie [kg] against the
/// paper's "Proposed Method" [kN] within 0.3 %, for a target spinning at w_t with contact offset r_tp.
template <class Rows>
void check_closed_form(const Eigen::Vector3d& w_t, const Eigen::Vector3d& r_tp, const Rows& rows) {
  const double v0 = approach_velocity(Eigen::Vector3d::UnitX(), Eigen::Vector3d(0.2, 0, 0),
                                      Eigen::Vector3d::Zero(), w_t, r_tp);
  const auto law = make_contact_law("herbert-mcwhannell", kPaper, v0);
  for (const auto& [M, paper_kN] : rows) {
    const double F = max_force_closed_form(law, M);
    INFO("M_ie = " << M << " kg: ours " << F / 1e3 << " kN, paper " << paper_kN << " kN");
    CHECK(rel(F / 1e3, paper_kN) < 3e-3);
  }
}

}  // namespace

TEST_CASE("Eq. 10-12: the approach velocities of the paper's scenarios", "[contact][paper]") {
  const Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d v_e = 0.2 * u, v_t = Eigen::Vector3d::Zero();
  // 3-DOF: ω = [0, 0, 2] deg/s, r = [-0.25, 0.15, 0]; u·(ω × r) = -0.15 ω_z by hand.
  const double v3 =
      approach_velocity(u, v_e, v_t, Eigen::Vector3d(0, 0, 2 * kDeg), Eigen::Vector3d(-0.25, 0.15, 0));
  CHECK(v3 == Approx(0.2 + 0.15 * 2 * kDeg).epsilon(1e-15));
  CHECK(v3 == Approx(0.2052).margin(5e-5));  // ≈ 0.2052 m/s, Eq. 10-12 by hand
  // 7-DOF: ω = [1, -0.5, 2] deg/s, r = [-0.25, 0.15, 0.1]; (ω × r)_x = ω_y r_z - ω_z r_y.
  const double v7 =
      approach_velocity(u, v_e, v_t, Eigen::Vector3d(1, -0.5, 2) * kDeg, Eigen::Vector3d(-0.25, 0.15, 0.1));
  CHECK(v7 == Approx(0.2 - (-0.5 * 0.1 - 2 * 0.15) * kDeg).epsilon(1e-15));
  CHECK(v7 == Approx(0.2061).margin(5e-5));  // ≈ 0.2061 m/s, Eq. 10-12 by hand
  // A moving target along u reduces the approach velocity one for one (Eq. 12).
  CHECK(approach_velocity(u, v_e, 0.05 * u, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()) ==
        Approx(0.15).epsilon(1e-15));
  CHECK_THROWS_AS(approach_velocity(2 * u, v_e, v_t, v_t, v_t), InputError);
  CHECK_THROWS_AS(approach_velocity(u, Eigen::Vector3d(std::nan(""), 0, 0), v_t, v_t, v_t), InputError);
}

TEST_CASE("Table 3 (3-DOF): closed-form F_max at the paper's M_ie within 0.3 %", "[contact][paper]") {
  // Table 3: integrated effective mass [kg] and "Proposed Method" [kN].
  const std::array<std::pair<double, double>, 10> rows{{{1.555, 0.834},
                                                        {1.648, 0.863},
                                                        {3.679, 1.397},
                                                        {4.299, 1.534},
                                                        {5.817, 1.840},
                                                        {5.926, 1.860},
                                                        {7.446, 2.133},
                                                        {9.635, 2.490},
                                                        {13.74, 3.081},
                                                        {21.093, 3.985}}};
  check_closed_form(Eigen::Vector3d(0, 0, 2 * kDeg), Eigen::Vector3d(-0.25, 0.15, 0), rows);
}

TEST_CASE("Table 6 (7-DOF): closed-form F_max at the paper's M_ie within 0.3 %", "[contact][paper]") {
  // Table 6: integrated effective mass [kg] and "Proposed Method" [kN].
  const std::array<std::pair<double, double>, 10> rows{{{4.875, 1.664},
                                                        {7.876, 2.218},
                                                        {2.848, 1.205},
                                                        {3.061, 1.258},
                                                        {3.167, 1.284},
                                                        {5.003, 1.690},
                                                        {2.513, 1.118},
                                                        {1.658, 0.871},
                                                        {2.677, 1.161},
                                                        {1.495, 0.819}}};
  check_closed_form(Eigen::Vector3d(1, -0.5, 2) * kDeg, Eigen::Vector3d(-0.25, 0.15, 0.1), rows);
}

TEST_CASE("Figure 3: both points, Gonthier, M = 1 kg, K = 1e9, 0.2 m/s, c_r = 0.5", "[contact][paper]") {
  const HertzDamped<Gonthier> law({1e9, 1.5, 0.5}, 0.2);
  const double M = 1.0;
  const ForcePeak pk = law.exact_peak(M);       // "*" : (δ'_max, F_max)
  const double d_max = law.max_deformation(M);  // "o" : (δ_max, F'_max)
  const double F_est = law.max_force_estimate(M);
  INFO("(delta'_max, F_max) = (" << pk.deformation << " m, " << pk.force << " N), (delta_max, F'_max) = ("
                                 << d_max << " m, " << F_est << " N), xi = " << law.relative_error() << " %");
  CHECK(pk.deformation < d_max);
  CHECK(pk.force > F_est);
  CHECK(pk.deformation_rate > 0.0);
  CHECK(pk.deformation_rate < 0.2);
  // Each point lies on the law (Eq. 15), tolerance 1e-14 relative.
  CHECK(rel(law.force(pk.deformation, pk.deformation_rate), pk.force) < 1e-14);
  CHECK(rel(law.force(d_max, 0.0), F_est) < 1e-14);
  // The point "*" lies on the trajectory of Eq. 19 (identity, 1e-14).
  CHECK(rel(law.deformation(M, pk.deformation_rate), pk.deformation) < 1e-14);
  // Eq. 21 from the two points equals relative_error() (percent; 1e-10 relative).
  CHECK(rel((pk.force - F_est) / pk.force * 100, law.relative_error()) < 1e-10);
}

TEST_CASE("Figures 4-5: ξ does not depend on K or on the approach velocity", "[contact][paper]") {
  for (std::string_view name : contact_law_names()) {
    const double xi_ref = relative_error(make_contact_law(name, kPaper, 0.2));
    INFO(name << ": xi(c_r = 0.9) = " << xi_ref << " %");
    CHECK(xi_ref > 0.0);
    // Figure 4: K from 1e7 to 1e11 at δ̇⁻ = 0.2; ξ from the two maxima (Eq. 21); < 1e-6 relative.
    for (double K : {1e7, 1e8, 1e9, 1e10, 1e11}) {
      const auto law = make_contact_law(name, {K, 1.5, 0.9}, 0.2);
      const double xi =
          (max_force_exact(law, 1.0) - max_force_estimate(law, 1.0)) / max_force_exact(law, 1.0) * 100;
      CHECK(rel(xi, xi_ref) < 1e-6);
      CHECK(rel(relative_error(law), xi_ref) < 1e-6);
    }
    // Figure 5: δ̇⁻ from 0.01 to 1 m/s at K = 1e9; < 1e-6 relative.
    for (double v0 : {0.01, 0.05, 0.1, 0.5, 1.0}) {
      const auto law = make_contact_law(name, kPaper, v0);
      const double xi =
          (max_force_exact(law, 2.5) - max_force_estimate(law, 2.5)) / max_force_exact(law, 2.5) * 100;
      CHECK(rel(xi, xi_ref) < 1e-6);
    }
  }
}

TEST_CASE("Figure 6: ξ decreases as c_r grows, for every law", "[contact][paper]") {
  for (std::string_view name : contact_law_names()) {
    double previous = std::numeric_limits<double>::infinity();
    for (double c = 0.1; c < 0.995; c += 0.01) {
      const double xi = relative_error(make_contact_law(name, {1e9, 1.5, c}, 0.2));
      INFO(name << " c_r = " << c << " xi = " << xi << " % (previous " << previous << ")");
      CHECK(xi > 0.0);
      CHECK(xi < previous);  // strictly decreasing (Figure 6)
      previous = xi;
    }
  }
}

namespace {

struct Row {
  Eigen::VectorXd q;
  double paper_closed_kN, paper_numerical_kN;
};

/// One row of Tables 3 and 6: the CVODE multibody contact (Herbert-McWhannell, the paper's contact,
/// 0.2 m/s) at the capture configuration q, with the closed-form and the single-body exact F_max at its
/// M_ie and approach velocity.
struct MultibodyRow {
  MultibodyContactResult mb;
  double closed, exact;
};
MultibodyRow multibody_row(const Model& m, const Eigen::VectorXd& q, bool seven_dof) {
  const MultibodyContactResult mb = simulate_contact(m, BasePose{}, q, m.end_effector(), paper_target(seven_dof),
                                                     0.2, kPaperContact, "herbert-mcwhannell");
  const AnyContactLaw law = make_contact_law("herbert-mcwhannell", kPaperContact, mb.approach_velocity);
  return {mb, max_force_closed_form(law, mb.integrated_effective_mass),
          max_force_exact(law, mb.integrated_effective_mass)};
}

}  // namespace

TEST_CASE("Table 3: the CVODE multibody F_max and the model accuracy of Eq. 32", "[simulate][paper]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  // Table 3: capture configuration, "Proposed Method" and "Numerical Integration Method" columns (kN)
  const std::vector<Row> rows = {{deg({36, 30, -4}), 0.834, 0.844},  {deg({85, -41, 11}), 0.863, 0.873},
                                 {deg({-75, 30, 12}), 1.397, 1.414}, {deg({10, 86, -76}), 1.534, 1.552},
                                 {deg({0, 90, -90}), 1.840, 1.861},  {deg({30, 21, -56}), 1.860, 1.882},
                                 {deg({54, -30, -5}), 2.133, 2.158}, {deg({-10, -18, 30}), 2.490, 2.519},
                                 {deg({46, -45, 0}), 3.081, 3.119},  {deg({-6, 20, -7}), 3.985, 4.036}};
  for (const Row& r : rows) {
    const auto [mb, closed, exact] = multibody_row(m, r.q, false);
    const double accuracy = model_accuracy(closed, mb.f_max);
    INFO("q = " << (r.q * 180 / M_PI).transpose() << "  M_ie " << mb.integrated_effective_mass
                << "  multibody " << mb.f_max << " N (paper " << r.paper_numerical_kN * 1e3 << ")  accuracy "
                << accuracy << " %");
    // the paper's rows are rounded to whole degrees (see the dynamics tests): 2.5 %
    CHECK(mb.f_max == Approx(r.paper_numerical_kN * 1e3).epsilon(0.025));
    CHECK(accuracy > 98.5);
    CHECK(accuracy < 99.5);
    // the contact lasts ~2 ms: the multibody peak is the single-body exact peak within 0.5 %
    CHECK(mb.f_max == Approx(exact).epsilon(0.005));
    // delta_dot^- = 0.2 + (w_t x r_tp)_x = 0.2 + 2 deg/s * 0.15 m (Eq. 10-12)
    CHECK(mb.approach_velocity == Approx(0.2 + 2 * M_PI / 180 * 0.15).epsilon(1e-9));
  }
}

TEST_CASE("Table 6: multibody F_max beside the paper's, against the single-body exact peak",
          "[simulate][paper]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  const std::vector<Row> rows = {{deg({0, 29, 54, 10, -10, 120, 32}), 1.664, 1.659},
                                 {deg({10, -2, 160, 0, 33, -5, 80}), 2.218, 2.213},
                                 {deg({55, -22, 45, 11, 36, -10, 160}), 1.205, 1.202},
                                 {deg({-10, 30, 60, -45, 0, 22, 4}), 1.258, 1.255},
                                 {deg({23, 33, -64, 145, 34, 88, 60}), 1.284, 1.281},
                                 {deg({74, -20, 2, 19, 112, 75, -10}), 1.690, 1.686},
                                 {deg({5, 100, 26, -69, 20, 108, -66}), 1.118, 1.115},
                                 {deg({100, 23, 126, -6, 34, 34, -1}), 0.871, 0.869},
                                 {deg({1, 110, -90, 90, 14, 150, 45}), 1.161, 1.158},
                                 {deg({-36, 88, 46, 123, -110, 15, 0}), 0.819, 0.817}};
  std::printf(
      "\nTable 6 (7-DOF): M_ie, closed form, CVODE multibody, accuracy; the paper's numerical column\n");
  for (const Row& r : rows) {
    const auto [mb, closed, exact] = multibody_row(m, r.q, true);
    std::printf(
        "  M_ie %7.4f kg  closed %7.4f kN  multibody %7.4f kN  accuracy %6.2f %%   paper %.3f kN (%.3f)\n",
        mb.integrated_effective_mass, closed / 1e3, mb.f_max / 1e3, model_accuracy(closed, mb.f_max),
        r.paper_numerical_kN, r.paper_closed_kN);
    // delta_dot^- = 0.2 - (w_t x r_tp)_x, w_t x r_tp = (wy rz - wz ry) = (-0.5*0.1 - 2*0.15) deg/s m
    CHECK(mb.approach_velocity == Approx(0.2 + (0.5 * 0.1 + 2 * 0.15) * M_PI / 180).epsilon(1e-9));
    CHECK(mb.f_max == Approx(exact).epsilon(0.005));
    CHECK(mb.f_max >= closed);  // the peak of Eq. 16 is never below F at the maximum deformation
  }
}

}  // namespace test_paper_contact
