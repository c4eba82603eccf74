// tests/unit/test_fast_dynamics.cpp -- the allocation-free CRBA and the O(n) integrated effective mass
// against independent routes, on every kind of tree the library builds.
//
// Models: the paper's 3-DOF and 7-DOF robots (URDF, unit joint axes), serial chains with random axes
// and with axes along +-x, +-y, +-z (some joint origins without rotation, some diagonal inertias), a
// branched tree numbered depth-first (as the URDF loader numbers it: the contiguous-subtree path of
// crba) with revolute and prismatic joints, the same tree added out of depth-first order (the
// ancestor-walk path), and a chain with a mimic joint (dense paths only).
//
// References, each computed another way: H against the columns of RNEA with unit accelerations (body
// coordinates, no composite inertias); the O(n) inverse effective mass under the free, locked and
// armature models against crba + the dense Cholesky path of joint_models.hpp (which forms H and
// factorizes it); the O(n) gradient against the dense analytic gradient and against central finite
// differences of the O(n) value; the O(n) forward dynamics (aba) against forward_dynamics (crba, the
// RNEA bias, a dense Cholesky solve) and against the identity H a + C = tau with RNEA (body
// coordinates) as the inverse dynamics. Tolerances are stated at each check.
#include "support/dynamics_helpers.hpp"

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/algorithm/forward_dynamics.hpp"
#include "ffsr/algorithm/momentum.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace test_fast_dynamics {

using namespace ffsr;
using namespace ffsr_test;

