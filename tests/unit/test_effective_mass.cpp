// tests/unit/test_effective_mass.cpp -- the effective mass m_e (Eq. 4) and the integrated effective
// mass M_ie (Eq. 14): independent of the base-velocity coordinates, invariant under a move of the whole
// system, the articulated-body recursion (articulated_effective_mass.hpp) equal to the dense Cholesky
// path, its 6x6 quadratic forms against Eigen's solves, the inverse inertia at a point and its
// gradient, the O(n) M_ie and its gradient against the dense paths under every joint model.
#include "support/dynamics_helpers.hpp"

#include "ffsr/algorithm/articulated_effective_mass.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace test_effective_mass {

using namespace ffsr;
using namespace ffsr_test;

namespace {

/// The three contact-joint models, the armature one with a different value per joint.
std::vector<ContactJoints> joint_models(const Model& m) {
  Eigen::VectorXd a(m.n());
  for (int k = 0; k < m.n(); ++k) a(k) = 0.05 + 0.1 * k;
  return {{JointModel::Free, Eigen::VectorXd::Zero(m.n())}, {JointModel::Locked, Eigen::VectorXd::Zero(m.n())},
          {JointModel::Armature, a}};
}

/// The k-th random SPD 6x6 matrix B B^T + shift I (shift 1e-3 for odd k: poorly conditioned), scaled by
/// `heavy` for every third k, and a random vector.
std::pair<Matrix6, Vector6> random_spd6(std::mt19937& gen, int k, double heavy) {
  std::normal_distribution<double> N(0.0, 1.0);
  Matrix6 B;
  for (int e = 0; e < 36; ++e) B.data()[e] = N(gen);
  const double shift = k % 2 ? 1e-3 : 1.0;
  const double scale = k % 3 ? 1.0 : heavy;
  Vector6 x;
  for (int e = 0; e < 6; ++e) x(e) = N(gen);
  return {scale * (B * B.transpose() + shift * Matrix6::Identity()), x};
}

}  // namespace

TEST_CASE("effective mass does not depend on the base-velocity coordinates", "[dynamics]") {
  for_each_config(18, 2, [&](const TestRobot& r, Data& d, Rng& rng, const Config& q, int k) {
    const Vector3 u = rng.unit();
    const double me = effective_mass(r.model, d, q.base, q.theta, r.ee, u);
    const MatrixXd H = d.H;
    INFO(r.name << " config " << k);
    // m_e = 1 / (u^T J_v H^-1 J_v^T u) with H and J_v of another chart, both from FD of forward
    // kinematics (the kinetic-energy body sum), never from the library's H or J.
    auto me_in = [&](const Chart& chart, MatrixXd* Hc) {
      const MatrixXd Hx = fd_inertia_matrix(r, q, chart);
      const MatrixXd Jv = fd_frame_jacobian(r, q, r.ee, chart).topRows(3);
      if (Hc) *Hc = Hx;
      const Eigen::VectorXd w = Jv.transpose() * u;
      return 1.0 / w.dot(Hx.ldlt().solve(w));
    };
    MatrixXd H_body, H_com;
    const Chart body_chart = advance_base_body_frame;
    const Chart com_chart = advance_com_chart(r);
    // FD errors O(h^2) propagate through the solve: 1e-7 relative
    CHECK(me_in(library_chart, nullptr) == Approx(me).epsilon(1e-7));
    CHECK(me_in(body_chart, &H_body) == Approx(me).epsilon(1e-7));
    CHECK(me_in(com_chart, &H_com) == Approx(me).epsilon(1e-7));
    // the charts are genuinely different coordinates: their inertia matrices differ from H ...
    CHECK(rel_err(H_body, H) > 1e-3);
    CHECK(rel_err(H_com, H) > 1e-3);
    // ... and they are what theory says. Body frame: H' = T^T H T with v = T v',
    // T = diag(R0, R0, 1). Centre-of-mass velocity: linear momentum M v_g decouples,
    // H'_gg = M E and H'_g* = 0 (closed form).
    const Matrix3 R0 = q.base.orientation.normalized().toRotationMatrix();
    MatrixXd T = MatrixXd::Identity(r.model.nv(), r.model.nv());
    T.block<3, 3>(0, 0) = R0;
    T.block<3, 3>(3, 3) = R0;
    CHECK(rel_err(H_body, MatrixXd(T.transpose() * H * T)) < 1e-8);
    CHECK(rel_err(MatrixXd(H_com.topLeftCorner(3, 3)),
                  MatrixXd(r.model.total_mass() * Matrix3::Identity())) < 1e-8);
    CHECK(H_com.block(0, 3, 3, r.model.nv() - 3).cwiseAbs().maxCoeff() < 1e-8 * H.cwiseAbs().maxCoeff());
  });
}

