// The capture objective (optimize/objective.hpp): one evaluator of M_ie and of the objective kinds
// under the joint model of the contact, called by every path. References are independent of it:
#include <catch2/catch.hpp>

#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/optimize/pareto.hpp"

#include <filesystem>
#include <random>

// the locked robot as one composite rigid body summed over the bodies (mass, centre of mass and
// inertia from the bodies' poses, not through H), the armature by a dense solve of
// (H + diag(0, a)) x = J_v^T u, the rigid body's jump of angular velocity for the locked base
// disturbance, central differences for the gradients. Then the UR5 pose scenario under locked and
// armature joints: its branches carry that model's M_ie, ranked by it, and the run ends on the least.

namespace test_capture_objective {

using namespace ffsr;

namespace {

const std::string kSource = FFSR_SOURCE_DIR;

/// The locked robot as one rigid body: total mass m, centre of mass c and inertia I about c, summed
/// over the bodies from their poses at (base, theta).
struct Composite {
  double m = 0;
  Vector3 c = Vector3::Zero();
  Matrix3 I = Matrix3::Zero();
};

Composite composite(const Model& model, const BasePose& base, const Eigen::VectorXd& theta) {
  Data data(model);
  forward_kinematics(model, data, base, theta);
  Composite k;
  Vector3 mc = Vector3::Zero();
  for (int i = 0; i < model.nb(); ++i) {
    const auto& in = model.body(i).inertia;
    k.m += in.mass;
    mc += in.mass * (data.p[size_t(i)] + data.R[size_t(i)] * in.com);
  }
  k.c = mc / k.m;
  for (int i = 0; i < model.nb(); ++i) {
    const auto& in = model.body(i).inertia;
    const Matrix3& R = data.R[size_t(i)];
    const Vector3 d = data.p[size_t(i)] + R * in.com - k.c;
    k.I += R * in.I * R.transpose() + in.mass * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose());
  }
  return k;
}

/// The end-effector frame's origin at (base, theta).
Vector3 contact_point(const Model& model, int frame, const BasePose& base, const Eigen::VectorXd& theta) {
  Data data(model);
  forward_kinematics(model, data, base, theta);
  return frame_pose(model, data, frame).p;
}

/// The target's inverse mass along its normal at its attitude, from its mass, inertia and offset.
double target_inverse_mass(const Target& t) {
  const Matrix3 R = t.attitude.normalized().toRotationMatrix();
  const Vector3 u = R * t.normal.normalized(), r = R * t.contact_offset;
  const Matrix3 I = R * t.inertia * R.transpose();
  const Vector3 ru = r.cross(u);
  return 1.0 / t.mass + ru.dot(I.inverse() * ru);
}

/// M_ie of the locked robot at (base, theta) against `t`: the composite rigid body's inverse mass
/// 1/m + (r x u)^T I^-1 (r x u), r = p_e - c, plus the target's.
double locked_M_ie(const Model& model, int frame, const BasePose& base, const Eigen::VectorXd& theta,
                   const Target& t) {
  const Composite k = composite(model, base, theta);
  const Vector3 u = t.attitude.normalized().toRotationMatrix() * t.normal.normalized();
  const Vector3 ru = (contact_point(model, frame, base, theta) - k.c).cross(u);
  return 1.0 / (1.0 / k.m + ru.dot(k.I.inverse() * ru) + target_inverse_mass(t));
}

/// M_ie with the armature a: u^T J_v (H + diag(0, a))^-1 J_v^T u by a dense LU solve, plus the target's.
double armature_M_ie(const Model& model, int frame, const BasePose& base, const Eigen::VectorXd& theta,
                     const Eigen::VectorXd& a, const Target& t) {
  Data data(model);
  crba(model, data, base, theta);
  frame_jacobian(model, data, frame);
  Eigen::MatrixXd H = data.H;
  H.diagonal().tail(model.n()) += a;
  const Vector3 u = t.attitude.normalized().toRotationMatrix() * t.normal.normalized();
  const Eigen::VectorXd w = data.J.topRows<3>().transpose() * u;
  return 1.0 / (w.dot(H.fullPivLu().solve(w)) + target_inverse_mass(t));
}

Scenario scenario_with(const std::string& file,
                       const std::vector<std::pair<std::string, std::string>>& keys) {
  ScenarioKeys k = read_scenario_file(file);
  for (const auto& [name, value] : keys) override_scenario_key(k, name, value);
  return build_scenario(std::move(k));
}

/// Central difference of f in every joint at theta (step h).
template <class F>
Eigen::VectorXd central_difference(F f, const Eigen::VectorXd& theta, double h) {
  Eigen::VectorXd g(theta.size());
  for (Eigen::Index k = 0; k < theta.size(); ++k) {
    Eigen::VectorXd p = theta, m = theta;
    p(k) += h;
    m(k) -= h;
    g(k) = (f(p) - f(m)) / (2 * h);
  }
  return g;
}

bool have_ur5() {
  const std::string f = kSource + "/../shared/urdf-samples/ur5_robot.urdf";
  if (std::filesystem::exists(f)) return true;
  WARN("skipped: the UR5 URDF sample is not at " << f);
  return false;
}

}  // namespace

