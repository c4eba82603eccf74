// tests/unit/test_momentum.cpp -- momentum (momentum.hpp): the total momentum against the first six
// rows of H v and the body sum of finite differences of forward kinematics; the centroidal momentum
// (centroidal_momentum) against the sum over the bodies about the centre of mass; their conservation,
// and the kinetic energy's, along a free-floating motion.
#include "support/dynamics_helpers.hpp"

#include "ffsr/algorithm/momentum.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace test_momentum {

using namespace ffsr;
using namespace ffsr_test;

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
    // momentum about the fixed inertial origin: L_o = L_p0 + p0 x P; the kinetic energy; the
    // centroidal momentum (L_c about the centre of mass c, which moves at P / M)
    auto invariants = [&](const VectorXd& x, Vector6& h, double& T, CentroidalMomentum& hc) {
      const Config q = unpack(x);
      const VectorXd v = x.tail(nv);
      const MatrixXd H = crba(m, d, q.base, q.theta);
      h = momentum(m, d, v);
      h.tail<3>() += q.base.position.cross(h.head<3>());
      T = 0.5 * v.dot(H * v);
      hc = centroidal_momentum(m, d, v);
    };
    const Config q0 = random_config(m, rng);
    VectorXd x(7 + n + nv);
    x << q0.base.position, q0.base.orientation.w(), q0.base.orientation.x(), q0.base.orientation.y(),
        q0.base.orientation.z(), q0.theta, random_velocity(m, rng);
    Vector6 h0;
    double T0;
    CentroidalMomentum c0;
    invariants(x, h0, T0, c0);
    const double dt = 1e-3;
    double worst_P = 0, worst_L = 0, worst_T = 0, worst_Lc = 0, worst_c = 0;
    for (int step = 1; step <= 1000; ++step) {  // 1 s, fixed-step RK4
      const VectorXd k1 = f(x), k2 = f(x + 0.5 * dt * k1), k3 = f(x + 0.5 * dt * k2), k4 = f(x + dt * k3);
      x += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      if (step % 50 == 0) {
        Vector6 h;
        double T;
        CentroidalMomentum hc;
        invariants(x, h, T, hc);
        worst_P = std::max(worst_P, (h.head<3>() - h0.head<3>()).norm() / h0.head<3>().norm());
        worst_L = std::max(worst_L, (h.tail<3>() - h0.tail<3>()).norm() / h0.tail<3>().norm());
        worst_T = std::max(worst_T, std::abs(T - T0) / T0);
        worst_Lc = std::max(worst_Lc, (hc.angular - c0.angular).norm() / c0.angular.norm());
        const Vector3 c_expected = c0.com + step * dt * c0.linear / c0.mass;  // straight at P / M
        worst_c = std::max(worst_c, (hc.com - c_expected).norm() / (step * dt * c0.linear.norm() / c0.mass));
      }
    }
    INFO(r.name << ": relative drift P " << worst_P << ", L_o " << worst_L << ", T " << worst_T << ", L_c "
                << worst_Lc << "; centre of mass off its line by " << worst_c << " of the way");
    // RK4 with dt = 1 ms: global error ~ (omega dt)^4 ~ 1e-12; allow 1e-8 relative
    CHECK(worst_P < 1e-8);
    CHECK(worst_L < 1e-8);
    CHECK(worst_T < 1e-8);
    CHECK(worst_Lc < 1e-8);
    CHECK(worst_c < 1e-8);
    // L_c is not L_o: the check above is not the one before it (they differ by c x P)
    CHECK((c0.angular - h0.tail<3>()).norm() > 1e-3 * c0.angular.norm());
    // the motion is not trivial: the joints moved (at least 0.1 rad somewhere)
    CHECK((unpack(x).theta - q0.theta).cwiseAbs().maxCoeff() > 0.1);
  }
}

TEST_CASE("centroidal_momentum: the sum over the bodies about the centre of mass", "[dynamics]") {
  for_each_config(21, 3, [&](const TestRobot& r, Data& d, Rng& rng, const Config& q, int k) {
    const VectorXd v = random_velocity(r.model, rng);
    crba(r.model, d, q.base, q.theta);
    const CentroidalMomentum h = centroidal_momentum(r.model, d, v);
    // the reference: every listed mass's centre of mass (forward kinematics) and velocities (finite
    // differences of forward kinematics), never the library's velocity or inertia code;
    // L_c = sum_i R_i I_i R_i^T w_i + m_i (c_i - c) x (v_i - v_c)
    const std::vector<LinkVelocity> lv = fd_link_velocities(r, q, v, library_chart);
    double M = 0;
    Vector3 c = Vector3::Zero(), P = Vector3::Zero();
    for (size_t i = 0; i < lv.size(); ++i) {
      const double mi = r.links[i].inertia.mass;
      M += mi;
      c += mi * lv[i].c;
      P += mi * lv[i].vc;
    }
    c /= M;
    const Vector3 vc = P / M;
    Vector3 L = Vector3::Zero();
    for (size_t i = 0; i < lv.size(); ++i) {
      const Inertia& in = r.links[i].inertia;
      L += lv[i].R * in.I * lv[i].R.transpose() * lv[i].w + in.mass * (lv[i].c - c).cross(lv[i].vc - vc);
    }
    INFO(r.name << " config " << k << ": L_c " << h.angular.transpose() << ", reference " << L.transpose());
    CHECK(h.mass == Approx(M).epsilon(1e-12));  // rounding only
    CHECK(rel_err(h.com, c) < 1e-12);           // positions from forward kinematics: rounding only
    CHECK(rel_err(h.linear, P) < 1e-8);         // finite differences, truncation O(h^2)
    CHECK(rel_err(h.angular, L) < 1e-8);
    // the library's momentum about the base origin, moved to c: L_c = L_0 - (c - p_0) x P (rounding)
    const Vector6 h0 = momentum(r.model, d, v);
    CHECK(rel_err(h.angular, Vector3(h0.tail<3>() - (h.com - q.base.position).cross(h0.head<3>()))) < 1e-12);
    CHECK(rel_err(h.linear, Vector3(h0.head<3>())) < 1e-12);
    // about another point the angular momentum differs: the reference point matters here
    CHECK((h.angular - h0.tail<3>()).norm() > 1e-3 * h.angular.norm());
  });
  const Model m = random_chain(3, 5);
  Data d(m);
  Rng rng(22);
  const Config q = random_config(m, rng);
  crba(m, d, q.base, q.theta);
  CHECK_THROWS_WITH(centroidal_momentum(m, d, VectorXd::Zero(m.nv() - 1)),
                    Catch::Contains("centroidal_momentum: v has 8 entries, expected 9"));
}

}  // namespace test_momentum
