// The joint models of the contact (algorithm/joint_models.hpp): free, locked and armature.
// References are independent: the locked robot's composite mass, centre of mass and inertia summed
// over the bodies from their poses (not through H); the armature against a second model whose
// joints drive counter-rotating rotor pairs through mimics; gradients against central differences.

// The effective mass under each model must not allocate: Eigen's runtime malloc check, made to
// throw. Defined before any Eigen header.
#define EIGEN_RUNTIME_NO_MALLOC
#include <stdexcept>
#define eigen_assert(x)                                           \
  do {                                                            \
    if (!(x)) throw std::logic_error("eigen_assert failed: " #x); \
  } while (false)

#include <catch2/catch.hpp>

#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/scenario/scenario.hpp"
#include "ffsr/jobs/scenario_run.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "support/command.hpp"

#include <filesystem>
#include <random>

namespace test_joint_models {

using namespace ffsr;

namespace {

std::string source(const std::string& rel) { return std::string(FFSR_SOURCE_DIR) + "/" + rel; }

std::string samples_dir() {
  if (const char* env = std::getenv("FFSR_URDF_SAMPLES")) return env;
  return std::string(FFSR_SOURCE_DIR) + "/../shared/urdf-samples";
}

/// The scenarios of the checks: both paper robots, and the reference arms when their URDFs exist.
std::vector<std::string> scenario_files() {
  std::vector<std::string> files{source("robots/paper_3dof.toml"), source("robots/paper_7dof_position.toml")};
  if (std::filesystem::exists(samples_dir() + "/panda.urdf")) {
    for (const char* f : {"tests/data/panda.toml", "tests/data/ur5.toml", "tests/data/kinova.toml"})
      files.push_back(source(f));
  } else {
    WARN("skipped Panda, UR5, Kinova: the URDF samples are not in " << samples_dir());
  }
  return files;
}

ContactJoints locked() { return {JointModel::Locked, {}}; }
ContactJoints armature(const Eigen::VectorXd& a) { return {JointModel::Armature, a}; }

/// The locked robot's inverse mass along u at p by sums over the bodies: total mass m, centre of
/// mass c, inertia I about c (parallel axes), then 1/m + (r x u)^T I^-1 (r x u), r = p - c.
double composite_inverse_mass(const Model& model, const BasePose& base, const Eigen::VectorXd& theta,
                              const Vector3& p, const Vector3& u) {
  Data data(model);
  forward_kinematics(model, data, base, theta);
  double m = 0;
  Vector3 mc = Vector3::Zero();
  for (int i = 0; i < model.nb(); ++i) {
    const auto& in = model.body(i).inertia;
    m += in.mass;
    mc += in.mass * (data.p[size_t(i)] + data.R[size_t(i)] * in.com);
  }
  const Vector3 c = mc / m;
  Matrix3 I = Matrix3::Zero();
  for (int i = 0; i < model.nb(); ++i) {
    const auto& in = model.body(i).inertia;
    const Matrix3& R = data.R[size_t(i)];
    const Vector3 d = data.p[size_t(i)] + R * in.com - c;
    I += R * in.I * R.transpose() + in.mass * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose());
  }
  const Vector3 ru = (p - c).cross(u);
  return 1.0 / m + ru.dot(I.ldlt().solve(ru));
}

Eigen::VectorXd perturbed(const Eigen::VectorXd& theta, std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> U(-scale, scale);
  Eigen::VectorXd t = theta;
  for (Eigen::Index k = 0; k < t.size(); ++k) t(k) += U(rng);
  return t;
}

Vector3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> N(0, 1);
  return Vector3(N(rng), N(rng), N(rng)).normalized();
}

/// A spatial 4-joint arm on a base (axes z, y, x, y; the last joint prismatic when `prismatic`). With
/// `rotors`, each revolute joint k also drives a counter-rotating pair of rotor bodies on its axis,
/// hung on its parent (mimics with multipliers +N and -N, axisymmetric inertia diag(J/2, J/2, J) about
/// the axis, 1 g at the axis): they add 2 N^2 J to H_kk and cancel each other in the couplings.
/// With `rigid_rotors` the same rotor bodies are merged rigidly into the parents (fixed joints).
Model rotor_arm(bool rotors, bool rigid_rotors, double N, double J, bool prismatic = false) {
  ModelBuilder b("base", {300, {0.02, -0.01, 0.03}, Vector3(40, 50, 45).asDiagonal()});
  const Vector3 axes[4] = {Vector3::UnitZ(), Vector3::UnitY(), Vector3::UnitX(), Vector3::UnitY()};
  const Pose origins[4] = {
      Pose::from_xyz_rpy({0.3, 0.1, 0.2}, {0.1, 0, 0}), Pose::from_xyz_rpy({0.2, 0, 0.1}, {0, 0.2, 0}),
      Pose::from_xyz_rpy({0.6, 0.05, 0}, {0, 0, 0.3}), Pose::from_xyz_rpy({0.5, 0, -0.05}, {0.2, 0, 0})};
  std::string parent = "base";
  for (int k = 0; k < 4; ++k) {
    const std::string link = "l" + std::to_string(k + 1), joint = "j" + std::to_string(k + 1);
    const bool pri = prismatic && k == 3;
    b.add_joint(joint, pri ? JointType::Prismatic : JointType::Revolute, parent, origins[k], axes[k], link,
                {4.0 - 0.5 * k, {0.2, 0.02, -0.01}, Vector3(0.02, 0.3, 0.31).asDiagonal()});
    if (!pri) {
      Vector3 d = Vector3::Constant(0.5 * J);
      d(axes[k].cwiseAbs().maxCoeff() == axes[k](0) ? 0 : (axes[k](1) != 0 ? 1 : 2)) = J;
      const Inertia rotor{1e-3, Vector3::Zero(), d.asDiagonal()};
      for (const char* side : {"a", "b"}) {
        const std::string name = "rotor" + std::to_string(k + 1) + side;
        if (rotors) {
          b.add_joint(name + "_joint", JointType::Revolute, parent, origins[k], axes[k], name, rotor);
          b.set_mimic(name + "_joint", joint, side[0] == 'a' ? N : -N, 0.0);
        } else if (rigid_rotors) {
          b.add_fixed(name + "_joint", parent, origins[k], name, rotor);
        }
      }
    }
    parent = link;
  }
  b.set_end_effector("l4");
  return b.build();
}

}  // namespace