TEST_CASE("Capture objective: M_ie of each joint model against independent computations", "[objective]") {
  const Scenario sc = load_scenario(kSource + "/robots/paper_7dof_position.toml");
  const Model& model = *sc.model;
  const CaptureSetup s = prepare_capture(sc.problem, sc.task, sc.capture);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.5, 1.5);
  Data data(model);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd theta(model.n());
    for (Eigen::Index k = 0; k < theta.size(); ++k) theta(k) = U(rng);
    BasePose base;
    base.position = Vector3(0.1, -0.2, 0.05) * trial;
    base.orientation = Quaternion(rotation_from_rpy(Vector3(0.1, -0.3, 0.2) * trial));
    CaptureProblem pb = sc.problem;
    pb.joints = {JointModel::Locked, {}};
    CHECK(CaptureEvaluator(pb, s).mass(data, base, theta) ==
          Approx(locked_M_ie(model, pb.frame, base, theta, s.capture.target)).epsilon(1e-10));
    pb.joints = {JointModel::Armature, Eigen::VectorXd::LinSpaced(model.n(), 0.1, 2.0)};
    CHECK(CaptureEvaluator(pb, s).mass(data, base, theta) ==
          Approx(armature_M_ie(model, pb.frame, base, theta, pb.joints.armature, s.capture.target))
              .epsilon(1e-10));
    pb.joints = {};
    CHECK(CaptureEvaluator(pb, s).mass(data, base, theta) ==
          Approx(
              armature_M_ie(model, pb.frame, base, theta, Eigen::VectorXd::Zero(model.n()), s.capture.target))
              .epsilon(1e-10));
    // the map's fast path is the same M_ie
    CHECK(CaptureEvaluator(pb, s).mass_fast(data, base, theta) ==
          Approx(CaptureEvaluator(pb, s).mass(data, base, theta)).epsilon(1e-12));
  }
}

TEST_CASE("Capture objective: Lambda^-1 and the base's jump of the locked robot are a rigid body's",
          "[objective]") {
  const Scenario sc = load_scenario(kSource + "/robots/paper_3dof.toml");
  const Model& model = *sc.model;
  const int frame = sc.problem.frame;
  const Eigen::VectorXd theta = Eigen::Vector3d(0.3, 1.2, -0.7);
  BasePose base;
  base.orientation = Quaternion(rotation_from_rpy(Vector3(0.2, 0.1, -0.4)));
  Data data(model);
  crba(model, data, base, theta);
  const ContactJoints locked{JointModel::Locked, {}};
  const Matrix6 Linv = inverse_inertia_matrix(model, data, frame, locked);
  const Composite k = composite(model, base, theta);
  const Vector3 pe = contact_point(model, frame, base, theta);
  // a force f at p_e + rho with a couple m: the rigid body's point acceleration and angular one
  const Vector3 f(0.3, -0.5, 0.8), rho(0.05, 0.1, -0.02), m(0.2, 0.0, -0.1);
  Vector6 s;
  s << f, rho.cross(f) + m;
  const Vector3 moment = (pe - k.c).cross(f) + rho.cross(f) + m;
  const Vector3 alpha = k.I.inverse() * moment;
  const double expected = f.dot(f) / k.m + moment.dot(alpha);  // s^T Lambda^-1 s = work per unit
  CHECK(s.dot(Linv * s) == Approx(expected).epsilon(1e-10));
  CHECK((Linv - Linv.transpose()).norm() == 0);
  // the base's jump of angular velocity per unit impulse along u at p_e: the rigid body's I^-1 (r x u)
  const Vector3 u = Vector3(1, 2, -0.5).normalized();
  double inverse_mass = 0;
  const Vector6 b = base_velocity_per_unit_impulse(model, data, frame, u, locked, inverse_mass);
  CHECK((b.tail<3>() - k.I.inverse() * (pe - k.c).cross(u)).norm() < 1e-12 * b.tail<3>().norm());
  const Vector3 r = pe - k.c;
  CHECK(inverse_mass == Approx(1.0 / k.m + r.cross(u).dot(k.I.inverse() * r.cross(u))).epsilon(1e-10));
}

