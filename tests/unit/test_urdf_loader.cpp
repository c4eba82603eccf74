// tests/unit/test_urdf_loader.cpp -- the named steps of the URDF loader and of ModelBuilder, each
// alone: link merging (composite inertia), mimic resolution, locked values through mimic chains,
// inertia repairs (each one reported), the document checks; and the steps of the contact
// simulations (scaled right-hand side, Hertz time, running maxima). Expected values come from identities
// and from sums computed here independently, never from the code under test.
#include "ffsr/parsers/detail/urdf_document.hpp"
#include "ffsr/simulate/multibody.hpp"
#include "ffsr/simulate/single_body.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

namespace test_urdf_loader {

using namespace ffsr;

namespace {

/// The spatial inertia about the frame origin, as its three parts: mass, first moment m c, and
/// rotational inertia about the origin I_o = I_c + m (|c|^2 1 - c c^T) (RBDA 2.12, written out
/// here). Inertias about one point add, so the parts of a composite are the sums of the parts.
struct AboutOrigin {
  double m;
  Vector3 h;
  Matrix3 Io;
};
AboutOrigin about_origin(const Inertia& in) {
  const Vector3& c = in.com;
  Matrix3 Io = in.I;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) Io(r, k) += in.mass * ((r == k ? c.squaredNorm() : 0.0) - c(r) * c(k));
  return {in.mass, in.mass * c, Io};
}

Inertia box(double m, const Vector3& com, double a, double b, double c) {
  Inertia in;
  in.mass = m;
  in.com = com;
  in.I = Vector3(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12).asDiagonal();
  return in;
}

const char* kTwoLinks = R"(<robot name="r">
  <link name="base"><inertial><origin xyz="0.1 0 0"/><mass value="20"/>
    <inertia ixx="2" ixy="0" ixz="0" iyy="3" iyz="0" izz="4"/></inertial></link>
  <link name="plate"><inertial><origin xyz="0 0.2 0"/><mass value="5"/>
    <inertia ixx="0.5" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.7"/></inertial></link>
  <link name="arm"><inertial><mass value="3"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="finger"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="weld" type="fixed"><parent link="base"/><child link="plate"/>
    <origin xyz="0.5 0 0" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="arm"/><child link="finger"/><axis xyz="0 0 1"/>
    <origin xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
    <mimic joint="j1" multiplier="2" offset="0.1"/></joint>
</robot>)";

}  // namespace

TEST_CASE("link merging: the composite inertia is the sum of the parts about one point", "[urdf_loader]") {
  const Inertia a = box(20, Vector3(0.1, -0.2, 0.3), 1.0, 0.5, 0.8);
  Inertia b = box(5, Vector3(0.4, 0.6, -0.1), 0.2, 0.3, 0.9);
  b.I(0, 1) = b.I(1, 0) = 0.01;
  const Inertia ab = detail::merged_inertia(a, b);
  const AboutOrigin pa = about_origin(a), pb = about_origin(b), pab = about_origin(ab);
  // Tolerance: a few ulps of the largest entry (inertias of order 1 kg m^2).
  CHECK(pab.m == Approx(pa.m + pb.m).epsilon(1e-15));
  CHECK((pab.h - (pa.h + pb.h)).norm() < 1e-13);
  CHECK((pab.Io - (pa.Io + pb.Io)).cwiseAbs().maxCoeff() < 1e-13);
  // The composite's centre of mass is the mass-weighted mean, by definition.
  CHECK((ab.com - (20 * a.com + 5 * b.com) / 25).norm() < 1e-15);
}

TEST_CASE("link merging: a rotated and moved link keeps its principal moments", "[urdf_loader]") {
  const Inertia in = box(2, Vector3(0.1, 0.2, 0.3), 0.3, 0.7, 1.1);
  const Pose pose{Vector3(1, -2, 0.5), rotation_about(Vector3(1, 1, 0).normalized(), 0.7)};
  const Inertia out = detail::inertia_in_frame(in, pose);
  CHECK(out.mass == 2);
  CHECK((out.com - (pose.p + pose.R * in.com)).norm() < 1e-15);
  // w^T I' w = (R^T w)^T I (R^T w) for every w: the same body seen from the rotated frame.
  for (const Vector3& w : {Vector3(1, 0, 0), Vector3(0.3, -0.5, 2.0), Vector3(-1, 1, 1)}) {
    const Vector3 wb = pose.R.transpose() * w;
    CHECK(w.dot(out.I * w) == Approx(wb.dot(in.I * wb)).epsilon(1e-14));
  }
}

