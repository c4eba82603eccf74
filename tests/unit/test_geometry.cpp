// Collision shapes and distances (geometry/shape.hpp, geometry/distance.hpp): FCL's distances on
// random configurations of both paper robots against an independent computation written here
// (exact point-box and point-segment distances minimized along the capsule's segment by golden
// section: the distance to a convex set is convex along a segment), the nearest points, and the
// gradient against central finite differences.
#include "ffsr/geometry/distance.hpp"
#include "ffsr/parsers/urdf.hpp"
#include "ffsr/parsers/urdf_collision.hpp"

#include <catch2/catch.hpp>

#include <random>

namespace test_geometry {

using namespace ffsr;

const std::string kRobots = std::string(FFSR_SOURCE_DIR) + "/robots/";

/// Golden-section minimum of a convex f on [0, 1].
template <class F>
double convex_min(F f) {
  double a = 0, b = 1;
  const double g = (std::sqrt(5.0) - 1) / 2;
  double c = b - g * (b - a), d = a + g * (b - a), fc = f(c), fd = f(d);
  for (int i = 0; i < 200 && b - a > 1e-15; ++i) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - g * (b - a), fc = f(c);
    } else {
      a = c, c = d, fc = fd, d = a + g * (b - a), fd = f(d);
    }
  }
  return std::min({f(0.0), f(1.0), f(0.5 * (a + b))});
}

/// Exact distance from point x to a box (centre c, axes R, half sizes h).
double point_box(const Vector3& x, const Vector3& c, const Matrix3& R, const Vector3& h) {
  const Vector3 q = (R.transpose() * (x - c)).cwiseAbs() - h;
  return q.cwiseMax(0.0).norm();
}

double point_segment(const Vector3& x, const Vector3& a, const Vector3& b) {
  const Vector3 d = b - a;
  const double t = d.squaredNorm() > 0 ? std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (x - a - t * d).norm();
}

struct Segment {
  Vector3 a, b;
  double r;
};

/// Capsule (segment s, radius r) to box: min over the segment of the point-box distance, minus r.
double capsule_box(const Segment& s, const Vector3& c, const Matrix3& R, const Vector3& h) {
  return convex_min([&](double t) { return point_box(s.a + t * (s.b - s.a), c, R, h); }) - s.r;
}

/// Capsule to capsule: min over the first segment of the point-segment distance, minus both radii.
double capsule_capsule(const Segment& s, const Segment& u) {
  return convex_min([&](double t) { return point_segment(s.a + t * (s.b - s.a), u.a, u.b); }) - s.r - u.r;
}

struct Robot {
  Model model;
  CollisionChecker checker;
};

Robot paper_robot(const std::string& urdf, double r, double exemption) {
  Model m = model_from_urdf_file(kRobots + urdf, "ee");
  RobotGeometry g = robot_geometry(m, urdf_collision_shapes(kRobots + urdf), {r}, {});
  CollisionChecker c(m, g, Shape::box(Vector3(0.5, 0.5, 0.5)), exemption);
  return {std::move(m), std::move(c)};
}

/// The world segment of body b's capsule, from the kinematics (not from the shapes): its joint origin
/// to its child's (the end-effector point on the last body, cut `cut` metres short).
Segment world_segment(const Model& m, const Data& d, int b, double r, double cut) {
  Vector3 end;
  if (b + 1 < m.nb() && m.body(b + 1).parent == b) {
    end = d.p[static_cast<size_t>(b + 1)];
  } else {
    end = frame_pose(m, d, m.end_effector()).p;
    const Vector3 dir = (end - d.p[static_cast<size_t>(b)]).normalized();
    end -= cut * dir;
  }
  return {d.p[static_cast<size_t>(b)], end, r};
}