TEST_CASE("locked joints: the composite rigid body summed over the bodies", "[joints]") {
  std::mt19937 rng(7);
  for (const auto& file : scenario_files()) {
    const Scenario sc = load_scenario(file);
    const Model& model = *sc.model;
    Data data(model);
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::VectorXd th = trial == 0 ? sc.problem.theta : perturbed(sc.problem.theta, rng, 0.5);
      const Vector3 u = trial == 0 ? sc.problem.target.normal_world() : random_unit(rng);
      crba(model, data, sc.problem.base, th);
      const double q = inverse_effective_mass(model, data, sc.problem.frame, u, locked());
      const Vector3 pe = frame_pose(model, data, sc.problem.frame).p;
      const double ref = composite_inverse_mass(model, sc.problem.base, th, pe, u);
      INFO(file << " trial " << trial << ": locked " << q << ", composite " << ref);
      CHECK(std::abs(q - ref) <= 1e-10 * ref);
      // locked is the upper bound of the effective mass: free joints give the smallest
      CHECK(q <= inverse_effective_mass(model, data, sc.problem.frame, u) * (1 + 1e-12));
    }
  }
}

TEST_CASE("armature: H of counter-rotating rotor pairs on the joint axes", "[joints]") {
  const double N = 100, J = 3e-5, a = 2 * N * N * J;  // 0.6 kg m^2 reflected per joint
  const Model plain = rotor_arm(false, false, N, J), rigid = rotor_arm(false, true, N, J);
  const Model rotors = rotor_arm(true, false, N, J);
  REQUIRE(rotors.n() == 4);
  REQUIRE(rotors.nb() == 13);
  Data dp(plain), dr(rigid), dm(rotors);
  const BasePose base{{0.1, -0.2, 0.3}, Quaternion(Eigen::AngleAxisd(0.4, Vector3(1, 2, 3).normalized()))};
  const Eigen::VectorXd th = (Eigen::VectorXd(4) << 0.3, -0.7, 1.1, 0.4).finished();
  crba(plain, dp, base, th);
  crba(rigid, dr, base, th);
  crba(rotors, dm, base, th);
  Eigen::MatrixXd expected = dr.H;
  expected.diagonal().tail(4).array() += a;
  CHECK((dm.H - expected).cwiseAbs().maxCoeff() <= 1e-12 * dm.H.cwiseAbs().maxCoeff());
  // without the rotors' own (un-geared) inertia, the armature model of the plain arm: the difference
  // is the rotors' J-sized rigid inertia only
  Eigen::MatrixXd with_a = dp.H;
  with_a.diagonal().tail(4).array() += a;
  CHECK((dm.H - with_a).cwiseAbs().maxCoeff() <= 20 * J + 0.01);
  // the effective mass: armature on the rigid-rotor arm = free joints of the geared-rotor arm
  const int f = plain.frame_index("l4");
  for (const Vector3& u : {Vector3(1, 0, 0), Vector3(0.3, -0.4, 0.866).normalized()}) {
    const double q_arm = inverse_effective_mass(rigid, dr, rigid.frame_index("l4"), u,
                                                armature(Eigen::VectorXd::Constant(4, a)));
    const double q_rot = inverse_effective_mass(rotors, dm, rotors.frame_index("l4"), u);
    CHECK(std::abs(q_arm - q_rot) <= 1e-10 * q_rot);
  }
  // zero armature is free, bit for bit in value
  const Vector3 u(0, 0, 1);
  CHECK(inverse_effective_mass(plain, dp, f, u, armature(Eigen::VectorXd::Zero(4))) ==
        Approx(inverse_effective_mass(plain, dp, f, u)).epsilon(1e-14));
}