TEST_CASE("link merging: a fixed child of the URDF base sums into the base body", "[urdf_loader]") {
  const Model m = model_from_urdf_string(kTwoLinks, "two_links.urdf", "finger");
  // Independent: the plate's inertia moved by the weld (a quarter turn about z, then 0.5 m along x),
  // both parts taken about the base origin and added.
  const Inertia base{20, Vector3(0.1, 0, 0), Vector3(2, 3, 4).asDiagonal()};
  Inertia plate;
  plate.mass = 5;
  plate.com = Vector3(0.5 - 0.2, 0, 0);           // (0, 0.2, 0) turned a quarter about z: (-0.2, 0, 0)
  plate.I = Vector3(0.6, 0.5, 0.7).asDiagonal();  // x and y moments swap under a quarter turn
  const AboutOrigin expected_base = about_origin(base), expected_plate = about_origin(plate);
  const AboutOrigin got = about_origin(m.body(0).inertia);
  CHECK(got.m == Approx(25).epsilon(1e-15));
  CHECK((got.h - (expected_base.h + expected_plate.h)).norm() < 1e-12);
  CHECK((got.Io - (expected_base.Io + expected_plate.Io)).cwiseAbs().maxCoeff() < 1e-12);
  // The plate stays a named frame on the base body.
  CHECK(m.frame(m.frame_index("plate")).body == 0);
}

TEST_CASE("mimic resolution: chains compose multipliers and offsets to one leader", "[urdf_loader]") {
  const Inertia link = box(1, Vector3(0.5, 0, 0), 1.0, 0.1, 0.1);
  ModelBuilder b("base", box(100, Vector3::Zero(), 1, 1, 1));
  b.add_joint("j1", JointType::Revolute, "base", Pose{}, Vector3::UnitZ(), "l1", link)
      .add_joint("j2", JointType::Revolute, "l1", Pose{Vector3(1, 0, 0), Matrix3::Identity()},
                 Vector3::UnitZ(), "l2", link)
      .add_joint("j3", JointType::Revolute, "l2", Pose{Vector3(1, 0, 0), Matrix3::Identity()},
                 Vector3::UnitZ(), "l3", link)
      .set_mimic("j3", "j2", 3.0, 0.5)
      .set_mimic("j2", "j1", -2.0, 0.25);
  const Model m = b.build();
  REQUIRE(m.n() == 1);
  // q3 = 3 q2 + 0.5 and q2 = -2 q1 + 0.25 give q3 = -6 q1 + 1.25.
  CHECK(m.body(3).leader == "j1");
  CHECK(m.body(3).multiplier == -6.0);
  CHECK(m.body(3).offset == 1.25);
  CHECK(m.body(2).leader == "j1");
  CHECK(m.body(1).leader.empty());
  CHECK(m.body(3).coord == m.body(1).coord);

  ModelBuilder loop = b;
  loop.set_mimic("j1", "j3", 1.0, 0.0);
  CHECK_THROWS_WITH(loop.build(), Catch::Contains("mimic joints form a loop"));
}

TEST_CASE("locked values follow mimic chains, unknown locks name the moving joints", "[urdf_loader]") {
  const detail::UrdfDocument doc = detail::parse_urdf_document(kTwoLinks, "two_links.urdf");
  UrdfOptions opt;
  opt.locks = {{"j1", 0.3}};
  const std::map<std::string, double> locked = detail::locked_joint_values(*doc.model, opt);
  REQUIRE(locked.size() == 1);
  const auto value = detail::locked_value(*doc.model, locked, *doc.model->joints_.at("j2"));
  REQUIRE(value);
  CHECK(*value == Approx(2 * 0.3 + 0.1).epsilon(1e-15));  // the <mimic> of j2: q2 = 2 q1 + 0.1
  CHECK_FALSE(detail::locked_value(*doc.model, {}, *doc.model->joints_.at("j2")));

  opt.locks = {{"nope", 0.0}};
  CHECK_THROWS_WITH(detail::locked_joint_values(*doc.model, opt),
                    "lock-joints: unknown joint 'nope'; the moving joints are: j1, j2");
  opt.locks = {{"weld", 0.0}};
  CHECK_THROWS_WITH(detail::locked_joint_values(*doc.model, opt),
                    "lock-joints: joint 'weld' is a fixed joint already");
}