TEST_CASE("effective mass invariances", "[dynamics]") {
  Rng rng(20);
  for (const auto& r : robots_under_test()) {
    Data d(r.model);
    for (int k = 0; k < 3; ++k) {
      Config q = random_config(r.model, rng);
      Target t;
      t.mass = 150;
      t.inertia = rng.inertia(60);
      t.attitude = rng.quaternion();
      t.contact_offset = rng.vec3(0.4);
      t.normal = rng.unit();
      t.validate();
      INFO(r.name << " config " << k);
      const double M = integrated_effective_mass(r.model, d, q.base, q.theta, r.ee, t);
      const MatrixXd H = crba(r.model, d, q.base, q.theta);
      // Eq. 14 with the target terms in the inertial frame (u = R_t u_n, r = R_t r_tp,
      // I = R_t I_t R_t^T), written out here: rounding only, 1e-12
      const Matrix3 Rt = t.attitude.toRotationMatrix();
      const Vector3 u = Rt * t.normal, rr = Rt * t.contact_offset;
      const Matrix3 Iw = Rt * t.inertia * Rt.transpose();
      const double me = effective_mass(r.model, d, q.base, q.theta, r.ee, u);
      const double inv = 1 / me + 1 / t.mass - u.dot(skew(rr) * Iw.inverse() * skew(rr) * u);
      CHECK(M == Approx(1 / inv).epsilon(1e-12));
      // base position: H is about the base origin, so translating everything leaves H and M_ie
      // unchanged (rounding grows with the 10 m shift: 1e-12 relative)
      Config moved = q;
      moved.base.position += Vector3(10.0, -7.0, 4.0);
      CHECK(integrated_effective_mass(r.model, d, moved.base, moved.theta, r.ee, t) ==
            Approx(M).epsilon(1e-12));
      CHECK(rel_err(MatrixXd(crba(r.model, d, moved.base, moved.theta)), H) < 1e-12);
      // turning the base and the target by the same rotation leaves M_ie unchanged
      const Quaternion Q = rng.quaternion();
      Config turned = q;
      turned.base.orientation = Q * q.base.orientation;
      Target tt = t;
      tt.attitude = Q * t.attitude;
      CHECK(integrated_effective_mass(r.model, d, turned.base, turned.theta, r.ee, tt) ==
            Approx(M).epsilon(1e-10));
      // ... while turning only the base changes it (the check above is not vacuous), by > 1e-6
      CHECK(std::abs(integrated_effective_mass(r.model, d, turned.base, turned.theta, r.ee, t) - M) >
            1e-6 * M);
    }
  }
}

TEST_CASE("inverse effective mass: the articulated-body recursion equals the dense Cholesky path",
          "[dynamics]") {
  // two independent computations of u^T J_v H^-1 J_v^T u: crba + Cholesky, and the O(n) recursion
  // over articulated inertias that never forms H; they agree to rounding (1e-10 relative)
  Rng rng(31);
  std::vector<std::pair<std::string, Model>> models;
  for (const auto& r : robots_under_test()) models.emplace_back(r.name, r.model);
  models.emplace_back("chain 14", random_chain(14, 14));
  models.emplace_back("chain 28", random_chain(28, 28));
  for (const auto& [name, model] : models) {
    Data d(model), e(model);
    for (int k = 0; k < 5; ++k) {
      const Config q = random_config(model, rng);
      const Vector3 u = rng.unit();
      for (int frame : {model.end_effector(), static_cast<int>(model.frames().size()) / 2, 0}) {
        INFO(name << " config " << k << " frame " << model.frame(frame).name);
        crba(model, d, q.base, q.theta);
        const double dense = inverse_effective_mass(model, d, frame, u);
        forward_kinematics(model, e, q.base, q.theta);
        const double articulated = inverse_effective_mass_articulated(model, e, frame, u);
        CHECK(std::abs(articulated - dense) < 1e-10 * dense);
      }
      Target t;
      t.attitude = rng.quaternion();
      const double M = integrated_effective_mass_dense(model, d, q.base, q.theta, model.end_effector(), t);
      const double fast = integrated_effective_mass(model, e, q.base, q.theta, model.end_effector(),
                                                    t.normal_world(), t.inverse_mass_along_normal());
      CHECK(std::abs(fast - M) < 1e-10 * M);
    }
  }
}

