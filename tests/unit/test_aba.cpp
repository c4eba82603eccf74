// tests/unit/test_aba.cpp -- the articulated-body algorithm (aba.hpp): the O(n) forward dynamics
// against forward_dynamics (crba, the RNEA bias, a dense Cholesky solve) and against H a + C = tau with
// RNEA as the inverse dynamics, on every kind of tree of tests/support/dynamics_helpers.hpp; the
// momentum its velocity pass gives; its refusals.
#include "support/dynamics_helpers.hpp"

#include "ffsr/algorithm/aba.hpp"
#include "ffsr/algorithm/forward_dynamics.hpp"
#include "ffsr/algorithm/momentum.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace test_aba {

using namespace ffsr;
using namespace ffsr_test;

TEST_CASE("aba: the O(n) forward dynamics equals crba + RNEA + Cholesky and inverts RNEA", "[dynamics][fast]") {
  Rng rng(59);
  std::vector<NamedModel> models = models_of_every_kind();
  models.push_back({"chain 7 with gravity", serial_chain(7, 61, false, Vector3(0.3, -9.81, 1.2))});
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
  const Model c = serial_chain(3, 67, true);
  Data dc(c);
  const Config qc = random_config(c, rng);
  VectorXd a;
  aba(c, dc, qc.base, qc.theta, VectorXd::Zero(c.nv()), VectorXd::Zero(c.nv()), a);
  CHECK(a.cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("aba refuses mimic joints and bad sizes, naming them", "[dynamics][fast]") {
  const Model m = mimic_chain(3);
  Data d(m);
  Rng rng(71);
  const Config q = random_config(m, rng);
  VectorXd a;
  CHECK_THROWS_WITH(aba(m, d, q.base, q.theta, VectorXd::Zero(m.nv()), VectorXd::Zero(m.nv()), a),
                    Catch::Contains("aba: the model has mimic joints; use forward_dynamics"));
  const Model c = serial_chain(3, 1, true);
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

}  // namespace test_aba
