// The impact disturbance of the base (algorithm/base_disturbance.hpp): the single-body restitution
// against the single-body CVODE run, the impulse response against a dense H^-1 J^T, the momentum
// identity, and the predicted base velocity jump against the CVODE multibody run after separation.
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/algorithm/base_disturbance.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "ffsr/simulate/single_body.hpp"

#include <string>
#include <vector>

namespace test_base_disturbance {

using namespace ffsr;
using ffsr::test::deg, ffsr::test::kPaperContact, ffsr::test::kRobots, ffsr::test::paper_target;

TEST_CASE("Single-body restitution: the root of G(-e) = 0 against the CVODE single-body run",
          "[base_disturbance]") {
  CHECK(single_body_restitution(0.0) == 1.0);
  for (const char* name :
       {"hunt-crossley", "herbert-mcwhannell", "lankarani-nikravesh", "flores", "gonthier"})
    for (double c_r : {0.3, 0.7, 0.9, 0.99}) {
      const ContactParams p{1e9, 1.5, c_r};
      const AnyContactLaw law = make_contact_law(name, p, 0.2);
      const double e = single_body_restitution(law);
      SingleBodyOptions opt;
      opt.cvode.rtol = 1e-11;
      opt.cvode.atol = 1e-13;
      const SingleBodyResult r = simulate_single_body(law, 3.0, opt);
      INFO(name << " c_r " << c_r << " e " << e << " cvode " << r.restitution);
      CHECK(e > 0.0);
      CHECK(e <= 1.0);
      CHECK(e == Approx(r.restitution).epsilon(1e-6));
      // independent of M_ie, K, alpha and the approach velocity (the file comment's separation)
      const AnyContactLaw other = make_contact_law(name, ContactParams{3e7, 1.0, c_r}, 0.05);
      CHECK(simulate_single_body(other, 40.0, opt).restitution == Approx(e).epsilon(1e-6));
    }
  CHECK_THROWS_AS(single_body_restitution(-0.1), InputError);
}

TEST_CASE("Base impulse response: base rows of a dense H^-1 J^T s, and the momentum it carries",
          "[base_disturbance]") {
  const Model m = model_from_urdf_file(kRobots + "paper_7dof.urdf");
  Data d(m);
  BasePose base;
  base.position = Vector3(0.2, -0.1, 0.3);
  base.orientation = Quaternion(Eigen::AngleAxisd(0.4, Vector3(1, -2, 1).normalized()));
  const Eigen::VectorXd q = deg({10, 70, 80, -60, 40, 100, -20});
  const Vector3 u = Vector3(0.3, -0.5, 0.8).normalized();
  const Vector3 rho(0.02, -0.01, 0.03);
  crba(m, d, base, q);
  const Vector6 b = base_velocity_per_unit_impulse(m, d, m.end_effector(), u, rho);
  const Eigen::VectorXd dv = d.y;  // the whole jump H^-1 J^T s
  const Eigen::MatrixXd H = d.H;
  const Eigen::MatrixXd J = frame_jacobian(m, d, m.end_effector());
  Vector6 s;
  s << u, rho.cross(u);
  const Eigen::VectorXd dense = H.inverse() * J.transpose() * s;
  CHECK((dense.head<6>() - b).norm() < 1e-10 * dense.norm());
  // the robot's linear momentum changes by the impulse (u per unit), its angular momentum about the
  // contact point not at all (the force acts there)
  const Vector6 h = momentum(m, d, dv);  // [P; L about the base origin]
  const Vector3 pc = frame_pose(m, d, m.end_effector()).p + rho;
  CHECK((h.head<3>() - u).norm() < 1e-10);
  CHECK((h.tail<3>() - (pc - d.p[0]).cross(h.head<3>())).norm() < 1e-10);
}

struct Case {
  const char* urdf;
  bool seven_dof;
  Eigen::VectorXd theta;
};

TEST_CASE("Predicted base velocity jump against the CVODE multibody run after separation",
          "[base_disturbance]") {
  const std::vector<Case> cases = {
      {"paper_3dof.urdf", false, deg({0, 150, -100})},
      {"paper_3dof.urdf", false, deg({20, 120, -70})},
      {"paper_3dof.urdf", false, deg({-30, 100, -40})},
      {"paper_7dof.urdf", true, deg({0, 90, 90, -90, 90, 90, 0})},
      {"paper_7dof.urdf", true, deg({10, 70, 80, -60, 40, 100, -20})},
      {"paper_7dof.urdf", true, deg({-20, 110, 60, -100, 120, 60, 30})},
  };
  for (const Case& c : cases) {
    const Model m = model_from_urdf_file(kRobots + c.urdf);
    Data d(m);
    const BasePose base;
    Target t = paper_target(c.seven_dof);
    const MultibodyContactResult mb =
        simulate_contact(m, base, c.theta, m.end_effector(), t, 0.2, kPaperContact, "herbert-mcwhannell");
    // the prediction from the configuration alone: the target at the first touch has the attitude of
    // `t` (simulate_contact moves only its position), delta_dot^- from Eq. 10-12
    crba(m, d, base, c.theta);
    const Vector3 u = t.normal_world();
    t.position = frame_pose(m, d, m.end_effector()).p - t.offset_world();
    const double vin =
        approach_velocity(u, Vector3(0.2 * u), t.velocity, t.angular_velocity_world(), t.offset_world());
    const AnyContactLaw law = make_contact_law("herbert-mcwhannell", kPaperContact, vin);
    const BaseDisturbance p = base_disturbance(m, d, base, c.theta, m.end_effector(), t, law);
    const Vector6 measured = mb.base_velocity_end - mb.base_velocity_start;
    INFO(c.urdf << " theta " << c.theta.transpose() << "\n predicted w " << p.angular.transpose() << " v "
                << p.linear.transpose() << "\n measured  w " << measured.tail<3>().transpose() << " v "
                << measured.head<3>().transpose() << "\n e " << p.restitution << " vs " << mb.restitution);
    CHECK(p.M_ie == Approx(mb.integrated_effective_mass).epsilon(1e-10));
    CHECK(vin == Approx(mb.approach_velocity).epsilon(1e-9));
    CHECK(p.angular_rate() > 0.0);
    CHECK((p.angular - measured.tail<3>()).norm() < 0.02 * measured.tail<3>().norm());
    CHECK((p.linear - measured.head<3>()).norm() < 0.02 * measured.head<3>().norm());
  }
}

}  // namespace test_base_disturbance