TEST_CASE("repairs: each change of a link's inertia is reported", "[urdf_loader]") {
  urdf::Link rod;
  rod.name = "rod";
  rod.inertial = std::make_shared<urdf::Inertial>();
  rod.inertial->mass = 2.0;
  rod.inertial->ixx = 0.1;  // 0.1 + 0.2 < 0.5: breaks the triangle inequality
  rod.inertial->iyy = 0.2;
  rod.inertial->izz = 0.5;
  std::vector<ModelRepair> repairs;
  UrdfOptions opt;
  CHECK_THROWS_WITH(detail::checked_link_inertia(rod, opt, repairs), Catch::Contains("inertia-repair"));
  CHECK(repairs.empty());

  opt.inertia_repair = InertiaRepair::Balance;
  opt.min_mass = 3.0;
  const Inertia in = detail::checked_link_inertia(rod, opt, repairs);
  REQUIRE(repairs.size() == 2);
  CHECK(repairs[0].link == "rod");
  CHECK(repairs[0].before == std::vector<double>{2.0});
  CHECK(repairs[0].after == std::vector<double>{3.0});
  CHECK(in.mass == 3.0);
  // Balance raises the two smaller moments by half the deficit 0.2 each: (0.2, 0.3, 0.5).
  REQUIRE(repairs[1].after.size() == 3);
  CHECK(repairs[1].after[0] == Approx(0.2).epsilon(1e-12));
  CHECK(repairs[1].after[1] == Approx(0.3).epsilon(1e-12));
  CHECK(repairs[1].after[2] == Approx(0.5).epsilon(1e-12));
  CHECK(in.I.trace() == Approx(1.0).epsilon(1e-12));  // trace = sum of the principal moments
}

TEST_CASE("the document checks: two parents, and the bus options", "[urdf_loader]") {
  const std::string two_parents = R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="ja" type="fixed"><parent link="a"/><child link="c"/></joint>
    <joint name="jb" type="fixed"><parent link="b"/><child link="c"/></joint></robot>)";
  CHECK_THROWS_AS(detail::parse_urdf_document(two_parents, "x.urdf"), ModelError);
  CHECK_THROWS_WITH(detail::parse_urdf_document("<robot name=\"r\"\xff/>", "x.urdf"),
                    Catch::StartsWith("x.urdf: not a text file in UTF-8"));

  Bus bus;
  bus.mass = -1;
  CHECK_THROWS_WITH(detail::validate_bus(bus), "bus-mass: must be positive and finite, got -1");
  bus.mass = 10;
  bus.inertia = Vector3(1, 1, 1).asDiagonal();
  CHECK_NOTHROW(detail::validate_bus(bus));
}

TEST_CASE("single-body steps: the scaled right-hand side is Eq. 16 in SI units", "[urdf_loader][simulate]") {
  const HertzDamped<HuntCrossley> law({1e9, 1.5, 0.5}, 0.2);
  const double M_ie = 40.0;
  const auto s = detail::single_body_scaling(law, M_ie);
  CHECK(s.delta_ref == law.max_deformation(M_ie));
  CHECK(s.v0 == 0.2);
  const cvode::Rhs rhs = detail::single_body_rhs(s);
  for (const auto& [x, v] : {std::pair{0.0, 1.0}, std::pair{0.5, 0.7}, std::pair{0.9, -0.3}}) {
    Eigen::Vector2d y(x, v), ydot;
    rhs(0.0, y, ydot);
    CHECK(ydot[0] == v);
    // Back in SI units: δ̈ = ydot[1] v0^2 / δ_ref, and M_ie δ̈ = -F(δ, δ̇) (Eq. 16); relative 1e-12.
    const double F = law.force(s.delta_ref * x, s.v0 * v);
    CHECK(M_ie * ydot[1] * s.v0 * s.v0 / s.delta_ref == Approx(-F).epsilon(1e-12).margin(1e-9));
  }
}

TEST_CASE("multibody steps: Hertz time and running maxima", "[urdf_loader][simulate]") {
  // A linear spring (alpha = 1): the time scale is sqrt(M/K), whatever the speed.
  for (double vin : {0.01, 0.3, 2.0})
    CHECK(detail::hertz_time({4e6, 1.0, 1.0}, 25.0, vin) == Approx(std::sqrt(25.0 / 4e6)).epsilon(1e-14));
  MultibodyContactResult res;
  detail::record_contact_sample(res, 0.1, 5.0, 1e-5, true);
  detail::record_contact_sample(res, 0.2, 9.0, 2e-5, true);
  detail::record_contact_sample(res, 0.3, 7.0, 3e-5, false);
  CHECK(res.f_max == 9.0);
  CHECK(res.t_at_f_max == 0.2);
  CHECK(res.delta_at_f_max == 2e-5);
  CHECK(res.delta_max == 3e-5);
  CHECK(res.series.size() == 2);
}

}  // namespace test_urdf_loader
