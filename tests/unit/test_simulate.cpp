// The multibody contact reference (simulate/multibody.hpp) against the paper's Table 3 and Table 6,
// the single-body exact maximum, and conservation laws.
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/io/urdf.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <cstdio>
#include <string>

using namespace ffsr;
using ffsr::test::deg;
using ffsr::test::kRobots;

namespace {

// The paper's target (Sections 5.1 and 5.2): 200 kg, diag(100,100,100), identity attitude.
Target paper_target(bool seven_dof) {
  Target t;
  t.contact_offset = seven_dof ? Vector3(-0.25, 0.15, 0.1) : Vector3(-0.25, 0.15, 0.0);
  t.angular_velocity = (seven_dof ? Vector3(1, -0.5, 2) : Vector3(0, 0, 2)) * (M_PI / 180.0);
  return t;
}

const ContactParams kPaperContact{1e9, 1.5, 0.9};

struct Row {
  Eigen::VectorXd q;
  double paper_closed_kN, paper_numerical_kN;
};

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
    const MultibodyContactResult mb = simulate_contact(
        m, BasePose{}, r.q, m.end_effector(), paper_target(false), 0.2, kPaperContact, "herbert-mcwhannell");
    const AnyContactLaw law = make_contact_law("herbert-mcwhannell", kPaperContact, mb.approach_velocity);
    const double closed = max_force_closed_form(law, mb.integrated_effective_mass);
    const double exact = max_force_exact(law, mb.integrated_effective_mass);
    const double accuracy = model_accuracy(closed, mb.f_max);
    INFO("q = " << (r.q * 180 / M_PI).transpose() << "  M_ie " << mb.integrated_effective_mass
                << "  multibody " << mb.f_max << " N (paper " << r.paper_numerical_kN * 1e3 << ")  accuracy "
                << accuracy << " %");
    // the paper's rows are rounded to whole degrees (see the dynamics tests): 2.5 % (issue 3)
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
    const MultibodyContactResult mb = simulate_contact(
        m, BasePose{}, r.q, m.end_effector(), paper_target(true), 0.2, kPaperContact, "herbert-mcwhannell");
    const AnyContactLaw law = make_contact_law("herbert-mcwhannell", kPaperContact, mb.approach_velocity);
    const double closed = max_force_closed_form(law, mb.integrated_effective_mass);
    const double exact = max_force_exact(law, mb.integrated_effective_mass);
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

TEST_CASE("Multibody contact conserves momentum, and energy without damping", "[simulate]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  BasePose base;
  base.position = Vector3(0.3, -0.2, 0.1);
  base.orientation = Quaternion(Eigen::AngleAxisd(0.3, Vector3(1, 2, 3).normalized()));
  Target t = paper_target(true);
  t.attitude = Quaternion(Eigen::AngleAxisd(0.5, Vector3(0, 1, 1).normalized()));
  t.velocity = Vector3(-0.01, 0.02, 0.0);
  t.inertia << 120, 5, -3, 5, 90, 2, -3, 2, 100;  // non-isotropic, full 3x3
  const Eigen::VectorXd q = deg({10, 40, 60, -30, 20, 50, 10});
  for (double c_r : {0.5, 0.9, 1.0}) {
    const MultibodyContactResult r =
        simulate_contact(m, base, q, m.end_effector(), t, 0.3, {1e9, 1.5, c_r}, "hunt-crossley");
    const double scale = r.momentum_start.norm() + t.mass * 0.3;
    INFO("c_r " << c_r << " dP " << (r.momentum_end - r.momentum_start).transpose());
    // the pair of contact forces is collinear: linear and angular momentum are conserved exactly
    CHECK((r.momentum_end - r.momentum_start).norm() < 1e-9 * scale);
    if (c_r == 1.0) {
      // no damping: the contact is elastic, kinetic energy is the same after the contact
      CHECK(r.energy_end == Approx(r.energy_start).epsilon(1e-7));
      // The normal relative velocity reverses only approximately: the arm keeps moving during the ~2 ms
      // (its effective mass changes by ~1e-3) and exchanges energy with the other coordinates.
      CHECK(r.restitution == Approx(1.0).epsilon(1e-2));
    } else {
      CHECK(r.energy_end < r.energy_start);
      CHECK(r.restitution < 1.0);
      CHECK(r.restitution > 0.0);
    }
    CHECK(r.contact_duration > r.t_at_f_max);
    CHECK(r.delta_max >= r.delta_at_f_max);
  }
  // struck 12 cm away from the end-effector's origin: the force's moment about the origin now acts
  // on the arm; the pair of forces stays collinear and the momentum is still conserved
  MultibodyContactOptions o;
  o.robot_contact_offset = Vector3(0.05, -0.08, 0.07);
  for (double c_r : {0.7, 1.0}) {
    const MultibodyContactResult r =
        simulate_contact(m, base, q, m.end_effector(), t, 0.3, {1e9, 1.5, c_r}, "hunt-crossley", o);
    const double scale = r.momentum_start.norm() + t.mass * 0.3;
    INFO("offset, c_r " << c_r << " dP " << (r.momentum_end - r.momentum_start).transpose());
    CHECK((r.momentum_end - r.momentum_start).norm() < 1e-9 * scale);
    if (c_r == 1.0)
      CHECK(r.energy_end == Approx(r.energy_start).epsilon(1e-7));
    else
      CHECK(r.energy_end < r.energy_start);
    CHECK(r.approach_velocity ==
          Approx(0.3 - t.normal_world().dot(t.velocity + t.angular_velocity_world().cross(t.offset_world())))
              .epsilon(1e-9));
  }
}

TEST_CASE("Multibody contact: series, errors", "[simulate]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  const Eigen::VectorXd q = deg({0, 90, -90});
  MultibodyContactOptions o;
  o.record_series = true;
  const auto r = simulate_contact(m, BasePose{}, q, m.end_effector(), paper_target(false), 0.2, kPaperContact,
                                  "gonthier", o);
  REQUIRE(r.series.size() > 20);
  CHECK(r.series.front().t == 0.0);
  CHECK(r.series.front().delta == Approx(0.0).margin(1e-15));
  for (const auto& s : r.series) CHECK(s.force >= 0.0);
  // receding bodies: the target moves away faster than the end-effector approaches
  Target away = paper_target(false);
  away.velocity = Vector3(0.5, 0, 0);
  CHECK_THROWS_AS(simulate_contact(m, BasePose{}, q, m.end_effector(), away, 0.2, kPaperContact, "gonthier"),
                  InputError);
  CHECK_THROWS_AS(simulate_contact(m, BasePose{}, q, m.end_effector(), paper_target(false), 0.2,
                                   {-1, 1.5, 0.9}, "gonthier"),
                  InputError);
  CHECK_THROWS_WITH(simulate_contact(m, BasePose{}, q, m.end_effector(), paper_target(false), 0.2,
                                     kPaperContact, "no-such-law"),
                    Catch::Contains("hunt-crossley"));
  MultibodyContactOptions tiny;
  tiny.max_num_steps = 3;
  CHECK_THROWS_AS(simulate_contact(m, BasePose{}, q, m.end_effector(), paper_target(false), 0.2,
                                   kPaperContact, "gonthier", tiny),
                  Error);
}
