// The grasp after the Hertz contact (control/contact_grasp.hpp) on both paper robots: the total momentum
// of robot and target, summed over the bodies, kept from the first touch through the contact and the
// lock; the relative twist after the lock zero; the total impulse of contact and lock equal to the
// lock's alone from the approach up to the configuration change during the contact.

#include <catch2/catch.hpp>

#include "support/dynamics_helpers.hpp"

#include "ffsr/control/contact_grasp.hpp"
#include "ffsr/control/detumble_run.hpp"
#include "ffsr/scenario/scenario.hpp"

#include <cmath>
#include <string>

namespace test_contact_grasp {

using namespace ffsr;
using namespace ffsr_test;

namespace {

/// [P; L about o] of robot plus target, summed over the bodies: each body's centre-of-mass velocity
/// and angular velocity from the frame Jacobian of its own frame (not the library's momentum()).
Vector6 total_momentum(const Model& m, const BasePose& base, const Eigen::VectorXd& theta,
                       const Eigen::VectorXd& v, const Target& t, const Vector6& target_twist) {
  Data d(m);
  forward_kinematics(m, d, base, theta);
  Vector6 h = Vector6::Zero();
  for (const auto& b : m.bodies()) {
    const int f = m.frame_index(b.name);
    const Pose X = frame_pose(m, d, f);
    const Vector6 tw = frame_jacobian(m, d, f) * v;  // [velocity of the frame's origin; angular velocity]
    const Vector3 c = X.p + X.R * b.inertia.com;
    const Vector3 w = tw.tail<3>();
    const Vector3 vc = tw.head<3>() + w.cross(c - X.p);
    h.head<3>() += b.inertia.mass * vc;
    h.tail<3>() += c.cross(b.inertia.mass * vc) + X.R * b.inertia.I * X.R.transpose() * w;
  }
  const Matrix3 R = t.rotation();
  h.head<3>() += t.mass * target_twist.head<3>();
  h.tail<3>() += t.position.cross(t.mass * target_twist.head<3>()) +
                 R * t.inertia * R.transpose() * target_twist.tail<3>();
  return h;
}

Vector6 twist_of(const Target& t) {
  Vector6 w;
  w << t.velocity, t.angular_velocity_world();
  return w;
}

/// The scenario's robot at its initial configuration, its target, law and approach speed.
ContactGraspResult after_contact(const Scenario& sc, double stiffness_factor = 1) {
  const CaptureProblem& p = sc.problem;
  ContactParams params = p.contact;
  params.K *= stiffness_factor;
  return grasp_after_contact(*p.model, p.frame, p.base, p.theta, p.target, p.approach_speed, params, p.law);
}

}  // namespace

TEST_CASE("grasp after the Hertz contact: momentum kept over contact and lock, relative twist zero",
          "[detumble][contact]") {
  for (const std::string file : {"paper_3dof.toml", "paper_7dof_position.toml"}) {
    INFO(file);
    const Scenario sc = load_scenario(source_path("robots/" + file));
    const Model& m = *sc.problem.model;
    const int ee = sc.problem.frame;
    const ContactGraspResult r = after_contact(sc);
    const ContactBodies& s = r.contact.start;
    const ContactBodies& e = r.contact.end;
    const GraspResult& g = r.grasp;
    // the run ends at the separation: the gripper's point back on the target's surface plane
    Data d(m);
    forward_kinematics(m, d, e.base, e.theta);
    const Vector3 pe = frame_pose(m, d, ee).p;
    const double delta = e.target.normal_world().dot(pe - e.target.contact_point());
    INFO("contact " << r.contact.contact_duration << " s, peak " << r.contact.f_max << " N, delta at the end "
                    << delta << " m, largest " << r.contact.delta_max << " m");
    CHECK(std::abs(delta) < 1e-9 * r.contact.delta_max);
    CHECK(r.contact.separation_velocity < 0);
    // momentum: first touch, separation (before the lock) and after the lock, summed over the bodies
    const Vector6 h0 = total_momentum(m, s.base, s.theta, s.v, s.target, twist_of(s.target));
    const Vector6 h1 = total_momentum(m, e.base, e.theta, e.v, e.target, twist_of(e.target));
    const Vector6 h2 = total_momentum(m, e.base, e.theta, g.v_after, e.target, g.target_after);
    INFO("h0 " << h0.transpose() << "\nh1 " << h1.transpose() << "\nh2 " << h2.transpose());
    CHECK((h1 - h0).norm() < 1e-8 * h0.norm());
    CHECK((h2 - h0).norm() < 1e-8 * h0.norm());
    // the lock's state in is the contact run's state out
    CHECK(g.v_before == e.v);
    CHECK((g.target_before - twist_of(e.target)).norm() == 0.0);
    // the relative twist at the lock's point after the lock, from the frame Jacobian and the target's twist
    forward_kinematics(m, d, e.base, e.theta);
    const Vector6 gripper = frame_jacobian(m, d, ee) * g.v_after;
    Vector6 target_at_p;
    target_at_p << g.target_after.head<3>() + g.target_after.tail<3>().cross(pe - e.target.position),
        g.target_after.tail<3>();
    CHECK((gripper - target_at_p).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(g.energy_after <= g.energy_before);
    // the contact's impulse on the gripper is the target's momentum change, against the normal
    CHECK(r.contact_impulse.dot(s.target.normal_world()) < 0);
  }
}

TEST_CASE("grasp after the Hertz contact: contact plus lock give the lock's impulse from the approach",
          "[detumble][contact]") {
  // From a configuration q the lock maps any pre-lock velocity v- to v+ = P(q) v-, with P = 1 - M^-1 J^T
  // (J M^-1 J^T)^-1 J, and P M^-1 J^T = 0. The contact's force acts along J^T (at the gripper's point,
  // opposite on the target), so were the configuration frozen during the contact, v+ would be the
  // approach lock's and the impulses would add up: p_contact + p_lock = p_approach (on the gripper).
  // The configuration moves during the contact (by ~ speed x duration), so the sum differs by O(duration):
  // checked small, and shrinking with a stiffer contact (duration ~ K^(-1/(alpha+1))).
  for (const std::string file : {"paper_3dof.toml", "paper_7dof_position.toml"}) {
    INFO(file);
    const Scenario sc = load_scenario(source_path("robots/" + file));
    const CaptureProblem& p = sc.problem;
    const GraspResult a = grasp_at_capture(*p.model, p.frame, p.base, p.theta, p.target, p.approach_speed);
    auto mismatch = [&](const ContactGraspResult& r) {
      Vector6 total = r.grasp.impulse;
      total.head<3>() += r.contact_impulse;  // the contact force acts at the point: no moment about it
      return (total - a.impulse).norm() / a.impulse.norm();
    };
    const ContactGraspResult soft = after_contact(sc), stiff = after_contact(sc, 100);
    const double e_soft = mismatch(soft), e_stiff = mismatch(stiff);
    const double shorter = soft.contact.contact_duration / stiff.contact.contact_duration;
    INFO("contact impulse " << soft.contact_impulse.norm() << " N s, lock " << soft.grasp.impulse.transpose()
                            << ", approach lock " << a.impulse.transpose() << "; mismatch " << e_soft
                            << " (duration " << soft.contact.contact_duration << " s), " << e_stiff
                            << " (x100 stiffer, " << shorter << " times shorter)");
    CHECK(e_soft < 1e-3);
    CHECK(e_stiff * shorter > 0.5 * e_soft);  // first order in the duration (measured: ratio 1.00)
    CHECK(e_stiff * shorter < 2.0 * e_soft);
    // the contact impulse is not small beside the lock's: the check above is not trivially met
    CHECK(soft.contact_impulse.norm() > 0.5 * a.impulse.head<3>().norm());
    // the same state after the lock either way (P v+ for nearly the same configuration)
    const double dv = (soft.grasp.v_after - a.v_after).norm() / a.v_after.norm();
    CHECK(dv < 1e-2);
    CHECK((stiff.grasp.v_after - a.v_after).norm() / a.v_after.norm() < dv / (0.5 * shorter));
    // the energy after the lock: both are the stack's at nearly the same state
    CHECK(std::abs(soft.grasp.energy_after - a.energy_after) < 1e-2 * a.energy_after);
  }
}

}  // namespace test_contact_grasp
