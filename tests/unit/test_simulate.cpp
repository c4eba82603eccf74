// The multibody contact reference (simulate/multibody.hpp) against the paper's Table 3 and Table 6,
// the single-body exact maximum, and conservation laws.
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <cstdio>
#include <string>

namespace test_simulate {

using namespace ffsr;
using ffsr::test::deg, ffsr::test::kPaperContact, ffsr::test::kRobots, ffsr::test::paper_target;

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

}  // namespace test_simulate