TEST_CASE("inverse effective mass: the composite route equals the dense Cholesky path", "[dynamics][fast]") {
  // the Schur complement of the floating base over the composite inertias (inverse_form_composite,
  // the route of integrated_effective_mass up to kCompositeMaxJoints joints) against crba + Cholesky,
  // free and with armature, at frames on and off the path of every body
  Rng rng(37);
  std::vector<NamedModel> models = models_of_every_kind();
  for (int n = 1; n <= kCompositeMaxJoints + 2; ++n)
    models.push_back({"chain", random_chain(n, 100u + unsigned(n))});
  int checked = 0;
  for (const auto& [name, model] : models) {
    if (!model.depth_first()) continue;  // the route needs contiguous subtrees (mimics: the dense route)
    Data d(model), e(model);
    for (const ContactJoints& joints : joint_models(model)) {
      if (joints.model == JointModel::Locked) continue;
      const Eigen::VectorXd* a = joints.model == JointModel::Armature ? &joints.armature : nullptr;
      for (int k = 0; k < 3; ++k) {
        const Config q = random_config(model, rng);
        const Vector3 u = rng.unit();
        for (int frame = 0; frame < static_cast<int>(model.frames().size()); ++frame) {
          INFO(name << " n " << model.n() << " config " << k << " frame " << model.frame(frame).name << " "
                    << joint_model_name(joints.model));
          crba(model, d, q.base, q.theta);
          const double dense = inverse_effective_mass(model, d, frame, u, joints);
          forward_kinematics(model, e, q.base, q.theta);
          const Vector6 f = detail::unit_point_force(model, e, frame, u);
          double composite = -1.0;
          REQUIRE(detail::inverse_form_composite(model, e, model.frame(frame).body, f, a, composite));
          CHECK(std::abs(composite - dense) <= 1e-12 * dense);
          // it leaves the composite inertias as crba does
          CHECK((e.Ic[0].matrix() - d.Ic[0].matrix()).cwiseAbs().maxCoeff() == 0.0);
          ++checked;
        }
      }
    }
  }
  CHECK(checked > 100);
}

TEST_CASE("inverse_quadratic_spd6: x^T A^-1 x against Eigen's LLT solve, refuses indefinite matrices",
          "[dynamics]") {
  std::mt19937 gen(17);
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    const auto [A, x] = random_spd6(gen, k, 1.0);
    const double ref = x.dot(A.llt().solve(x));
    double q = 0;
    REQUIRE(ffsr::detail::inverse_quadratic_spd6(A, x, q));
    worst = std::max(worst, std::abs(q - ref) / ref);
  }
  INFO("worst relative difference " << worst);
  CHECK(worst < 1e-10);
  Matrix6 A = Matrix6::Identity();
  A(4, 4) = -1;  // indefinite
  double q = 0;
  CHECK_FALSE(ffsr::detail::inverse_quadratic_spd6(A, Vector6::Ones(), q));
  A(4, 4) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(ffsr::detail::inverse_quadratic_spd6(A, Vector6::Ones(), q));
  CHECK_FALSE(ffsr::detail::inverse_quadratic_spd6(Matrix6::Zero(), Vector6::Ones(), q));
}

TEST_CASE("inverse_quadratic_articulated: the base's x^T A^-1 x by adjugates against Eigen's LLT solve",
          "[dynamics]") {
  std::mt19937 gen(23);
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    const auto [A, x] = random_spd6(gen, k, 1e3);  // a third with a heavy body's scale
    ffsr::ArticulatedInertia IA;
    IA.ll = A.topLeftCorner<3, 3>();
    IA.la = A.topRightCorner<3, 3>();
    IA.aa = A.bottomRightCorner<3, 3>();
    const double ref = x.dot(A.llt().solve(x));
    double q = 0;
    REQUIRE(ffsr::detail::inverse_quadratic_articulated(IA, x, q));
    worst = std::max(worst, std::abs(q - ref) / ref);
  }
  INFO("worst relative difference " << worst);
  CHECK(worst < 1e-10);
  ffsr::ArticulatedInertia IA;
  const Matrix3 I_com = Vector3(1, 2, 3).asDiagonal();
  IA.set(ffsr::SpatialInertia::from_com(2.0, Vector3(0.1, -0.2, 0.3), I_com));
  double q = 0;
  REQUIRE(ffsr::detail::inverse_quadratic_articulated(IA, Vector6::Ones(), q));
  CHECK(std::abs(q - Vector6::Ones().dot(IA.matrix().llt().solve(Vector6::Ones()))) < 1e-12 * q);
  IA.aa(1, 1) = -1;  // indefinite
  CHECK_FALSE(ffsr::detail::inverse_quadratic_articulated(IA, Vector6::Ones(), q));
  IA.aa(1, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(ffsr::detail::inverse_quadratic_articulated(IA, Vector6::Ones(), q));
  IA.set(ffsr::SpatialInertia::from_com(1e120, Vector3(0.1, -0.2, 0.3), 1e120 * Matrix3::Identity()));
  // |P| |S'| overflows: the LDL^T decides
  REQUIRE(ffsr::detail::inverse_quadratic_articulated(IA, Vector6::Ones(), q));
  CHECK(std::abs(q - Vector6::Ones().dot(IA.matrix().llt().solve(Vector6::Ones()))) < 1e-12 * q);
  CHECK_FALSE(ffsr::detail::inverse_quadratic_articulated(ffsr::ArticulatedInertia(), Vector6::Ones(), q));
}