TEST_CASE("armature: large armature tends to the locked robot", "[joints]") {
  for (const auto& file : scenario_files()) {
    const Scenario sc = load_scenario(file);
    const Model& model = *sc.model;
    Data data(model);
    crba(model, data, sc.problem.base, sc.problem.theta);
    const Vector3 u = sc.problem.target.normal_world();
    const double ql = inverse_effective_mass(model, data, sc.problem.frame, u, locked());
    auto rel_gap = [&](double a) {  // (m_e(a) - m_locked) / m_locked
      const double q = inverse_effective_mass(model, data, sc.problem.frame, u,
                                              armature(Eigen::VectorXd::Constant(model.n(), a)));
      return (1 / q - 1 / ql) * ql;
    };
    const double qf = inverse_effective_mass(model, data, sc.problem.frame, u);
    const double qm = inverse_effective_mass(model, data, sc.problem.frame, u,
                                             armature(Eigen::VectorXd::Constant(model.n(), 0.5)));
    const double g8 = rel_gap(1e8), g9 = rel_gap(1e9), g10 = rel_gap(1e10);
    INFO(file << ": free " << 1 / qf << " kg, armature 0.5 " << 1 / qm << " kg, locked " << 1 / ql
              << " kg; relative gap at 1e8, 1e9, 1e10 kg m^2: " << g8 << ", " << g9 << ", " << g10);
    // the gap closes like c / a (first order in 1/a): the same c at 1e8 and 1e10, below 1e-5 at 1e8
    // (the paper robots' heavy links give c = 3.4e2 and 1.8e2) and 1e-6 at 1e9
    CHECK(g8 < 0);
    CHECK(std::abs(g8) <= 1e-5);
    CHECK(std::abs(g9) <= 1e-6);
    CHECK(g10 * 1e10 == Approx(g8 * 1e8).epsilon(1e-3));
    CHECK(qm <= qf);  // between free and locked
    CHECK(qm >= ql);
  }
}