TEST_CASE(
    "Capture objective: the gradients of every joint model and of robust-force equal central differences",
    "[objective]") {
  ScenarioKeys keys = read_scenario_file(kSource + "/robots/paper_7dof_position_uncertain.toml");
  const Scenario sc = build_scenario(keys);
  const Model& model = *sc.model;
  const CaptureSetup s = prepare_capture(sc.problem, sc.task, sc.capture);
  const auto robust =
      scenario_robust_objective(sc, uncertainty_spec(sc.keys, std::uint64_t{40}, std::nullopt));
  const Eigen::VectorXd theta = (Eigen::VectorXd(7) << 0.2, 1.4, 1.1, -1.2, 1.3, 1.5, 0.1).finished();
  const BasePose base;
  Data data(model);
  Eigen::VectorXd grad(model.n());
  const std::vector<ContactJoints> models{{JointModel::Free, {}},
                                          {JointModel::Locked, {}},
                                          {JointModel::Armature, Eigen::VectorXd::Constant(7, 0.5)}};
  for (const ContactJoints& joints : models) {
    CaptureProblem pb = sc.problem;
    pb.joints = joints;
    for (GlobalObjective kind : {GlobalObjective::Mass, GlobalObjective::RobustForce}) {
      INFO(joint_model_name(joints.model) << ", " << objective_name(kind));
      const CaptureEvaluator f(pb, s, kind, nullptr, robust.get());
      const double v = f.search_value_gradient(data, base, theta, grad);
      double M = 0;
      CHECK(f.search_value(data, base, theta, M) == Approx(v).epsilon(1e-12));
      const Eigen::VectorXd fd = central_difference(
          [&](const Eigen::VectorXd& q) {
            double Mq = 0;
            return f.search_value(data, base, q, Mq);
          },
          theta, 1e-6);
      CHECK((grad - fd).norm() <= 1e-6 * std::max(1.0, fd.norm()));
    }
  }
}

TEST_CASE(
    "UR5 pose task under locked and armature joints: the branches carry that model's M_ie, ranked by it",
    "[objective][branches]") {
  if (!have_ur5()) return;
  const std::string file = kSource + "/tests/data/ur5_pose.toml";
  for (const std::vector<std::pair<std::string, std::string>>& keys :
       {std::vector<std::pair<std::string, std::string>>{{"contact-joints", "locked"}},
        std::vector<std::pair<std::string, std::string>>{{"contact-joints", "armature"},
                                                         {"armature", "0.5"}}}) {
    const Scenario sc = scenario_with(file, keys);
    INFO(sc.keys.contact_joints);
    const ScenarioResult r = run_scenario(sc, {});
    REQUIRE(r.global);
    const std::vector<CaptureBranch>& branches = r.global->branches;
    REQUIRE(branches.size() == 8);  // the UR5's inverse-kinematics solutions at this capture point
    const BasePose& base = r.global->result.run.base;  // the branches are at the reached base pose
    const Target at_T = propagate_target(sc.problem.target, sc.capture.duration);
    const Model& model = *sc.model;
    const bool locked = sc.problem.joints.model == JointModel::Locked;
    for (size_t i = 0; i < branches.size(); ++i) {
      const CaptureBranch& b = branches[i];
      const double expected =
          locked ? locked_M_ie(model, sc.problem.frame, base, b.theta, at_T)
                 : armature_M_ie(model, sc.problem.frame, base, b.theta, sc.problem.joints.armature, at_T);
      CHECK(b.M_ie == Approx(expected).epsilon(1e-10));
      CHECK(b.objective == b.M_ie);  // the mass objective
      if (i > 0) CHECK(branches[i - 1].M_ie <= b.M_ie);
    }
    // the run ends on the branch of least M_ie, with its M_ie
    const CaptureResult& run = r.global->result.run;
    CHECK(detail::configuration_distance(model, run.theta, branches.front().theta) < 1e-4);
    const double expected = locked ? locked_M_ie(model, sc.problem.frame, run.base, run.theta, at_T)
                                   : armature_M_ie(model, sc.problem.frame, run.base, run.theta,
                                                   sc.problem.joints.armature, at_T);
    CHECK(run.M_ie == Approx(expected).epsilon(1e-10));
    CHECK(run.M_ie == Approx(branches.front().M_ie).epsilon(1e-6));
    std::printf("UR5 pose, %s joints: branches %.4f to %.4f kg, the run ends on %.4f kg\n",
                sc.keys.contact_joints.c_str(), branches.front().M_ie, branches.back().M_ie, run.M_ie);
  }
}

}  // namespace test_capture_objective
