// tests/unit/test_rnea.cpp -- the recursive Newton-Euler algorithm (rnea.hpp): its columns with unit
// accelerations are H's, its gravity bias is the statics of the whole system, and tau = H a + C with
// bias_forces as C.
#include "support/dynamics_helpers.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace test_rnea {

using namespace ffsr;
using namespace ffsr_test;

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

}  // namespace test_rnea
