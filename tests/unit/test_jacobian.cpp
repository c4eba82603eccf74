// tests/unit/test_jacobian.cpp -- frame Jacobians (jacobian.hpp) against finite differences of forward
// kinematics, and the generalized Jacobian J_f (Eq. 29) as the end-effector velocity under zero
// momentum.
#include "support/dynamics_helpers.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace test_jacobian {

using namespace ffsr;
using namespace ffsr_test;

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

}  // namespace test_jacobian