TEST_CASE("joint models: the gradient of M_ie against central differences", "[joints]") {
  std::mt19937 rng(11);
  std::vector<std::pair<std::string, std::unique_ptr<Model>>> models;
  for (const auto& file : {source("robots/paper_3dof.toml"), source("robots/paper_7dof_position.toml")}) {
    Scenario sc = load_scenario(file);
    models.emplace_back(file, std::move(sc.model));
  }
  models.emplace_back("prismatic arm", std::make_unique<Model>(rotor_arm(false, false, 1, 0, true)));
  for (auto& [name, mp] : models) {
    const Model& model = *mp;
    const int n = model.n(), frame = model.end_effector();
    Data data(model);
    Eigen::VectorXd a(n);
    for (int k = 0; k < n; ++k) a(k) = 0.2 + 0.3 * k;
    const double tinv = 1.0 / 150.0;
    for (const ContactJoints& joints : {ContactJoints{}, locked(), armature(a)}) {
      const BasePose base{{0.2, 0.1, -0.1}, Quaternion(Eigen::AngleAxisd(0.3, Vector3::UnitZ()))};
      const Eigen::VectorXd th = perturbed(Eigen::VectorXd::Constant(n, 0.4), rng, 0.8);
      const Vector3 u = random_unit(rng);
      Eigen::VectorXd g(n), gd(n);
      const double M =
          integrated_effective_mass_gradient_dense(model, data, base, th, frame, u, tinv, joints, g);
      const double h = 1e-6;
      for (int k = 0; k < n; ++k) {
        Eigen::VectorXd tp = th, tm = th;
        tp(k) += h;
        tm(k) -= h;
        auto Mie = [&](const Eigen::VectorXd& t) {
          crba(model, data, base, t);
          return 1.0 / (inverse_effective_mass(model, data, frame, u, joints) + tinv);
        };
        gd(k) = (Mie(tp) - Mie(tm)) / (2 * h);
      }
      INFO(name << " " << joint_model_name(joints.model) << ": M_ie " << M << "\n analytic " << g.transpose()
                << "\n numeric  " << gd.transpose());
      CHECK((g - gd).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, gd.cwiseAbs().maxCoeff()));
      crba(model, data, base, th);
      CHECK(M == Approx(1.0 / (inverse_effective_mass(model, data, frame, u, joints) + tinv)).epsilon(1e-13));
    }
  }
}

TEST_CASE("joint models: no allocation per call, H left as it was", "[joints]") {
  const Scenario sc = load_scenario(source("robots/paper_7dof_position.toml"));
  const Model& model = *sc.model;
  Data data(model);
  const ContactJoints arm = armature(Eigen::VectorXd::Constant(model.n(), 0.5));
  Eigen::VectorXd g(model.n());
  const Vector3 u = sc.problem.target.normal_world();
  crba(model, data, sc.problem.base, sc.problem.theta);
  const Eigen::MatrixXd H = data.H;
  Eigen::internal::set_is_malloc_allowed(false);
  double sum = 0;
  for (const ContactJoints* j : {&arm}) {
    sum += inverse_effective_mass(model, data, sc.problem.frame, u, *j);
    sum += inverse_effective_mass(model, data, sc.problem.frame, u, locked());
    sum += integrated_effective_mass_gradient_dense(model, data, sc.problem.base, sc.problem.theta,
                                                    sc.problem.frame, u, 0.01, *j, g);
  }
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(std::isfinite(sum));
  CHECK(data.H == H);
}

TEST_CASE("joint models: parse and validate", "[joints]") {
  CHECK(parse_joint_model("locked", "--contact-joints") == JointModel::Locked);
  CHECK_THROWS_WITH(parse_joint_model("rigid", "--contact-joints"),
                    Catch::Contains("--contact-joints") && Catch::Contains("unknown joint model 'rigid'"));
  const Model m = rotor_arm(false, false, 1, 0);
  CHECK_THROWS_WITH(per_joint_values({0.1, 0.1, 0.1}, m, "--armature"),
                    Catch::Contains("--armature: 3 values for 4 joints (j1, j2, j3, j4)"));
  CHECK_THROWS_WITH(per_joint_values({0.1, 0.1, -1, 0.1}, m, "--armature"),
                    Catch::Contains("--armature: the value of joint 'j3' must be finite and >= 0"));
  CHECK_THROWS_WITH(per_joint_values({std::nan("")}, m, "--joint-damping"),
                    Catch::Contains("--joint-damping: the value of joint 'j1'"));
  CHECK(per_joint_values({}, m, "--armature") == Eigen::VectorXd::Zero(4));
  CHECK(per_joint_values({0.5}, m, "--armature") == Eigen::VectorXd::Constant(4, 0.5));
}