TEST_CASE(
    "inverse inertia at a point: a force at p_e + rho is the effective mass of a frame there -- form "
    "gradient against central differences",
    "[dynamics]") {
  // Lambda^-1 = J H^-1 J^T at the end-effector's body origin. Three independent checks: its linear
  // block and the whole matrix from finite differences of forward kinematics; s^T Lambda^-1 s with
  // s = [u; rho x u] equals the effective mass of the end-effector frame, a different point of the
  // same body (rho = p_ee - p_body from forward kinematics); and the analytic gradient of a form
  // s^T Lambda^-1 s (any 6-vector s) equals central differences.
  for_each_config(47, 3, [&](const TestRobot& r, Data& d, Rng& rng, const Config& q, int k) {
    const int body = r.model.frame(r.ee).body;
    const int origin = r.model.frame_index(r.model.body(body).name);
    REQUIRE(r.model.frame(origin).body == body);
    INFO(r.name << " config " << k);
    crba(r.model, d, q.base, q.theta);
    const Matrix6 L = inverse_inertia_matrix(r.model, d, origin);
    CHECK((L - L.transpose()).cwiseAbs().maxCoeff() == 0.0);
    CHECK(Eigen::SelfAdjointEigenSolver<Matrix6>(L).eigenvalues().minCoeff() > -1e-12 * L.norm());
    const MatrixXd H = fd_inertia_matrix(r, q, library_chart);
    const MatrixXd J = fd_frame_jacobian(r, q, origin, library_chart);
    const MatrixXd Lfd = J * H.ldlt().solve(J.transpose());
    CHECK(rel_err(MatrixXd(L), Lfd) < 1e-6);

    forward_kinematics(r.model, d, q.base, q.theta);
    const Vector3 rho = frame_pose(r.model, d, r.ee).p - frame_pose(r.model, d, origin).p;
    CHECK(rho.norm() > 0.05);  // a genuinely different point
    crba(r.model, d, q.base, q.theta);
    for (int j = 0; j < 3; ++j) {
      const Vector3 u = rng.unit();
      Vector6 s;
      s << u, rho.cross(u);
      const double at_point = s.dot(L * s);
      CHECK(std::abs(at_point - inverse_effective_mass(r.model, d, r.ee, u)) < 1e-10 * at_point);
    }

    Vector6 s;
    s << rng.vec3(1.0), rng.vec3(0.5);  // not a force at a point in general (s_f . s_m != 0)
    VectorXd g(r.model.n());
    crba(r.model, d, q.base, q.theta);
    const double qs = inverse_inertia_form_gradient(r.model, d, origin, s, g);
    CHECK(qs == Approx(s.dot(L * s)).epsilon(1e-12));
    for (int c = 0; c < r.model.n(); ++c) {
      const double h = 1e-6;
      VectorXd tp = q.theta, tm = q.theta;
      tp(c) += h;
      tm(c) -= h;
      crba(r.model, d, q.base, tp);
      const double fp = s.dot(inverse_inertia_matrix(r.model, d, origin) * s);
      crba(r.model, d, q.base, tm);
      const double fm = s.dot(inverse_inertia_matrix(r.model, d, origin) * s);
      INFO("coordinate " << c);
      CHECK(g(c) == Approx((fp - fm) / (2 * h)).epsilon(1e-6).margin(1e-8 * qs));
    }
  });
}

TEST_CASE("the O(n) integrated effective mass equals the dense path under every joint model",
          "[dynamics][fast]") {
  Rng rng(43);
  for (const auto& [name, model] : models_of_every_kind()) {
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
  for (const auto& [name, model] : models_of_every_kind()) {
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
  const Model c = serial_chain(3, 1, true);
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

}  // namespace test_effective_mass