/// Checks every pair of `rob` at `samples` random configurations (random base and target poses too).
void check_robot(const Robot& rob, int samples, std::uint64_t seed, double bus_half, int& compared) {
  const Model& m = rob.model;
  const CollisionChecker& cc = rob.checker;
  const double r = 0.05, cut = cc.exemption();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Data d(m);
  std::vector<PairDistance> out;
  for (int s = 0; s < samples; ++s) {
    Eigen::VectorXd th(m.n());
    for (int k = 0; k < m.n(); ++k) th(k) = M_PI * U(rng);
    BasePose base;
    base.position = Vector3(U(rng), U(rng), U(rng)) * 0.3;
    base.orientation = Quaternion(Eigen::AngleAxisd(0.5 * U(rng), Vector3(U(rng), U(rng), 1).normalized()));
    forward_kinematics(m, d, base, th);
    Pose target{Vector3(U(rng), U(rng), U(rng)) * 2.5,
                Eigen::AngleAxisd(M_PI * U(rng), Vector3(U(rng), 1, U(rng)).normalized()).toRotationMatrix()};
    cc.distances(d, target, out);
    for (const PairDistance& pd : out) {
      const BodyPair& p = cc.pairs()[static_cast<size_t>(pd.pair)];
      double expected;
      if (p.b < 0) {
        if (p.a == 0) continue;  // bus-target: box-box, not covered by the independent forms here
        const Segment sa = world_segment(m, d, p.a, r, p.a == m.frame(m.end_effector()).body ? cut : 0.0);
        expected = capsule_box(sa, target.p, target.R, Vector3::Constant(0.25));
      } else if (p.b == 0) {
        expected = capsule_box(world_segment(m, d, p.a, r, 0.0), d.p[0], d.R[0], Vector3::Constant(bus_half));
      } else {
        expected = capsule_capsule(world_segment(m, d, p.a, r, 0.0), world_segment(m, d, p.b, r, 0.0));
      }
      if (expected < 1e-6) continue;  // overlapping: the independent forms give 0 there, not the depth
      INFO(cc.pair_name(pd.pair) << " sample " << s);
      CHECK(std::abs(pd.distance - expected) < 1e-9);
      CHECK(std::abs((pd.p_a - pd.p_b).norm() - pd.distance) < 1e-9);  // the nearest points
      ++compared;
    }
  }
}

TEST_CASE("geometry: FCL distances match closed forms on random configurations of both paper robots") {
  // 1e-9 m: capsule-box pairs by the library's golden section on the box's signed distance (60
  // steps), capsule-capsule by segment closest points; the test's forms by golden section to 1e-15 in t
  int compared3 = 0, compared7 = 0;
  const Robot r3 = paper_robot("paper_3dof.urdf", 0.05, 0.2);
  const Robot r7 = paper_robot("paper_7dof.urdf", 0.05, 0.2);
  check_robot(r3, 200, 7, 0.6, compared3);
  check_robot(r7, 200, 11, 0.45, compared7);
  CHECK(compared3 > 400);
  CHECK(compared7 > 2000);
  // the pairs: 3-DOF (links 1..3, bus, target): 3 target pairs + bus + link2, link3 vs bus + link1-link3
  CHECK(r3.checker.pairs().size() == 4 + 2 + 1);
}