namespace {

struct ServoRun {
  MultibodyContactResult mb;
  double f_free, f_locked;  ///< the single-body exact peaks at the free and locked M_ie
  double M_free, M_locked;
};

/// The multibody contact of the 3-DOF paper robot at [0, 90, -90] deg with the paper's target, with
/// joint PD gains K, D and armature a on every joint; beside it the single-body peaks (exact) at the
/// free and locked M_ie.
ServoRun servo_run(double K, double D, double a) {
  const Scenario sc = load_scenario(source("robots/paper_3dof.toml"));
  const Model& model = *sc.model;
  const Eigen::VectorXd th = Eigen::Vector3d(0, 90, -90) * (M_PI / 180);
  MultibodyContactOptions mo;
  mo.joint_stiffness = Eigen::VectorXd::Constant(model.n(), K);
  mo.joint_damping = Eigen::VectorXd::Constant(model.n(), D);
  mo.armature = Eigen::VectorXd::Constant(model.n(), a);
  const CaptureProblem& pb = sc.problem;
  ServoRun r;
  r.mb = simulate_contact(model, pb.base, th, pb.frame, pb.target, pb.approach_speed, pb.contact, pb.law, mo);
  Data data(model);
  r.M_free = integrated_effective_mass(model, data, pb.base, th, pb.frame, pb.target);
  r.M_locked = integrated_effective_mass(model, data, pb.base, th, pb.frame, pb.target, locked());
  const AnyContactLaw law = make_contact_law(pb.law, pb.contact, r.mb.approach_velocity);
  r.f_free = max_force_exact(law, r.M_free);
  r.f_locked = max_force_exact(law, r.M_locked);
  return r;
}

}  // namespace

TEST_CASE("multibody with joint PD: from free to locked", "[joints][multibody]") {
  const ServoRun free = servo_run(0, 0, 0);
  const ServoRun soft = servo_run(1e-3, 1e-3, 0);
  const ServoRun stiff = servo_run(1e12, 1e8, 0);
  INFO("M_ie free " << free.M_free << " kg, locked " << free.M_locked << " kg; F_max free run "
                    << free.mb.f_max << " N (single body " << free.f_free << "), soft " << soft.mb.f_max
                    << ", stiff " << stiff.mb.f_max << " N (locked single body " << free.f_locked << ")");
  CHECK(std::abs(soft.mb.f_max - free.mb.f_max) <= 1e-4 * free.mb.f_max);
  CHECK(std::abs(stiff.mb.f_max - free.f_locked) <= 1e-2 * free.f_locked);
  // the servo's torques are internal: robot plus target keep their momentum
  CHECK((stiff.mb.momentum_end - stiff.mb.momentum_start).norm() <=
        1e-6 * stiff.mb.momentum_start.norm() + 1e-9);
}

TEST_CASE("multibody with armature: the armature model's prediction", "[joints][multibody]") {
  const double a = 0.5;
  const ServoRun r = servo_run(0, 0, a);
  const Scenario sc = load_scenario(source("robots/paper_3dof.toml"));
  const Model& model = *sc.model;
  Data data(model);
  const Eigen::VectorXd th = Eigen::Vector3d(0, 90, -90) * (M_PI / 180);
  const CaptureProblem& pb = sc.problem;
  const double M_a = integrated_effective_mass(model, data, pb.base, th, pb.frame, pb.target,
                                               armature(Eigen::VectorXd::Constant(3, a)));
  const AnyContactLaw law = make_contact_law(pb.law, pb.contact, r.mb.approach_velocity);
  const double f_a = max_force_exact(law, M_a);
  INFO("M_ie free " << r.M_free << ", armature " << M_a << ", locked " << r.M_locked
                    << " kg; F_max multibody " << r.mb.f_max << " N, single body " << f_a << " N");
  CHECK(M_a > r.M_free);
  CHECK(M_a < r.M_locked);
  CHECK(std::abs(r.mb.f_max - f_a) <= 1e-2 * f_a);
  // a passive armature keeps the energy (c_r = 0.9 loses some: only check it went down)
  CHECK(r.mb.energy_end <= r.mb.energy_start);
}