namespace {

struct Named {
  std::string name;
  Model model;
};

/// A serial chain of n joints; `unit_axes`: axes +-x, +-y, +-z in turn and every third joint origin
/// without rotation; else random axes and rotations. Inertias full, every other one diagonal.
Model chain(int n, unsigned seed, bool unit_axes, const Vector3& gravity = Vector3::Zero()) {
  Rng rng(seed);
  ModelBuilder b("base", Inertia{400, rng.vec3(0.2), rng.inertia(100)});
  b.set_gravity(gravity);
  std::string parent = "base";
  const Vector3 axes[] = {Vector3::UnitX(), -Vector3::UnitY(), Vector3::UnitZ(),
                          -Vector3::UnitX(), Vector3::UnitY(), -Vector3::UnitZ()};
  for (int i = 0; i < n; ++i) {
    const std::string child = "l" + std::to_string(i + 1);
    const Vector3 rpy = unit_axes && i % 3 == 0 ? Vector3::Zero() : rng.vec3(M_PI);
    const Vector3 axis = unit_axes ? axes[i % 6] : rng.unit();
    const Matrix3 I = i % 2 ? Matrix3(Vector3(0.2, 0.3, 0.4).asDiagonal()) : rng.inertia(0.5);
    b.add_joint("j" + std::to_string(i + 1), JointType::Revolute, parent,
                Pose::from_xyz_rpy(rng.vec3(0.4), rpy), axis, child, Inertia{rng.uniform(1, 10), rng.vec3(0.2), I});
    parent = child;
  }
  b.add_fixed("tip_mount", parent, Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

/// A branched tree: trunk with branches a (a1 - a2 (prismatic) - a3, and c1 - c2 on a1) and b
/// (b1 - b2), end-effector on a3. `depth_first`: bodies added so that every subtree is a contiguous
/// range (a1 a2 a3 c1 c2 b1 b2); else interleaved (a1 b1 a2 c1 b2 a3 c2).
Model tree(unsigned seed, bool depth_first) {
  Rng rng(seed);
  ModelBuilder b("trunk", Inertia{300, rng.vec3(0.3), rng.inertia(20)});
  struct J {
    const char *joint, *parent, *child;
    JointType type;
  };
  const std::vector<J> dfs = {{"ja1", "trunk", "a1", JointType::Revolute}, {"ja2", "a1", "a2", JointType::Prismatic},
                              {"ja3", "a2", "a3", JointType::Revolute},    {"jc1", "a1", "c1", JointType::Revolute},
                              {"jc2", "c1", "c2", JointType::Prismatic},   {"jb1", "trunk", "b1", JointType::Revolute},
                              {"jb2", "b1", "b2", JointType::Revolute}};
  const std::vector<int> interleaved = {0, 5, 1, 3, 6, 2, 4};
  for (int k = 0; k < 7; ++k) {
    const J& j = dfs[static_cast<size_t>(depth_first ? k : interleaved[static_cast<size_t>(k)])];
    b.add_joint(j.joint, j.type, j.parent, Pose::from_xyz_rpy(rng.vec3(0.6), rng.vec3(M_PI)), rng.unit(), j.child,
                Inertia{rng.uniform(2, 12), rng.vec3(0.3), rng.inertia(0.5)});
  }
  b.add_fixed("tip_mount", "a3", Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

/// A chain of 5 joints whose joint j4 mimics j2 (multiplier -0.7, offset 0.2).
Model mimic_chain(unsigned seed) {
  Rng rng(seed);
  ModelBuilder b("base", Inertia{200, rng.vec3(0.2), rng.inertia(50)});
  std::string parent = "base";
  for (int i = 0; i < 5; ++i) {
    const std::string child = "l" + std::to_string(i + 1);
    b.add_joint("j" + std::to_string(i + 1), JointType::Revolute, parent,
                Pose::from_xyz_rpy(rng.vec3(0.4), rng.vec3(M_PI)), rng.unit(), child,
                Inertia{rng.uniform(1, 10), rng.vec3(0.2), rng.inertia(0.5)});
    parent = child;
  }
  b.set_mimic("j4", "j2", -0.7, 0.2);
  b.add_fixed("tip_mount", parent, Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

std::vector<Named> models_under_test() {
  std::vector<Named> m;
  m.push_back({"paper 3-DOF", model_from_urdf_file(source_path("robots/paper_3dof.urdf"))});
  m.push_back({"paper 7-DOF", model_from_urdf_file(source_path("robots/paper_7dof.urdf"))});
  for (int n : {1, 3, 7, 14, 28}) m.push_back({"chain " + std::to_string(n), chain(n, 100u + unsigned(n), false)});
  m.push_back({"unit-axis chain 12", chain(12, 7, true)});
  m.push_back({"depth-first tree", tree(5, true)});
  m.push_back({"interleaved tree", tree(5, false)});
  return m;
}

/// The three contact-joint models, the armature one with a different value per joint.
std::vector<ContactJoints> joint_models(const Model& m) {
  Eigen::VectorXd a(m.n());
  for (int k = 0; k < m.n(); ++k) a(k) = 0.05 + 0.1 * k;
  return {{JointModel::Free, Eigen::VectorXd::Zero(m.n())}, {JointModel::Locked, Eigen::VectorXd::Zero(m.n())},
          {JointModel::Armature, a}};
}

}  // namespace

TEST_CASE("crba equals the columns of RNEA on chains and trees of every numbering", "[dynamics][fast]") {
  Rng rng(41);
  std::vector<Named> models = models_under_test();
  models.push_back({"mimic chain", mimic_chain(3)});
  for (const auto& [name, model] : models) {
    Data d(model);
    for (int k = 0; k < 3; ++k) {
      const Config q = random_config(model, rng);
      const MatrixXd H = crba(model, d, q.base, q.theta);
      // exactly symmetric: both triangles are written from one computed value
      CHECK((H - H.transpose()).cwiseAbs().maxCoeff() == 0.0);
      const VectorXd zero = VectorXd::Zero(model.nv());
      const double scale = H.cwiseAbs().maxCoeff();
      for (int i = 0; i < model.nv(); ++i) {
        INFO(name << " config " << k << " column " << i);
        // RNEA in body coordinates, without composite inertias: rounding only, 1e-12 of H's largest entry
        const VectorXd col = rnea(model, d, q.base, q.theta, zero, VectorXd::Unit(model.nv(), i));
        CHECK((col - H.col(i)).cwiseAbs().maxCoeff() < 1e-12 * scale);
      }
    }
  }
}

TEST_CASE("the O(n) integrated effective mass equals the dense path under every joint model",
          "[dynamics][fast]") {
  Rng rng(43);
  for (const auto& [name, model] : models_under_test()) {
    Data dense(model), fast(model);
    for (int k = 0; k < 4; ++k) {
      const Config q = random_config(model, rng);
      Target t;
      t.attitude = rng.quaternion();
      const Vector3 u = t.normal_world();
      const double tim = t.inverse_mass_along_normal();
      for (const ContactJoints& joints : joint_models(model)) {
        INFO(name << " config " << k << " joints " << joint_model_name(joints.model));
        // dense: crba, H (+ armature) factorized, forward substitution; or H_bb for locked
        const double M =
            integrated_effective_mass_dense(model, dense, q.base, q.theta, model.end_effector(), t, joints);
        const double M_fast =
            integrated_effective_mass(model, fast, q.base, q.theta, model.end_effector(), u, tim, joints);
        // two factorizations of the same SPD system: rounding, 1e-12 relative
        CHECK(std::abs(M_fast - M) <= 1e-12 * M);
        // one name, one route: the target's overload is the (u, 1/m_t) one, free joints the default
        const int ee = model.end_effector();
        CHECK(integrated_effective_mass(model, fast, q.base, q.theta, ee, t, joints) == M_fast);
        if (joints.model == JointModel::Free) {
          CHECK(integrated_effective_mass(model, fast, q.base, q.theta, ee, t) == M_fast);
          CHECK(integrated_effective_mass_dense(model, dense, q.base, q.theta, ee, t) == M);
        }
        // the inverse effective mass alone at another frame (the base's) and the first link's
        for (int frame : {0, 1}) {
          crba(model, dense, q.base, q.theta);
          const double inv = inverse_effective_mass(model, dense, frame, u, joints);
          forward_kinematics(model, fast, q.base, q.theta);
          CHECK(std::abs(inverse_effective_mass_articulated(model, fast, frame, u, joints) - inv) <= 1e-12 * inv);
        }
      }
    }
  }
}

TEST_CASE("the O(n) gradient of M_ie equals the dense gradient and finite differences", "[dynamics][fast]") {
  Rng rng(47);
  for (const auto& [name, model] : models_under_test()) {
    if (model.n() > 14) continue;  // the finite differences cost n evaluations each
    Data dense(model), fast(model);
    for (int k = 0; k < 2; ++k) {
      const Config q = random_config(model, rng, 2.5);
      const Vector3 u = rng.unit();
      const double tim = 0.004;
      for (const ContactJoints& joints : joint_models(model)) {
        INFO(name << " config " << k << " joints " << joint_model_name(joints.model));
        VectorXd g_dense(model.n()), g_fast(model.n());
        const double M_dense = integrated_effective_mass_gradient_dense(
            model, dense, q.base, q.theta, model.end_effector(), u, tim, joints, g_dense);
        const double M = integrated_effective_mass_gradient(model, fast, q.base, q.theta,
                                                            model.end_effector(), u, tim, joints, g_fast);
        CHECK(std::abs(M - M_dense) <= 1e-12 * M_dense);
        // the same formula fed by two solves: rounding, 1e-10 of the gradient's largest entry
        const double gs = std::max(g_dense.cwiseAbs().maxCoeff(), 1e-12);
        CHECK((g_fast - g_dense).cwiseAbs().maxCoeff() < 1e-10 * gs);
        // central differences of the O(n) value, h = 1e-6 rad: truncation O(h^2) ~ 1e-12, rounding
        // ~ 1e-16 M / h ~ 1e-10 relative to M; checked to 1e-6 of the largest entry plus 1e-8 M
        for (int j = 0; j < model.n(); ++j) {
          const double h = 1e-6;
          VectorXd tp = q.theta, tm = q.theta;
          tp(j) += h;
          tm(j) -= h;
          const int ee = model.end_effector();
          const double fd = (integrated_effective_mass(model, fast, q.base, tp, ee, u, tim, joints) -
                             integrated_effective_mass(model, fast, q.base, tm, ee, u, tim, joints)) /
                            (2 * h);
          INFO("joint " << j << " analytic " << g_fast(j) << " finite differences " << fd);
          CHECK(std::abs(g_fast(j) - fd) < 1e-6 * gs + 1e-8 * M);
        }
      }
    }
  }
}

TEST_CASE("aba: the O(n) forward dynamics equals crba + RNEA + Cholesky and inverts RNEA", "[dynamics][fast]") {
  Rng rng(59);
  std::vector<Named> models = models_under_test();
  models.push_back({"chain 7 with gravity", chain(7, 61, false, Vector3(0.3, -9.81, 1.2))});
  for (const auto& [name, model] : models) {
    Data d(model), e(model);
    const Eigen::Index nv = model.nv();
    for (int k = 0; k < 3; ++k) {
      const Config q = random_config(model, rng);
      // base velocity ~ 0.1 m/s and 0.1 rad/s, joint rates ~ 1 rad/s, forces ~ 100 N, 100 N m
      VectorXd v = rng.vec(nv, 1.0), tau = rng.vec(nv, 100.0);
      v.head<6>() *= 0.1;
      INFO(name << " config " << k);
      VectorXd a, a_ref;
      aba(model, d, q.base, q.theta, v, tau, a);
      forward_dynamics(model, e, q.base, q.theta, v, tau, a_ref);
      // two exact solves of the same system: rounding amplified by H's condition number (up to ~1e6 on
      // the 28-joint chain): 1e-9 of the largest acceleration
      const double as = a_ref.cwiseAbs().maxCoeff();
      INFO("aba " << a.transpose() << "\nforward_dynamics " << a_ref.transpose());
      CHECK((a - a_ref).cwiseAbs().maxCoeff() < 1e-9 * as);
      // H a + C = tau by RNEA with the acceleration aba found (body coordinates, no articulated
      // inertias): rounding, 1e-11 of the largest of |tau|, |C| and |H| |a|
      const VectorXd C = bias_forces(model, e, q.base, q.theta, v);
      const MatrixXd H = crba(model, e, q.base, q.theta);
      const double fs =
          std::max({tau.cwiseAbs().maxCoeff(), C.cwiseAbs().maxCoeff(), H.cwiseAbs().maxCoeff() * as});
      CHECK((rnea(model, e, q.base, q.theta, v, a) - tau).cwiseAbs().maxCoeff() < 1e-11 * fs);
      CHECK((H * a + C - tau).cwiseAbs().maxCoeff() < 1e-11 * fs);
      // the second half again with other forces at the same state (as the closed loop does when only
      // the joint torques change): the same numbers as a full aba with those forces
      const VectorXd tau2 = rng.vec(nv, 100.0);
      VectorXd a2(nv), a2_full;
      detail::aba_acceleration_pass(model, d, v, tau2, a2);
      aba(model, e, q.base, q.theta, v, tau2, a2_full);
      CHECK(a2 == a2_full);
      // the momentum from the velocity pass's bodies (sum of I_i V_i, what the closed loop records
      // per tick) against the body-by-body sum of momentum() and against H v (its first six rows)
      const Vector6 h_pass = detail::momentum_from_velocity_pass(model, d);
      forward_kinematics(model, e, q.base, q.theta);
      const Vector6 h_ref = momentum(model, e, v);
      const Vector6 h_H = (H * v).head<6>();
      INFO("momentum from the pass " << h_pass.transpose() << "\nmomentum() " << h_ref.transpose());
      const double hs = std::max(1.0, h_ref.cwiseAbs().maxCoeff());
      CHECK((h_pass - h_ref).cwiseAbs().maxCoeff() < 1e-12 * hs);
      CHECK((h_pass - h_H).cwiseAbs().maxCoeff() < 1e-12 * hs);
    }
  }
  // no velocity, no force, no gravity: at rest, exactly
  const Model c = chain(3, 67, true);
  Data dc(c);
  const Config qc = random_config(c, rng);
  VectorXd a;
  aba(c, dc, qc.base, qc.theta, VectorXd::Zero(c.nv()), VectorXd::Zero(c.nv()), a);
  CHECK(a.cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("the model's subtree numbering equals the ancestry of every body", "[dynamics][fast]") {
  std::vector<Named> models = models_under_test();
  models.push_back({"mimic chain", mimic_chain(3)});
  for (const Named& nm : models) {
    const Model& m = nm.model;
    INFO(nm.name);
    // the reference: the subtree of i is every body that i supports (walking each body's parents)
    bool contiguous = m.nb() - 1 == m.n();
    for (int i = 0; i < m.nb(); ++i) {
      int last = i;
      for (int j = i; j < m.nb(); ++j)
        if (supports(m, i, j)) last = j;
      CHECK(m.subtree_last(i) == last);
      for (int j = i; j <= last; ++j) contiguous = contiguous && supports(m, i, j);
    }
    CHECK(m.depth_first() == contiguous);
  }
  // the URDF loader and the builder's chains number depth-first; an interleaved tree and a mimic do not
  CHECK(models[0].model.depth_first());
  CHECK(models[2].model.depth_first());
  CHECK(models[models.size() - 3].model.depth_first());
  CHECK_FALSE(models[models.size() - 2].model.depth_first());
  CHECK_FALSE(models.back().model.depth_first());
}

/// A chain of three joints whose second joint origin is `length` metres from the first.
Model long_chain(double length) {
  ModelBuilder b("base", Inertia{100, Vector3::Zero(), Matrix3::Identity()});
  const Inertia link{2, Vector3(0.1, 0, 0), 0.1 * Matrix3::Identity()};
  b.add_joint("j1", JointType::Revolute, "base", Pose{}, Vector3::UnitZ(), "l1", link);
  b.add_joint("j2", JointType::Revolute, "l1", Pose{Vector3(length, 0, 0)}, Vector3::UnitY(), "l2", link);
  b.add_joint("j3", JointType::Revolute, "l2", Pose{Vector3(0, 0.5, 0)}, Vector3(1, 1, 0), "l3", link);
  return b.build();
}

TEST_CASE("crba: a finite H of huge lengths is returned, an H that overflows is refused",
          "[dynamics][fast]") {
  const Eigen::VectorXd theta = Eigen::Vector3d(0.3, -0.4, 0.5);
  BasePose base;
  base.orientation = Quaternion(Eigen::AngleAxisd(0.2, Vector3(1, 2, 3).normalized()));
  // 1e100 m: H's entries reach 1e200 (m l^2), finite
  {
    const Model m = long_chain(1e100);
    Data d(m);
    REQUIRE_NOTHROW(crba(m, d, base, theta));
    CHECK(d.H.allFinite());
    CHECK(d.H.cwiseAbs().maxCoeff() > 1e199);
  }
  // 1e120 m: F_i stays finite (1e240) but S_j . F_i does not (1e360); 1e200 m: F_i overflows already
  for (double length : {1e120, 1e200}) {
    INFO(length);
    const Model m = long_chain(length);
    Data d(m);
    CHECK_THROWS_AS(crba(m, d, base, theta), NumericalError);
    CHECK_THROWS_WITH(crba(m, d, base, theta), Catch::Contains("inertia matrix H is not finite"));
  }
  // a configuration that is not finite names its first bad entry
  const Model m = long_chain(1.0);
  Data d(m);
  Eigen::VectorXd bad = theta;
  bad(1) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(crba(m, d, base, bad), Catch::Contains("theta must be finite, entry 1 is inf"));
  bad(1) = 0.0;
  bad(2) = std::nan("");
  CHECK_THROWS_WITH(crba(m, d, base, bad), Catch::Contains("theta must be finite, entry 2 is nan"));
}

TEST_CASE("aba refuses mimic joints and bad sizes, naming them", "[dynamics][fast]") {
  const Model m = mimic_chain(3);
  Data d(m);
  Rng rng(71);
  const Config q = random_config(m, rng);
  VectorXd a;
  CHECK_THROWS_WITH(aba(m, d, q.base, q.theta, VectorXd::Zero(m.nv()), VectorXd::Zero(m.nv()), a),
                    Catch::Contains("aba: the model has mimic joints; use forward_dynamics"));
  const Model c = chain(3, 1, true);
  Data dc(c);
  const Config qc = random_config(c, rng);
  CHECK_THROWS_WITH(aba(c, dc, qc.base, qc.theta, VectorXd::Zero(c.nv() - 1), VectorXd::Zero(c.nv()), a),
                    Catch::Contains("aba: v has"));
  VectorXd bad = VectorXd::Zero(c.nv());
  bad(2) = std::nan("");
  CHECK_THROWS_WITH(aba(c, dc, qc.base, qc.theta, VectorXd::Zero(c.nv()), bad, a), Catch::Contains("tau"));
  CHECK_THROWS_WITH(aba(c, dc, qc.base, VectorXd::Zero(2), VectorXd::Zero(c.nv()), VectorXd::Zero(c.nv()), a),
                    Catch::Contains("theta"));
}

TEST_CASE("the O(n) paths refuse what they cannot do and fall back for mimic joints", "[dynamics][fast]") {
  const Model m = mimic_chain(3);
  Data d(m), e(m);
  Rng rng(53);
  const Config q = random_config(m, rng);
  const Vector3 u = rng.unit();
  forward_kinematics(m, d, q.base, q.theta);
  CHECK_THROWS_WITH(inverse_effective_mass_articulated(m, d, m.end_effector(), u),
                    Catch::Contains("mimic joints; use inverse_effective_mass"));
  // integrated_effective_mass and its O(n) gradient take the dense route: the same numbers
  for (const ContactJoints& joints : joint_models(m)) {
    crba(m, e, q.base, q.theta);
    const double M = 1.0 / (inverse_effective_mass(m, e, m.end_effector(), u, joints) + 0.01);
    CHECK(integrated_effective_mass(m, d, q.base, q.theta, m.end_effector(), u, 0.01, joints) == M);
    CHECK(integrated_effective_mass_dense(m, e, q.base, q.theta, m.end_effector(), u, 0.01, joints) == M);
    VectorXd g(m.n()), g_dense(m.n());
    CHECK(integrated_effective_mass_gradient(m, d, q.base, q.theta, m.end_effector(), u, 0.01, joints, g) ==
          integrated_effective_mass_gradient_dense(m, e, q.base, q.theta, m.end_effector(), u, 0.01, joints,
                                                   g_dense));
    CHECK(g == g_dense);
  }
  // bad input names the argument
  const Model c = chain(3, 1, true);
  Data dc(c);
  const Config qc = random_config(c, rng);
  VectorXd g(c.n());
  const ContactJoints bad{JointModel::Armature, VectorXd::Zero(2)};
  CHECK_THROWS_WITH(
      integrated_effective_mass(c, dc, qc.base, qc.theta, c.end_effector(), u, 0.0, bad),
      Catch::Contains("armature"));
  CHECK_THROWS_WITH(integrated_effective_mass(c, dc, qc.base, qc.theta, c.end_effector(), Vector3(1, 1, 0),
                                              0.0, ContactJoints{}),
                    Catch::Contains("unit vector"));
  CHECK_THROWS_WITH(integrated_effective_mass(c, dc, qc.base, qc.theta, c.end_effector(), u, -1.0),
                    Catch::Contains("inverse mass"));
  VectorXd short_grad(2);
  CHECK_THROWS_WITH(integrated_effective_mass_gradient(c, dc, qc.base, qc.theta, c.end_effector(), u, 0.0,
                                                       ContactJoints{}, short_grad),
                    Catch::Contains("grad"));
  CHECK_THROWS_AS(integrated_effective_mass(c, dc, qc.base, qc.theta, 99, u, 0.0, ContactJoints{}),
                  InputError);
}

}  // namespace test_fast_dynamics