TEST_CASE("geometry: a contact exemption longer than the end-effector link reaches back along the chain") {
  // paper 3-DOF: link 3 runs 0.5 m from joint 3 to the end-effector point, link 2 1.6 m from joint 2
  // to joint 3. With a 0.7 m exemption link 3 has no arm-target pair and link 2 is checked against
  // the target with its centre-line capsule ending 0.2 m before joint 3.
  const Robot rob = paper_robot("paper_3dof.urdf", 0.05, 0.7);
  const Model& m = rob.model;
  const CollisionChecker& cc = rob.checker;
  CHECK(cc.exempt(3));
  CHECK_FALSE(cc.exempt(2));
  REQUIRE(cc.exempt_capsule(2).has_value());
  CHECK(cc.exempt_capsule(2)->length == Approx(1.4).margin(1e-12));
  int link2_target = -1;
  for (size_t i = 0; i < cc.pairs().size(); ++i) {
    const BodyPair& p = cc.pairs()[i];
    CHECK_FALSE((p.b < 0 && p.a == 3));
    if (p.b < 0 && p.a == 2) link2_target = static_cast<int>(i);
  }
  REQUIRE(link2_target >= 0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  Data d(m);
  int compared = 0;
  for (int s = 0; s < 100; ++s) {
    const Eigen::Vector3d th(M_PI * U(rng), M_PI * U(rng), M_PI * U(rng));
    forward_kinematics(m, d, BasePose{}, th);
    const Pose target{Vector3(U(rng), U(rng), U(rng)) * 2.5,
                      Eigen::AngleAxisd(M_PI * U(rng), Vector3(U(rng), 1, U(rng)).normalized()).toRotationMatrix()};
    const Vector3 a = d.p[2], b = d.p[2] + (d.p[3] - d.p[2]) * (1.4 / 1.6);
    const double expected = capsule_box({a, b, 0.05}, target.p, target.R, Vector3::Constant(0.25));
    if (expected < 1e-6) continue;
    CHECK(std::abs(cc.pair_distance(d, target, link2_target).distance - expected) < 1e-9);
    ++compared;
  }
  CHECK(compared > 50);
  // the default 0.2 m ends on link 3 itself: link 2 keeps its whole capsule
  const Robot def = paper_robot("paper_3dof.urdf", 0.05, 0.2);
  CHECK_FALSE(def.checker.exempt(3));
  REQUIRE(def.checker.exempt_capsule(3).has_value());
  CHECK(def.checker.exempt_capsule(3)->length == Approx(0.3).margin(1e-12));
  CHECK_FALSE(def.checker.exempt_capsule(2).has_value());
}

TEST_CASE("geometry: distance gradient equals central finite differences (base and target fixed)") {
  const Robot rob = paper_robot("paper_7dof.urdf", 0.05, 0.2);
  const Model& m = rob.model;
  Data d(m), dh(m);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  const Pose target{Vector3(2.0, -0.5, 1.5), Matrix3::Identity()};
  int checked = 0;
  for (int s = 0; s < 30; ++s) {
    Eigen::VectorXd th(m.n());
    for (int k = 0; k < m.n(); ++k) th(k) = M_PI * U(rng);
    forward_kinematics(m, d, BasePose{}, th);
    Eigen::VectorXd g(m.n());
    for (size_t i = 0; i < rob.checker.pairs().size(); ++i) {
      const PairDistance pd = rob.checker.pair_distance(d, target, static_cast<int>(i));
      if (pd.distance < 1e-3) continue;
      rob.checker.distance_gradient(m, d, pd, g);
      const double h = 1e-6;
      for (int k = 0; k < m.n(); ++k) {
        Eigen::VectorXd tp = th, tm = th;
        tp(k) += h;
        tm(k) -= h;
        forward_kinematics(m, dh, BasePose{}, tp);
        const double fp = rob.checker.pair_distance(dh, target, static_cast<int>(i)).distance;
        forward_kinematics(m, dh, BasePose{}, tm);
        const double fm = rob.checker.pair_distance(dh, target, static_cast<int>(i)).distance;
        INFO(rob.checker.pair_name(static_cast<int>(i)) << " joint " << k);
        CHECK(std::abs(g(k) - (fp - fm) / (2 * h)) < 1e-5);
      }
      ++checked;
    }
  }
  CHECK(checked > 200);
}

TEST_CASE("geometry: the contact point on a shape's surface, closed forms") {
  const Shape box = Shape::box(Vector3(0.5, 0.5, 0.5));
  CHECK(point_surface_distance(box, Vector3(-0.25, 0.15, 0.1)) == Approx(0).margin(1e-15));
  CHECK(point_surface_distance(box, Vector3(-0.35, 0, 0)) == Approx(0.1));
  CHECK(point_surface_distance(box, Vector3(0, 0, 0)) == Approx(-0.25));
  CHECK(point_surface_distance(box, Vector3(0.35, 0.35, 0)) == Approx(0.1 * std::sqrt(2.0)));
  CHECK(point_surface_distance(Shape::sphere(0.3), Vector3(0, 0.5, 0)) == Approx(0.2));
  CHECK(point_surface_distance(Shape::cylinder(0.3, 1.0), Vector3(0, 0, 0.7)) == Approx(0.2));
  CHECK(point_surface_distance(Shape::cylinder(0.3, 1.0), Vector3(0.4, 0, 0.6)) == Approx(std::sqrt(0.02)));
}

TEST_CASE("geometry: bad shapes and radii are refused naming the key") {
  auto msg = [](auto f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(msg([] { target_shape_of("cone", {1}, {}); }) ==
        "--target-shape: unknown shape 'cone' (box, sphere or cylinder)");
  CHECK(msg([] { target_shape_of("box", {0.5, -0.5, 0.5}, {}); }) ==
        "--target-size: box sizes must be positive and finite, got -0.5");
  CHECK(msg([] { target_shape_of("sphere", {std::nan("")}, {}); }) ==
        "--target-size: radius must be positive and finite, got nan");
  CHECK(msg([] { target_shape_of("box", {0.5, 0.5}, {}); }) == "--target-size: a box needs 3 numbers, got 2");
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf", "ee");
  CHECK(msg([&] { robot_geometry(m, {}, {-0.5}, {}); }) == "--link-radius: must be positive and finite, got -0.5");
  CHECK(msg([&] { robot_geometry(m, {}, {0.05, 0.05}, {}); }) ==
        "--link-radius: expected 1 value or one per moving body (3), got 2");
  CHECK(msg([&] { robot_geometry(m, {}, {0.05}, {1, 1, std::nan("")}); }) ==
        "--bus-box: box sizes must be positive and finite, got nan");
}

TEST_CASE("geometry: URDF collision primitives are read and capsules fill the links without them") {
  const Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf", "ee");
  const RobotGeometry g = robot_geometry(m, urdf_collision_shapes(kRobots + "paper_3dof.urdf"), {0.05}, {});
  REQUIRE(g.shapes[0].size() == 1);
  CHECK(g.origin[0] == "urdf");
  CHECK(g.shapes[0][0].size.isApprox(Vector3(1.2, 1.2, 1.2)));
  for (int b = 1; b <= 3; ++b) {
    REQUIRE(g.shapes[static_cast<size_t>(b)].size() == 1);
    CHECK(g.shapes[static_cast<size_t>(b)][0].kind == Shape::Kind::Capsule);
  }
  CHECK(g.shapes[1][0].length == Approx(1.4));
  CHECK(g.shapes[3][0].length == Approx(0.5));  // link 3 to the end-effector
}

TEST_CASE("geometry: a capsule sunk into a box gets the least signed distance along its segment") {
  // random capsules through a rotated box: the depth against the signed point-box distance minimized
  // along the segment by golden section (convex along a segment), written here
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  const Shape box = Shape::box(Vector3(0.5, 0.3, 0.8));
  const Pose B{Vector3(0.2, -0.1, 0.3), Eigen::AngleAxisd(0.7, Vector3(1, 2, 3).normalized()).toRotationMatrix()};
  auto signed_box = [&](const Vector3& x) {
    const Vector3 e = (B.R.transpose() * (x - B.p)).cwiseAbs() - 0.5 * box.size;
    return e.maxCoeff() > 0 ? e.cwiseMax(0.0).norm() : e.maxCoeff();
  };
  int sunk = 0;
  for (int s = 0; s < 400; ++s) {
    const Shape cap = Shape::capsule(0.05 + 0.1 * std::abs(U(rng)), 0.2 + 0.8 * std::abs(U(rng)));
    const Pose P{B.p + 0.4 * Vector3(U(rng), U(rng), U(rng)),
                 Eigen::AngleAxisd(M_PI * U(rng), Vector3(U(rng), U(rng), U(rng)).normalized()).toRotationMatrix()};
    const Vector3 a = P.p - 0.5 * cap.length * P.R.col(2), b = P.p + 0.5 * cap.length * P.R.col(2);
    const double expected = convex_min([&](double t) { return signed_box(a + t * (b - a)); }) - cap.radius;
    if (expected > -1e-3) continue;  // the segment well inside: the depth branch
    double d;
    Vector3 pa, pb;
    detail::round_box(cap, P, box, B, d, pa, pb);
    INFO("sample " << s);
    CHECK(std::abs(d - expected) < 1e-9);
    CHECK((pa - pb).norm() == Approx(std::abs(d)).margin(1e-9));
    ++sunk;
  }
  CHECK(sunk > 100);
}

TEST_CASE("geometry: a capsule overlapping a box gets its depth, continuous with the distance") {
  // a capsule of radius 0.1 along x at height z above the top face (z = 0.25) of a 0.5 m cube:
  // signed distance z - 0.25 - 0.1 whether it is above the face or sunk into it (closed form)
  Model m = model_from_urdf_file(kRobots + "paper_3dof.urdf", "ee");
  for (double z : {0.5, 0.36, 0.3, 0.2}) {
    double d;
    Vector3 pa, pb;
    const Shape cap = Shape::capsule(0.1, 0.2);
    const Pose P{Vector3(0, 0, z), Eigen::AngleAxisd(M_PI / 2, Vector3::UnitY()).toRotationMatrix()};
    const Shape box = Shape::box(Vector3(0.5, 0.5, 0.5));
    if (z - 0.35 > 0) continue;
    detail::round_box(cap, P, box, Pose{}, d, pa, pb);
    CHECK(d == Approx(z - 0.35).margin(1e-12));
    CHECK((pa - pb).norm() == Approx(std::abs(d)).margin(1e-12));
  }
}

}  // namespace test_geometry