TEST_CASE("multibody servo table (measurement)", "[.measure]") {
  for (auto [K, D] : std::vector<std::pair<double, double>>{{0, 0}, {1e4, 1e2}, {1e8, 1e5}, {1e12, 1e8}}) {
    const ServoRun r = servo_run(K, D, 0);
    WARN("K " << K << " D " << D << ": F_max " << r.mb.f_max << " N, t_peak " << r.mb.t_at_f_max
              << " s, duration " << r.mb.contact_duration << " s, steps " << r.mb.steps
              << "; single body free " << r.f_free << " N (M " << r.M_free << "), locked " << r.f_locked
              << " N (M " << r.M_locked << ")");
  }
}

TEST_CASE("scenario keys of the joint models: bad values name the key", "[joints]") {
  auto build = [&](const std::string& extra) {
    ScenarioKeys k = read_scenario_file(source("robots/paper_3dof.toml"));
    for (const auto& line : {extra}) {
      const auto eq = line.find('=');
      override_scenario_key(k, line.substr(0, eq), line.substr(eq + 1));
    }
    return build_scenario(k);
  };
  CHECK(build("contact-joints=locked").problem.joints.model == JointModel::Locked);
  CHECK(build("armature=0.2,0.3,0.4").problem.joints.armature == Eigen::Vector3d(0.2, 0.3, 0.4));
  CHECK_THROWS_WITH(build("contact-joints=rigid"),
                    Catch::Contains("--contact-joints: unknown joint model 'rigid'"));
  CHECK_THROWS_WITH(build("armature=-1"), Catch::Contains("--armature: the value of joint"));
  CHECK_THROWS_WITH(build("armature=1,2"),
                    Catch::Contains("--armature: 2 values for 3 joints (joint1, joint2, joint3)"));
  CHECK_THROWS_WITH(build("joint-stiffness=-5"), Catch::Contains("--joint-stiffness: the value of joint"));
  CHECK_THROWS_WITH(build("joint-damping=1,2,3,4"),
                    Catch::Contains("--joint-damping: 4 values for 3 joints"));
  CHECK_THROWS_WITH(build("armature=nan"), Catch::Contains("--armature"));
}

TEST_CASE("joint models on the paper's scenarios (measurement)", "[.measure]") {
  const char* names[] = {"free", "locked", "armature"};
  for (const char* file : {"robots/paper_3dof.toml", "robots/paper_7dof_position.toml"}) {
    for (const char* chosen : names) {
      ScenarioKeys k = read_scenario_file(source(file));
      override_scenario_key(k, "contact-joints", chosen);
      override_scenario_key(k, "armature", "0.5");
      const Scenario sc = build_scenario(k);
      const ScenarioResult r = run_scenario(sc);
      const CaptureSetup setup = prepare_capture(sc.problem, sc.task, sc.capture);
      const Model& model = *sc.model;
      Data data(model);
      const std::pair<const char*, const CaptureResult*> rows[] = {
          {"plain", &r.plain}, {"paper", &r.optimized}, {"global", &r.global->result.run}};
      for (const auto& [label, run] : rows) {
        std::ostringstream os;
        os << file << " objective " << chosen << " " << label << " [";
        for (int i = 0; i < model.n(); ++i) os << (i ? ", " : "") << run->theta(i) * 180 / M_PI;
        os << "] deg:";
        crba(model, data, run->base, run->theta);
        for (const char* m : names) {
          const ContactJoints j{parse_joint_model(m, "m"), sc.problem.joints.armature};
          const double M =
              1.0 / (inverse_effective_mass(model, data, sc.problem.frame, setup.capture.u_cap, j) +
                     setup.capture.target_inv_mass);
          const AnyContactLaw law =
              make_contact_law(sc.problem.law, sc.problem.contact, run->approach_velocity);
          os << "  " << m << " M " << M << " kg F " << max_force_exact(law, M) << " N;";
        }
        WARN(os.str());
      }
    }
  }
}

