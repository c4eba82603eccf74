// tests/unit/test_crba.cpp -- the composite rigid body algorithm (crba.hpp): H symmetric positive
// definite, equal to the kinetic-energy sum of finite differences of forward kinematics and to the
// columns of RNEA on chains and trees of every numbering (the contiguous-subtree path and the ancestor
// walk), the subtree numbering it relies on, and its refusal of an H that overflows.
//
// Robots: the paper's 3-DOF and 7-DOF robots, the random branched tree, serial chains and branched
// trees of tests/support/dynamics_helpers.hpp. Independent references: finite differences of forward
// kinematics (h = 1e-5, truncation O(h^2) ~ 1e-10 relative) and RNEA in body coordinates (no
// composite inertias). Tolerances are stated next to each check.
#include "support/dynamics_helpers.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace test_crba {

using namespace ffsr;
using namespace ffsr_test;

namespace {

/// A chain of three joints whose second joint origin is `length` metres from the first.
Model long_chain(double length) {
  ModelBuilder b("base", Inertia{100, Vector3::Zero(), Matrix3::Identity()});
  const Inertia link{2, Vector3(0.1, 0, 0), 0.1 * Matrix3::Identity()};
  b.add_joint("j1", JointType::Revolute, "base", Pose{}, Vector3::UnitZ(), "l1", link);
  b.add_joint("j2", JointType::Revolute, "l1", Pose{Vector3(length, 0, 0)}, Vector3::UnitY(), "l2", link);
  b.add_joint("j3", JointType::Revolute, "l2", Pose{Vector3(0, 0.5, 0)}, Vector3(1, 1, 0), "l3", link);
  return b.build();
}

}  // namespace

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

TEST_CASE("crba equals the columns of RNEA on chains and trees of every numbering", "[dynamics][fast]") {
  Rng rng(41);
  std::vector<NamedModel> models = models_of_every_kind();
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

TEST_CASE("the model's subtree numbering equals the ancestry of every body", "[dynamics][fast]") {
  std::vector<NamedModel> models = models_of_every_kind();
  models.push_back({"mimic chain", mimic_chain(3)});
  for (const NamedModel& nm : models) {
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

}  // namespace test_crba
