// tests/test_dynamics.cpp -- identities of the floating-base dynamics, and the paper's tables.
//
// Robots: the paper's 3-DOF and 7-DOF robots (robots/*.urdf) and a random branched tree built in
// code (mixed revolute/prismatic joints, random axes, full inertias, a fixed child with mass, a joint
// hung on that fixed frame, bodies added out of depth-first order). Every configuration uses a random
// base position and a non-identity base attitude.
//
// Independent references (tests/support/dynamics_helpers.hpp): body velocities, momentum, kinetic
// energy, the inertia matrix and frame Jacobians come from central finite differences of forward
// kinematics (h = 1e-5, truncation error O(h^2) ~ 1e-10 relative, rounding ~ 1e-11), never from the
// library's velocity code. Tolerances below are stated next to each check.
#include "support/dynamics_helpers.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <utility>

namespace test_dynamics {

using namespace ffsr;
using namespace ffsr_test;

namespace {

/// The random branched tree: 9 moving joints on three branches (a, b, c; c hangs on a1), two
/// prismatic joints, random non-unit axes, random full inertias and centre-of-mass offsets, a fixed
/// child "tool" with mass on a3 and a joint "a4" hung on the fixed frame "tool", a massless fixed
/// frame "tip" on a4 as the end-effector. Bodies are added interleaved (not depth-first).
TestRobot random_tree(unsigned seed) {
  Rng rng(seed);
  auto inertia = [&](double m) { return Inertia{m, rng.vec3(0.3), rng.inertia(0.05 * m)}; };
  auto pose = [&] { return Pose::from_xyz_rpy(rng.vec3(0.6), rng.vec3(M_PI)); };
  auto axis = [&] { return Vector3(rng.unit() * rng.uniform(0.5, 2.0)); };  // normalized by the builder

  const Inertia trunk = inertia(300);
  ModelBuilder b("trunk", trunk);
  TestRobot r;
  r.name = "random tree";
  r.links.push_back({"trunk", trunk});
  auto add = [&](const char* joint, JointType type, const char* parent, const char* child, double m) {
    const Inertia in = inertia(m);
    b.add_joint(joint, type, parent, pose(), axis(), child, in);
    r.links.push_back({child, in});
  };
  add("ja1", JointType::Revolute, "trunk", "a1", 12);
  add("jb1", JointType::Revolute, "trunk", "b1", 9);
  add("ja2", JointType::Prismatic, "a1", "a2", 7);
  add("jc1", JointType::Revolute, "a1", "c1", 5);
  add("jb2", JointType::Revolute, "b1", "b2", 8);
  add("ja3", JointType::Revolute, "a2", "a3", 6);
  const Inertia tool = inertia(2.5);
  b.add_fixed("tool_mount", "a3", pose(), "tool", tool);
  r.links.push_back({"tool", tool});
  add("ja4", JointType::Revolute, "tool", "a4", 3);
  add("jc2", JointType::Prismatic, "c1", "c2", 4);
  add("jb3", JointType::Revolute, "b2", "b3", 4.5);
  b.add_fixed("tip_mount", "a4", pose(), "tip", Inertia{});
  b.set_end_effector("tip");
  r.model = b.build();
  r.ee = r.model.end_effector();
  return r;
}

std::vector<TestRobot> robots_under_test() {
  return {paper_robot("paper_3dof.urdf"), paper_robot("paper_7dof.urdf"), random_tree(7)};
}


/// The common loop of the identity checks: for every robot under test, `samples` random
/// configurations drawn from one generator seeded with `seed`, each handed to
/// body(robot, its Data, the generator, configuration, sample index); the body draws whatever else
/// it needs from the same generator, so the sequence is fixed by the seed.
template <class Body>
void for_each_config(unsigned seed, int samples, Body body) {
  Rng rng(seed);
  for (const auto& r : robots_under_test()) {
    Data d(r.model);
    for (int k = 0; k < samples; ++k) {
      const Config q = random_config(r.model, rng);
      body(r, d, rng, q, k);
    }
  }
}

VectorXd random_velocity(const Model& m, Rng& rng) {
  VectorXd v(m.nv());
  v << rng.vec3(0.4), rng.vec3(0.3), rng.vec(m.n(), 1.0);
  return v;
}

const Chart library_chart = advance_library;

}  // namespace

// -------------------------------------------------------------------------------------------------
TEST_CASE("random tree: the builder made the intended tree", "[dynamics]") {
  const TestRobot r = random_tree(7);
  CHECK(r.model.n() == 9);
  CHECK(r.model.joint_names() ==
        std::vector<std::string>{"ja1", "jb1", "ja2", "jc1", "jb2", "ja3", "ja4", "jc2", "jb3"});
  // total mass: the sum of the masses given to the builder (exact up to rounding, 1e-12 relative)
  double m = 0;
  for (const auto& l : r.links) m += l.inertia.mass;
  CHECK(r.model.total_mass() == Approx(m).epsilon(1e-12));
  CHECK(r.model.frame(r.ee).name == "tip");
  CHECK(r.model.frame(r.model.frame_index("tool")).body == 6);  // merged into a3 (body 6)
}

TEST_CASE("H is symmetric positive definite", "[dynamics]") {
  for_each_config(11, 5, [&](const TestRobot& r, Data& d, Rng& /*rng*/, const Config& q, int k) {
    const MatrixXd H = crba(r.model, d, q.base, q.theta);
    INFO(r.name << " config " << k);
    // symmetry: 1e-13 relative to the largest entry (CRBA writes both triangles from one value;
    // only the rotated link inertias R I R^T may round differently)
    CHECK((H - H.transpose()).cwiseAbs().maxCoeff() <= 1e-13 * H.cwiseAbs().maxCoeff());
    Eigen::SelfAdjointEigenSolver<MatrixXd> es(H);
    // positive definite: every moving body has mass, so the smallest eigenvalue must be clearly
    // above the rounding level, 1e-12 of the largest (the light 7-DOF wrist brings it down to
    // ~1e-5 of the largest in some configurations: physical, not a defect)
    CHECK(es.eigenvalues().minCoeff() > 1e-12 * es.eigenvalues().maxCoeff());
    CHECK(H.llt().info() == Eigen::Success);
  });
}

TEST_CASE("H columns equal RNEA with unit accelerations", "[dynamics]") {
  Rng rng(12);
  for (const auto& r : robots_under_test()) {
    Model with_g = r.model;
    with_g.gravity = Vector3(0.3, -9.81, 1.7);
    Data d(r.model), dg(with_g);
    for (int k = 0; k < 3; ++k) {
      const Config q = random_config(r.model, rng);
      const MatrixXd H = crba(r.model, d, q.base, q.theta);
      const VectorXd zero = VectorXd::Zero(r.model.nv());
      const VectorXd g_bias = rnea(with_g, dg, q.base, q.theta, zero, zero);
      for (int i = 0; i < r.model.nv(); ++i) {
        INFO(r.name << " config " << k << " column " << i);
        const VectorXd e = VectorXd::Unit(r.model.nv(), i);
        // RNEA is computed in body coordinates without composites: an independent route.
        // 1e-12 relative to max(1, |H col|): rounding only.
        CHECK(rel_err(VectorXd(rnea(r.model, d, q.base, q.theta, zero, e)), VectorXd(H.col(i))) < 1e-12);
        CHECK(rel_err(VectorXd(rnea(with_g, dg, q.base, q.theta, zero, e) - g_bias), VectorXd(H.col(i))) <
              1e-12);
      }
      // without velocity the gravity bias is the weight: force M g on the base, moment about the
      // base origin (c - p0) x M g (closed form, statics of the whole system)
      ffsr::Data dk(r.model);
      const auto s = link_states(r, dk, q);
      const Vector3 c = system_com(r, s);
      Vector6 weight;
      weight << -r.model.total_mass() * with_g.gravity,
          -(c - q.base.position).cross(r.model.total_mass() * with_g.gravity);
      CHECK(rel_err(Vector6(g_bias.head<6>()), weight) < 1e-12);
    }
  }
}

TEST_CASE("RNEA is H a + C, and bias_forces is RNEA at zero acceleration", "[dynamics]") {
  for_each_config(13, 3, [&](const TestRobot& r, Data& d, Rng& rng, const Config& q, int k) {
    const VectorXd v = random_velocity(r.model, rng), a = rng.vec(r.model.nv(), 2.0);
    const MatrixXd H = crba(r.model, d, q.base, q.theta);
    const VectorXd C = bias_forces(r.model, d, q.base, q.theta, v);
    const VectorXd C0 = rnea(r.model, d, q.base, q.theta, v, VectorXd::Zero(r.model.nv()));
    const VectorXd tau = rnea(r.model, d, q.base, q.theta, v, a);
    INFO(r.name << " config " << k);
    CHECK(rel_err(C, C0) == 0.0);                      // the same computation
    CHECK(rel_err(tau, VectorXd(H * a + C)) < 1e-11);  // Eq. 1, rounding only
  });
}

TEST_CASE("kinetic energy and H from finite differences of forward kinematics", "[dynamics]") {
  for_each_config(14, 3, [&](const TestRobot& r, Data& d, Rng& rng, const Config& q, int k) {
    const VectorXd v = random_velocity(r.model, rng);
    const MatrixXd H = crba(r.model, d, q.base, q.theta);
    const double T_fd = fd_kinetic_energy(r, fd_link_velocities(r, q, v, library_chart));
    INFO(r.name << " config " << k);
    // FD truncation O(h^2) with h = 1e-5: 1e-8 relative
    CHECK(0.5 * v.dot(H * v) == Approx(T_fd).epsilon(1e-8));
    CHECK(kinetic_energy(r.model, d, v) == Approx(T_fd).epsilon(1e-8));
    // the whole matrix: sum over bodies of m Jv^T Jv + Jw^T I Jw with FD Jacobians
    CHECK(rel_err(H, fd_inertia_matrix(r, q, library_chart)) < 1e-8);
  });
}

TEST_CASE("first six rows of H v are the total momentum", "[dynamics]") {
  for_each_config(15, 3, [&](const TestRobot& r, Data& d, Rng& rng, const Config& q, int k) {
    const VectorXd v = random_velocity(r.model, rng);
    const MatrixXd H = crba(r.model, d, q.base, q.theta);
    const Vector6 Hv = (H * v).head<6>();
    const Vector6 h_fd = fd_momentum(r, fd_link_velocities(r, q, v, library_chart), q.base.position);
    INFO(r.name << " config " << k);
    CHECK(rel_err(momentum(r.model, d, v), Hv) < 1e-12);  // two library routes: rounding only
    CHECK(rel_err(Hv, h_fd) < 1e-8);                      // FD body sum, truncation O(h^2)
  });
}

TEST_CASE("frame_jacobian against finite differences of forward kinematics", "[dynamics]") {
  for_each_config(16, 3, [&](const TestRobot& r, Data& d, Rng& /*rng*/, const Config& q, int k) {
    std::vector<int> frames{r.ee, 0};
    if (r.name == "random tree")
      frames = {r.ee, r.model.frame_index("tool"), r.model.frame_index("c2"), r.model.frame_index("b3"), 0};
    forward_kinematics(r.model, d, q.base, q.theta);
    for (int f : frames) {
      const MatrixXd J = frame_jacobian(r.model, d, f);
      INFO(r.name << " config " << k << " frame " << r.model.frame(f).name);
      CHECK(rel_err(J, fd_frame_jacobian(r, q, f, library_chart)) < 1e-8);  // FD, O(h^2)
    }
  });
}

TEST_CASE("J_f is the end-effector velocity under zero momentum", "[dynamics]") {
  for_each_config(17, 3, [&](const TestRobot& r, Data& d, Rng& rng, const Config& q, int k) {
    const VectorXd theta_dot = rng.vec(r.model.n(), 1.0);
    const MatrixXd Jf = generalized_jacobian(r.model, d, q.base, q.theta, r.ee);
    const MatrixXd J = d.J;
    const Vector6 xb = base_velocity_from_momentum(r.model, d, theta_dot);
    VectorXd v(r.model.nv());
    v << xb, theta_dot;
    INFO(r.name << " config " << k);
    const Vector6 xe = Jf * theta_dot;
    CHECK(rel_err(Vector6(J * v), xe) < 1e-12);  // Eq. 29 algebra, rounding only
    // independent: the end-effector velocity by FD of forward kinematics along v, O(h^2)
    CHECK(rel_err(Vector6(fd_frame_jacobian(r, q, r.ee, library_chart) * v), xe) < 1e-8);
    // the motion carries no momentum (FD body sum): compare with the momentum the joint motion
    // alone would carry on a clamped base, 1e-8 of it
    VectorXd v_clamped = VectorXd::Zero(r.model.nv());
    v_clamped.tail(r.model.n()) = theta_dot;
    const double scale =
        fd_momentum(r, fd_link_velocities(r, q, v_clamped, library_chart), q.base.position).norm();
    CHECK(fd_momentum(r, fd_link_velocities(r, q, v, library_chart), q.base.position).norm() <
          1e-8 * scale);
    CHECK(momentum(r.model, d, v).norm() < 1e-12 * scale);
    // and with a given momentum the base velocity reproduces it (library momentum, rounding)
    const Vector6 h = Vector6(rng.vec(6, 50.0));
    v.head<6>() = base_velocity_from_momentum(r.model, d, theta_dot, h);
    CHECK(rel_err(momentum(r.model, d, v), h) < 1e-12);
  });
}

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

TEST_CASE("momentum and energy are conserved along a free-floating motion", "[dynamics]") {
  Rng rng(19);
  for (const auto& r : robots_under_test()) {
    const Model& m = r.model;
    const long n = m.n(), nv = m.nv();
    Data d(m);
    // state x = [p0 (3), attitude quaternion (w, x, y, z), theta (n), v (6+n)]; zero torques, no gravity
    auto unpack = [&](const VectorXd& x) {
      Config q;
      q.base.position = x.head<3>();
      q.base.orientation = Quaternion(x(3), x(4), x(5), x(6));
      q.theta = x.segment(7, n);
      return q;
    };
    auto f = [&](const VectorXd& x) {
      const Config q = unpack(x);
      const VectorXd v = x.tail(nv);
      const MatrixXd H = crba(m, d, q.base, q.theta);
      const VectorXd C = rnea(m, d, q.base, q.theta, v, VectorXd::Zero(nv));
      VectorXd dx(x.size());
      dx.head<3>() = v.head<3>();
      const Quaternion qd = Quaternion(0, v(3), v(4), v(5)) * q.base.orientation;  // w0 inertial: left
      dx.segment<4>(3) << 0.5 * qd.w(), 0.5 * qd.x(), 0.5 * qd.y(), 0.5 * qd.z();
      dx.segment(7, n) = v.tail(n);
      dx.tail(nv) = H.llt().solve(-C);
      return dx;
    };
    // momentum about the fixed inertial origin: L_o = L_p0 + p0 x P; and the kinetic energy
    auto invariants = [&](const VectorXd& x, Vector6& h, double& T) {
      const Config q = unpack(x);
      const VectorXd v = x.tail(nv);
      const MatrixXd H = crba(m, d, q.base, q.theta);
      h = momentum(m, d, v);
      h.tail<3>() += q.base.position.cross(h.head<3>());
      T = 0.5 * v.dot(H * v);
    };
    const Config q0 = random_config(m, rng);
    VectorXd x(7 + n + nv);
    x << q0.base.position, q0.base.orientation.w(), q0.base.orientation.x(), q0.base.orientation.y(),
        q0.base.orientation.z(), q0.theta, random_velocity(m, rng);
    Vector6 h0;
    double T0;
    invariants(x, h0, T0);
    const double dt = 1e-3;
    double worst_P = 0, worst_L = 0, worst_T = 0;
    for (int step = 1; step <= 1000; ++step) {  // 1 s, fixed-step RK4
      const VectorXd k1 = f(x), k2 = f(x + 0.5 * dt * k1), k3 = f(x + 0.5 * dt * k2), k4 = f(x + dt * k3);
      x += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      if (step % 50 == 0) {
        Vector6 h;
        double T;
        invariants(x, h, T);
        worst_P = std::max(worst_P, (h.head<3>() - h0.head<3>()).norm() / h0.head<3>().norm());
        worst_L = std::max(worst_L, (h.tail<3>() - h0.tail<3>()).norm() / h0.tail<3>().norm());
        worst_T = std::max(worst_T, std::abs(T - T0) / T0);
      }
    }
    INFO(r.name << ": relative drift P " << worst_P << ", L_o " << worst_L << ", T " << worst_T);
    // RK4 with dt = 1 ms: global error ~ (omega dt)^4 ~ 1e-12; allow 1e-8 relative
    CHECK(worst_P < 1e-8);
    CHECK(worst_L < 1e-8);
    CHECK(worst_T < 1e-8);
    // the motion is not trivial: the joints moved (at least 0.1 rad somewhere)
    CHECK((unpack(x).theta - q0.theta).cwiseAbs().maxCoeff() > 0.1);
  }
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

// ------------------------------------------------------------------------------------------------
// Forward kinematics of the paper robots, closed forms.

// ------------------------------------------------------------------------------------------------
// The paper's tables.


namespace {

/// A serial chain of n revolute joints with random axes, offsets and inertias (the size tests of the
/// articulated-body recursion).
Model random_chain(int n, unsigned seed) {
  Rng rng(seed);
  ModelBuilder b("base", Inertia{400, rng.vec3(0.2), rng.inertia(100)});
  std::string parent = "base";
  for (int i = 0; i < n; ++i) {
    const std::string child = "l" + std::to_string(i + 1);
    b.add_joint("j" + std::to_string(i + 1), JointType::Revolute, parent,
                Pose::from_xyz_rpy(rng.vec3(0.4), rng.vec3(M_PI)), Vector3(rng.unit()), child,
                Inertia{rng.uniform(1, 10), rng.vec3(0.2), rng.inertia(0.5)});
    parent = child;
  }
  b.add_fixed("tip_mount", parent, Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

}  // namespace

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

TEST_CASE("forward kinematics: each body's pose is its parent's times tree times the joint's motion",
          "[dynamics]") {
  // the definition, composed with Eigen from the Body records (Pose products and rotation_about),
  // against forward_kinematics, which folds tree.R into Rodrigues' formula for general axes, picks
  // columns for axes along x, y or z and skips identity joint origins (JointKinematics); the random
  // tree has rotated joint origins, general revolute and prismatic axes, the paper's robots unit
  // axes and identity origins, and the chain rotated origins and general axes throughout
  std::vector<std::pair<std::string, Model>> models;
  for (const auto& r : robots_under_test()) models.emplace_back(r.name, r.model);
  models.emplace_back("chain 14", random_chain(14, 14));
  Rng rng(43);
  for (const auto& [name, model] : models) {
    Data d(model);
    for (int k = 0; k < 5; ++k) {
      const Config q = random_config(model, rng);
      forward_kinematics(model, d, q.base, q.theta);
      std::vector<Pose> X(static_cast<size_t>(model.nb()));
      X[0] = Pose{q.base.position, q.base.orientation.normalized().toRotationMatrix()};
      double worst = 0;
      for (int i = 1; i < model.nb(); ++i) {
        const Body& b = model.body(i);
        const double qi = b.joint_position(q.theta);
        const Pose joint = b.joint.type == JointType::Revolute
                               ? Pose{Vector3::Zero(), rotation_about(b.joint.axis, qi)}
                               : Pose{b.joint.axis * qi, Matrix3::Identity()};
        const auto ui = static_cast<size_t>(i);
        X[ui] = X[static_cast<size_t>(b.parent)] * b.tree * joint;
        worst = std::max(
            {worst, (d.R[ui] - X[ui].R).cwiseAbs().maxCoeff(), (d.p[ui] - X[ui].p).cwiseAbs().maxCoeff()});
      }
      INFO(name << " config " << k << ": largest difference " << worst);
      CHECK(worst < 1e-13);
    }
  }
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

TEST_CASE("sin_cos of the kinematics: within 2 units in the last place of std::sin and std::cos",
          "[dynamics]") {
  std::mt19937_64 gen(31);
  std::uniform_real_distribution<double> small(-10.0, 10.0), large(-1e5, 1e5);
  double worst_abs = 0, worst_rel = 0;
  auto check = [&](double x) {
    double s = 0, c = 0;
    ffsr::detail::sin_cos(x, s, c);
    const double S = std::sin(x), C = std::cos(x);
    for (const auto& [a, b] : {std::pair<double, double>{s, S}, std::pair<double, double>{c, C}}) {
      const double d = std::abs(a - b);
      worst_abs = std::max(worst_abs, d);
      if (b != 0) worst_rel = std::max(worst_rel, d / std::abs(b));
    }
  };
  for (int i = 0; i < 200000; ++i) {
    check(small(gen));
    check(large(gen));
  }
  // the hard cases of the reduction: the doubles nearest to multiples of pi/2 (sin or cos near 0)
  for (int k = -60000; k <= 60000; k += 7) {
    const double x = k * (M_PI / 2);
    check(x);
    check(std::nextafter(x, 1e9));
    check(std::nextafter(x, -1e9));
  }
  for (double x : {0.0, -0.0, 1e-300, M_PI / 4, 1e5, -1e5}) check(x);
  INFO("worst absolute " << worst_abs << ", worst relative " << worst_rel);
  CHECK(worst_abs <= 2 * std::numeric_limits<double>::epsilon());
  CHECK(worst_rel <= 2 * std::numeric_limits<double>::epsilon());
  // beyond the reduced range, and non-finite: the standard functions
  for (double x : {1e5 * 1.5, 1e300, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    double s = 0, c = 0;
    ffsr::detail::sin_cos(x, s, c);
    const double S = std::sin(x), C = std::cos(x);
    CHECK(((s == S && c == C) || (std::isnan(s) && std::isnan(S) && std::isnan(c) && std::isnan(C))));
  }
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

}  // namespace test_dynamics