TEST_CASE("ffsr-optimize with joint models: contact, map, the main job, bad flags", "[joints][command]") {
  using ffsr::test::cli;
  using ffsr::test::kUrdf3;
  const Scenario sc = load_scenario(source("robots/paper_3dof.toml"));
  const Eigen::VectorXd th = Eigen::Vector3d(0, 90, -90) * (M_PI / 180);
  Data data(*sc.model);
  Target target;  // the contact command's default target: the paper's, at rest
  target.mass = 200;
  target.inertia = 100 * Matrix3::Identity();
  target.contact_offset = Vector3(-0.25, 0.15, 0);
  const double M_locked =
      integrated_effective_mass(*sc.model, data, sc.problem.base, th, sc.problem.frame, target, locked());
  SECTION("contact --contact-joints all: the three predictions beside the multibody run with the armature") {
    const auto r = cli({"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--contact-joints", "all",
                        "--armature", "0.5", "--json"});
    REQUIRE(r.exit_code == 0);
    const auto j = nlohmann::json::parse(r.out);
    REQUIRE(j["joint_models"].size() == 3);
    CHECK(j["joint_models"][1]["contact_joints"] == "locked");
    CHECK(j["joint_models"][1]["integrated_effective_mass"].get<double>() == Approx(M_locked).epsilon(1e-12));
    const double f_arm = j["joint_models"][2]["f_max_exact"], f_mb = j["f_max_multibody"];
    CHECK(std::abs(f_arm - f_mb) <= 1e-2 * f_mb);
  }
  SECTION("contact with stiff servo gains: the multibody peak at the locked prediction") {
    const auto r = cli({"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--contact-joints", "locked",
                        "--joint-stiffness", "1e12", "--joint-damping", "1e8", "--json"});
    REQUIRE(r.exit_code == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j["contact_joints"] == "locked");
    CHECK(j["integrated_effective_mass"].get<double>() == Approx(M_locked).epsilon(1e-12));
    const double f_exact = j["f_max_exact"], f_mb = j["f_max_multibody"];
    CHECK(std::abs(f_exact - f_mb) <= 1e-2 * f_exact);
  }
  SECTION("map of the locked model") {
    const auto r = cli({"map", "--urdf", kUrdf3, "--joints-deg", "0,90,-90", "--vary", "3", "--range-deg",
                        "-90,-89", "--step-deg", "1", "--contact-joints", "locked", "--csv", "-"});
    REQUIRE(r.exit_code == 0);
    CHECK(r.out.find("joint3_deg,M_ie_locked_kg,F_max_N") != std::string::npos);
    const auto line = r.out.substr(r.out.find('\n') + 1);
    CHECK(std::stod(line.substr(line.find(',') + 1)) == Approx(M_locked).epsilon(1e-12));
  }
  SECTION("the main job records the model") {
    const auto r = cli({"--config", source("robots/paper_3dof.toml"), "--contact-joints", "locked",
                        "--global", "false", "--json", "-", "--quiet"});
    REQUIRE(r.exit_code == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j["scenario"]["contact-joints"] == "locked");
    CHECK(j["baseline"]["integrated_effective_mass"].get<double>() > 50);
  }
  SECTION("bad flags: one line naming the flag") {
    const std::vector<std::pair<std::vector<std::string>, std::string>> bad{
        {{"--contact-joints", "rigid"}, "--contact-joints: unknown joint model 'rigid'"},
        {{"--armature", "-1"}, "--armature: the value of joint 'joint1' must be finite and >= 0"},
        {{"--armature", "1,2"}, "--armature: 2 values for 3 joints (joint1, joint2, joint3)"},
        {{"--joint-stiffness", "-1"}, "--joint-stiffness: the value of joint 'joint1'"},
        {{"--joint-damping", "1,2,3,4"}, "--joint-damping: 4 values for 3 joints"}};
    for (const auto& [args, message] : bad) {
      std::vector<std::string> a{"contact", "--urdf", kUrdf3, "--joints-deg", "0,90,-90"};
      a.insert(a.end(), args.begin(), args.end());
      const auto r = cli(a);
      INFO(args.front() << ": " << r.err);
      CHECK(r.exit_code != 0);
      CHECK(r.err.find(message) != std::string::npos);
      CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
      CHECK(r.out.empty());
    }
  }
}

}  // namespace test_joint_models
