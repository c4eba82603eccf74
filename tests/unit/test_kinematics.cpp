// tests/unit/test_kinematics.cpp -- forward kinematics (kinematics.hpp): each body's pose against its
// definition, the sin_cos it uses against the standard functions, and the random tree the dynamics
// tests share (tests/support/dynamics_helpers.hpp).
#include "support/dynamics_helpers.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace test_kinematics {

using namespace ffsr;
using namespace ffsr_test;

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

}  // namespace test_kinematics
