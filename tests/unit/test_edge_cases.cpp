// Numerical edge cases: each ends in a correct answer or in a typed error with a message;
// none hangs and none answers NaN. The README's "Edge cases" table points here.
#include <catch2/catch.hpp>

#include "support/paper.hpp"

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/optimize/capture.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "ffsr/simulate/single_body.hpp"

#include <string>

namespace test_edge_cases {

using namespace ffsr;
using ffsr::test::deg;
using ffsr::test::kRobots;

namespace {

Inertia rod(double m, double L) {  // uniform rod along x, centre of mass at mid-length
  return {m, Vector3(L / 2, 0, 0), Vector3(0.0, m * L * L / 12, m * L * L / 12).asDiagonal()};
}

CaptureProblem problem_3dof(const Model& m, const Eigen::VectorXd& q0, const Vector3& target_position) {
  CaptureProblem pb;
  pb.model = &m;
  pb.frame = m.end_effector();
  pb.theta = q0;
  pb.target.position = target_position;
  pb.target.angular_velocity = Vector3(0, 0, 2) * (M_PI / 180);
  return pb;
}

CaptureTask planar() {
  CaptureTask t;
  t.axes = {true, true, false};
  return t;
}

}  // namespace

TEST_CASE("Edge: the arm stretched straight (J_f singular)", "[edge]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  Data d(m);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(3);
  // Figure 9: the integrated effective mass is largest at the stretched arm, and finite
  Target t;
  const double M = integrated_effective_mass(m, d, BasePose{}, q, m.end_effector(), t);
  CHECK(std::isfinite(M));
  CHECK(M > integrated_effective_mass(m, d, BasePose{}, deg({0, 90, -90}), m.end_effector(), t));
  // the planar task Jacobian loses rank: its smallest singular value is ~0
  generalized_jacobian(m, d, BasePose{}, q, m.end_effector());
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(d.Jf.topRows(2));
  CHECK(svd.singularValues()(1) < 1e-9);
  // planning away from the singular configuration: the damped pseudo-inverse takes over (reported)
  CaptureOptions opt;
  opt.duration = 60;
  const CaptureResult r = plan_capture(problem_3dof(m, q, Vector3(2.5, 1.0, 0)), planar(), opt);
  CHECK(r.damped_steps > 0);
  CHECK(r.min_singular_value < opt.singular_value_threshold);
  CHECK(r.tracking_error < opt.tolerance);
  CHECK(std::isfinite(r.M_ie));
}

TEST_CASE("Edge: a capture point at the edge of the workspace", "[edge]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  // reach from joint 1: 1.4 + 1.6 + 0.5 = 3.5 m; put the contact point exactly there (base fixed
  // would give x = 4.1; the free base recoils, so the line ends at the singular boundary or beyond)
  Target t;
  const Vector3 cap(0.6 + 3.5, 0.0, 0.0);
  CaptureProblem pb = problem_3dof(m, deg({0, 150, -100}), cap - t.contact_offset);
  pb.target.angular_velocity.setZero();
  CaptureOptions opt;
  opt.duration = 120;
  // ends either at the capture point or with the typed error that says it is out of reach
  try {
    const CaptureResult r = plan_capture(pb, planar(), opt);
    CHECK(r.tracking_error <= opt.tolerance);
    CHECK(std::isfinite(r.M_ie));
  } catch (const NumericalError& e) {
    CHECK_THAT(e.what(), Catch::Contains("out of reach"));
  }
}

TEST_CASE("Edge: a contact normal perpendicular to every direction the end-effector can move", "[edge]") {
  // The planar robot cannot move its end-effector along z (its J_f has a zero z row).
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  Data d(m);
  Target t;
  t.normal = Vector3::UnitZ();
  const Eigen::VectorXd q = deg({0, 90, -90});
  // the effective mass along z is the free base's: finite and positive, at least the arm's share
  const double me = effective_mass(m, d, BasePose{}, q, m.end_effector(), Vector3::UnitZ());
  CHECK(std::isfinite(me));
  CHECK(me > 0);
  CHECK(me <= m.total_mass() + 1e-9);
  // the end-effector cannot approach along z: delta_dot^- = 0 without target motion -> typed error
  t.angular_velocity.setZero();
  CHECK_THROWS_WITH(
      simulate_contact(m, BasePose{}, q, m.end_effector(), t, 0.2, {1e9, 1.5, 0.9}, "hunt-crossley"),
      Catch::Contains("do not approach"));
}

TEST_CASE("Edge: c_r = 1 and c_r close to 0", "[edge]") {
  for (auto name : contact_law_names()) {
    INFO(name);
    // c_r = 1: no damping, the pure Hertz result (lambda -> 0), no division by zero
    const AnyContactLaw elastic = make_contact_law(name, {1e9, 1.5, 1.0}, 0.2);
    const double hertz =
        1e9 * std::pow(5.0 * 2.5 * 0.04 / (2 * 1e9), 1.5 / 2.5);  // K ((a+1) M v^2 / 2K)^(a/(a+1))
    CHECK(max_force_closed_form(elastic, 5.0) == Approx(hertz).epsilon(1e-12));
    CHECK(max_force_exact(elastic, 5.0) == Approx(hertz).epsilon(1e-12));
    // c_r -> 0: every law stays finite; the exact peak is at least the closed form
    const AnyContactLaw soft = make_contact_law(name, {1e9, 1.5, 1e-6}, 0.2);
    const double fc = max_force_closed_form(soft, 5.0), fe = max_force_exact(soft, 5.0);
    CHECK(std::isfinite(fc));
    CHECK(std::isfinite(fe));
    CHECK(fe >= fc);
    CHECK(std::isfinite(max_deformation(soft, 5.0)));
    // the single-body integration (Eq. 16) at c_r = 1e-3: the clamp holds F = 0 in the restitution
    // phase, the bodies separate slowly; the peak still agrees with the exact maximum
    const AnyContactLaw lossy = make_contact_law(name, {1e9, 1.5, 1e-3}, 0.2);
    try {
      const SingleBodyResult sb = simulate_single_body(lossy, 5.0);
      CHECK(sb.f_max == Approx(max_force_exact(lossy, 5.0)).epsilon(1e-6));
      CHECK(std::isfinite(sb.contact_duration));
    } catch (const Error& e) {
      FAIL_CHECK(e.what());
    }
  }
  // the multibody reference at c_r = 0.01 (Flores: f = 79): a very damped contact still separates
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  const auto r = simulate_contact(m, BasePose{}, deg({0, 90, -90}), m.end_effector(), Target{}, 0.2,
                                  {1e9, 1.5, 0.01}, "flores");
  CHECK(std::isfinite(r.f_max));
  CHECK(r.restitution >= 0.0);
  CHECK(r.restitution < 0.2);
}

TEST_CASE("Edge: very stiff and very soft contact (K from 1e5 to 1e12)", "[edge]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  const Eigen::VectorXd q = deg({0, 90, -90});
  for (double K : {1e5, 1e7, 1e9, 1e12}) {
    INFO("K = " << K);
    const auto r = simulate_contact(m, BasePose{}, q, m.end_effector(), Target{}, 0.2, {K, 1.5, 0.9},
                                    "herbert-mcwhannell");
    const AnyContactLaw law = make_contact_law("herbert-mcwhannell", {K, 1.5, 0.9}, r.approach_velocity);
    const double exact = max_force_exact(law, r.integrated_effective_mass);
    CHECK(std::isfinite(r.f_max));
    // a stiff contact is short and the single-body model holds; a soft one lasts long enough
    // (K = 1e5: ~0.1 s) for the arm to move, and the multibody peak departs from it a little
    CHECK(r.f_max == Approx(exact).epsilon(K >= 1e7 ? 0.005 : 0.05));
  }
}

TEST_CASE("Edge: tiny and huge masses (1e-3 to 1e6 kg)", "[edge]") {
  for (double scale : {1e-3, 1e6}) {
    INFO("mass scale " << scale);
    // a robot whose every mass and inertia is scaled: M_ie of the robot alone scales with it
    const double s = scale / 500.0;  // base 500 kg -> scale
    const Model m = ModelBuilder("base", {500 * s, Vector3::Zero(), 200 * s * Matrix3::Identity()})
                        .add_joint("j1", JointType::Revolute, "base", Pose{Vector3(0.6, 0, 0)},
                                   Vector3::UnitZ(), "l1", rod(5 * s, 1.4))
                        .add_joint("j2", JointType::Revolute, "l1", Pose{Vector3(1.4, 0, 0)},
                                   Vector3::UnitZ(), "l2", rod(6 * s, 1.6))
                        .add_joint("j3", JointType::Revolute, "l2", Pose{Vector3(1.6, 0, 0)},
                                   Vector3::UnitZ(), "l3", rod(4 * s, 0.5))
                        .add_fixed("ee_joint", "l3", Pose{Vector3(0.5, 0, 0)}, "ee", {})
                        .build();
    const Model ref = model_from_urdf_file(kRobots + "paper_3dof.urdf");
    Data d(m), dref(ref);
    const Eigen::VectorXd q = deg({0, 90, -90});
    const Vector3 u = Vector3::UnitX();
    CHECK(effective_mass(m, d, BasePose{}, q, m.end_effector(), u) ==
          Approx(s * effective_mass(ref, dref, BasePose{}, q, ref.end_effector(), u)).epsilon(1e-6));
    // the same target, scaled: the contact simulation still answers
    Target t;
    t.mass = scale;
    t.inertia = 0.5 * scale * Matrix3::Identity();
    const auto r =
        simulate_contact(m, BasePose{}, q, m.end_effector(), t, 0.2, {1e9, 1.5, 0.9}, "hunt-crossley");
    CHECK(std::isfinite(r.f_max));
    CHECK(r.f_max > 0);
  }
}

TEST_CASE("Edge: a robot with one joint", "[edge]") {
  const Model m = ModelBuilder("base", {100, Vector3::Zero(), 10 * Matrix3::Identity()})
                      .add_joint("j1", JointType::Revolute, "base", Pose{Vector3(0.5, 0, 0)},
                                 Vector3::UnitZ(), "arm", rod(5, 1.0))
                      .add_fixed("tip", "arm", Pose{Vector3(1.0, 0, 0)}, "ee", {})
                      .build();
  Data d(m);
  Target t;
  t.normal = Vector3::UnitY();
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(1);
  const double M = integrated_effective_mass(m, d, BasePose{}, q, m.end_effector(), t);
  CHECK(std::isfinite(M));
  CHECK(M > 0);
  const auto r = simulate_contact(m, BasePose{}, q, m.end_effector(), t, 0.2, {1e9, 1.5, 0.9}, "lee-wang");
  CHECK(std::isfinite(r.f_max));
  // one joint, a one-axis task: no null space, so a non-zero gain is refused
  CaptureProblem pb;
  pb.model = &m;
  pb.frame = m.end_effector();
  pb.theta = q;
  pb.target.position = Vector3(1.3, 0.3, 0) - pb.target.contact_offset;
  CaptureTask task;
  task.axes = {false, true, false};
  CaptureOptions opt;
  opt.duration = 30;
  opt.gain = -0.01;
  CHECK_THROWS_AS(plan_capture(pb, task, opt), InputError);
  opt.gain = 0;
  const CaptureResult res = plan_capture(pb, task, opt);
  CHECK(std::abs(res.end_effector.y() - res.capture_point.y()) < opt.tolerance);
}

TEST_CASE("Edge: a branched robot with two arms, one of them the end-effector", "[edge]") {
  const Inertia link{4, Vector3(0.5, 0, 0), Vector3(0.01, 0.33, 0.33).asDiagonal()};
  ModelBuilder b("base", {300, Vector3::Zero(), 50 * Matrix3::Identity()});
  b.add_joint("a1", JointType::Revolute, "base", Pose{Vector3(0.5, 0.3, 0)}, Vector3::UnitZ(), "arm_a1", link)
      .add_joint("a2", JointType::Revolute, "arm_a1", Pose{Vector3(1, 0, 0)}, Vector3::UnitZ(), "arm_a2",
                 link)
      .add_joint("a3", JointType::Revolute, "arm_a2", Pose{Vector3(1, 0, 0)}, Vector3::UnitZ(), "arm_a3",
                 link)
      .add_joint("b1", JointType::Revolute, "base", Pose{Vector3(0.5, -0.3, 0)}, Vector3::UnitZ(), "arm_b1",
                 link)
      .add_joint("b2", JointType::Revolute, "arm_b1", Pose{Vector3(1, 0, 0)}, Vector3::UnitZ(), "arm_b2",
                 link)
      .add_fixed("tool_joint", "arm_a3", Pose{Vector3(1, 0, 0)}, "tool", {});
  // two leaves: the end-effector must be named, and the error lists both
  CHECK_THROWS_WITH(ModelBuilder(b).build(), Catch::Contains("tool") && Catch::Contains("arm_b2"));
  b.set_end_effector("tool");
  const Model m = b.build();
  Data d(m);
  const Eigen::VectorXd q = deg({20, 60, -40, -30, 45});
  Target t;
  const double M = integrated_effective_mass(m, d, BasePose{}, q, m.end_effector(), t);
  CHECK(std::isfinite(M));
  // the passive arm still matters: the same arm without it has a different effective mass
  CaptureProblem pb;
  pb.model = &m;
  pb.frame = m.end_effector();
  pb.theta = q;
  crba(m, d, BasePose{}, q);
  pb.target.position = frame_pose(m, d, m.end_effector()).p + Vector3(-0.4, -0.2, 0) - t.contact_offset;
  CaptureTask task;
  task.axes = {true, true, false};
  CaptureOptions opt;
  opt.duration = 60;
  opt.gain = -0.01;
  const CaptureResult r = plan_capture(pb, task, opt);
  CHECK(r.tracking_error < opt.tolerance);
  CHECK(std::isfinite(r.M_ie));
  CHECK(r.max_com_drift < 1e-9);
}

TEST_CASE("Edge: a long task (T = 1e4 s)", "[edge]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  CaptureProblem pb = problem_3dof(m, deg({0, 150, -100}), Vector3(2.75, 1.45, 0));
  CaptureOptions opt;
  opt.duration = 1e4;
  opt.step = 2.0;
  opt.gain = -0.01;
  const CaptureResult r = plan_capture(pb, planar(), opt);
  CHECK(r.steps == 5000);
  CHECK(r.tracking_error < opt.tolerance);
  CHECK(std::isfinite(r.M_ie));
  // too many steps is refused up front rather than run for hours
  opt.step = 1e-4;
  CHECK_THROWS_AS(plan_capture(pb, planar(), opt), InputError);
}

// fuzz finding ../shared/findings/fuzz_numeric-plan_capture-inf.bin: T = 8.4e-227 s with a 0.2 s step
// gave ceil(T/step - 1e-9) = 0 RK4 steps, so the run returned the initial state and a smallest task
// singular value of +inf (never evaluated). A run has at least one step now.
TEST_CASE("Edge: a duration far below one step still takes one step", "[edge][fuzz]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  CaptureProblem pb = problem_3dof(m, deg({0, 150, -100}), Vector3(0.6, 1.2, 0));
  CaptureOptions opt;
  opt.step = 0.2;
  opt.tolerance = 1e79;  // the finding's: no miss is an error, so the result itself is checked
  for (double T : {8.442542515286355e-227, 1e-12, 1e-10}) {
    opt.duration = T;
    INFO("T = " << T);
    const CaptureResult r = plan_capture(pb, planar(), opt);
    CHECK(r.steps == 1);
    CHECK(std::isfinite(r.min_singular_value));
    CHECK(r.min_singular_value > 0.0);
    CHECK(r.theta.allFinite());
    CHECK(std::isfinite(r.M_ie));
  }
}

TEST_CASE("Edge: CVODE asked for impossible tolerances", "[edge]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  MultibodyContactOptions o;
  o.rtol = 1e-30;
  o.atol_position = 1e-40;
  o.atol_velocity = 1e-40;
  o.max_num_steps = 2000;
  CHECK_THROWS_AS(simulate_contact(m, BasePose{}, deg({0, 90, -90}), m.end_effector(), Target{}, 0.2,
                                   {1e9, 1.5, 0.9}, "hunt-crossley", o),
                  Error);
  o.rtol = -1;
  CHECK_THROWS_AS(simulate_contact(m, BasePose{}, deg({0, 90, -90}), m.end_effector(), Target{}, 0.2,
                                   {1e9, 1.5, 0.9}, "hunt-crossley", o),
                  InputError);
}

TEST_CASE("Edge: finite inputs past double precision are NumericalErrors, never NaN or inf", "[edge][fuzz]") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf");
  Data d(m);
  const Eigen::VectorXd q = deg({0, 150, -100});
  const int nv = m.nv();
  // huge but finite velocities: the products overflow in the dynamics
  Eigen::VectorXd v = Eigen::VectorXd::Zero(nv), a = Eigen::VectorXd::Zero(nv), acc;
  v(6) = 1e160;
  CHECK_THROWS_AS(rnea(m, d, BasePose{}, q, v, a), NumericalError);
  CHECK_THROWS_AS(forward_dynamics(m, d, BasePose{}, q, v, a, acc), NumericalError);
  CHECK_THROWS_AS(aba(m, d, BasePose{}, q, v, a, acc), NumericalError);
  forward_kinematics(m, d, BasePose{}, q);
  CHECK_THROWS_AS(kinetic_energy(m, d, v), NumericalError);
  v(6) = 1e308;
  v(7) = 1e308;
  CHECK_THROWS_AS(momentum(m, d, v), NumericalError);
  v(6) = std::nan("");
  CHECK(std::isnan(kinetic_energy(m, d, v)));  // NaN in, NaN out: not an overflow
  // the target: its contact point's velocity and its motion
  Target t;
  t.angular_velocity = Vector3(0, 0, 1e200);
  t.contact_offset = Vector3(1e200, 0, 0);
  CHECK_THROWS_AS(t.contact_point_velocity(), NumericalError);
  t = Target{};
  t.velocity = Vector3(1e300, 0, 0);
  CHECK_THROWS_AS(propagate_target(t, 1e10), NumericalError);
  CHECK_THROWS_AS(propagate_target(Target{}, std::numeric_limits<double>::infinity()), InputError);
  t = Target{};
  t.inertia = Vector3(100, 200, 250).asDiagonal();  // not isotropic: the Euler equations are integrated
  t.angular_velocity = Vector3(0, 0, 0.01);
  CHECK_THROWS_AS(propagate_target(t, 1e300), InputError);  // too long a span, not a cast past long
  t.angular_velocity = Vector3(1e200, 1e200, 1e200);
  CHECK_THROWS_AS(propagate_target(t, 1.0), NumericalError);
  // M_ie from an effective mass whose inverse overflows
  CHECK_THROWS_AS(integrated_effective_mass(1e-310, Target{}), NumericalError);
  CHECK(integrated_effective_mass(5.0, Target{}) > 0.0);
}

}  // namespace test_edge_cases
