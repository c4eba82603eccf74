// tests/test_real_robots.cpp -- URDFs of real arms as the community ships them (Panda, UR5,
// Kinova Jaco2 in ../shared/urdf-samples), mounted on a spacecraft bus, with mimic and locked joints,
// inertia repairs and the contact point at the gripper.
#include "support/dynamics_helpers.hpp"
#include "support/run_command.hpp"

#include "ffsr/parsers/detail/urdf_document.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

// The samples are read from FFSR_URDF_SAMPLES or FFSR_SOURCE_DIR/../shared/urdf-samples; the tests
// that need them say "skipped" and pass when the folder is absent. References are independent of
// the code under test: RNEA (body coordinates) against CRBA; finite differences of forward
// kinematics (tests/support/dynamics_helpers.hpp, h = 1e-5, O(h^2)) for energy, momentum and
// Jacobians; the full model (mimic tag removed) for the mimic reduction; closed forms for the repairs
// and for the mount split.

namespace test_real_robots {

using namespace ffsr;
using namespace ffsr_test;

namespace {

std::string samples_dir() {
  if (const char* env = std::getenv("FFSR_URDF_SAMPLES")) return env;
  return std::string(FFSR_SOURCE_DIR) + "/../shared/urdf-samples";
}

/// True when the samples are there; otherwise a visible "skipped" message.
bool have_samples() {
  if (std::filesystem::exists(samples_dir() + "/panda.urdf")) return true;
  WARN("skipped: the URDF samples are not in " << samples_dir() << " (set FFSR_URDF_SAMPLES)");
  return false;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A 500 kg bus with a full inertia, its centre of mass off the bus frame origin, the arm mounted
/// off-centre and tilted (nothing aligned by accident).
Bus test_bus() {
  Bus b;
  b.mass = 500;
  b.inertia << 90, 2, -1, 2, 80, 3, -1, 3, 100;
  b.com = Vector3(0.02, -0.03, 0.05);
  b.mount = Pose::from_xyz_rpy(Vector3(0.6, 0.1, 0.4), Vector3(0.1, -0.2, 0.3));
  return b;
}

struct Sample {
  std::string file;
  UrdfOptions opt;
};

/// The samples with the options a user gives them (the same as tests/data/<robot>.toml).
std::vector<Sample> samples() {
  std::vector<Sample> s(3);
  s[0].file = "panda.urdf";
  s[0].opt.end_effector = "panda_hand";
  s[0].opt.end_effector_offset = Vector3(0, 0, 0.1034);
  s[1].file = "ur5_robot.urdf";
  s[1].opt.end_effector = "tool0";
  s[2].file = "kinova.urdf";
  s[2].opt.end_effector = "j2s6s200_end_effector";
  for (auto& x : s) x.opt.bus = test_bus();
  return s;
}

/// The masses as the file states them (each <inertial> in its own link frame), plus the bus: read
/// through urdfdom directly, not through the model's merged bodies.
std::vector<LinkMass> masses_of(const std::string& xml, const Bus& bus) {
  std::vector<LinkMass> links{{bus.name, Inertia{bus.mass, bus.com, bus.inertia}}};
  const urdf::ModelInterfaceSharedPtr u = urdf::parseURDF(xml);
  for (const auto& lp : u->links_)
    if (lp.second->inertial) links.push_back({lp.first, detail::urdf_inertia(*lp.second)});
  for (const auto& lp : u->links_) lp.second->child_links.clear();  // see model_from_urdf_string
  return links;
}

TestRobot load(const std::string& name, const std::string& xml, const UrdfOptions& opt,
               UrdfReport* rep = nullptr) {
  TestRobot r{name, model_from_urdf_string(xml, name, opt, rep), masses_of(xml, *opt.bus), -1};
  r.ee = r.model.end_effector();
  return r;
}

/// The dynamics identities, each to 1e-9 relative (rel_err: relative to max(1, |reference|)).
void check_identities(const TestRobot& r, unsigned seed) {
  Rng rng(seed);
  Data d(r.model);
  for (int k = 0; k < 2; ++k) {
    const Config q = random_config(r.model, rng, 1.0);
    VectorXd v(r.model.nv());
    v << rng.vec3(0.4), rng.vec3(0.3), rng.vec(r.model.n(), 1.0);
    INFO(r.name << " config " << k);
    const MatrixXd H = crba(r.model, d, q.base, q.theta);
    // H columns against RNEA with unit accelerations (body coordinates, no composites)
    const VectorXd zero = VectorXd::Zero(r.model.nv());
    for (int i = 0; i < r.model.nv(); ++i)
      CHECK(rel_err(VectorXd(rnea(r.model, d, q.base, q.theta, zero, VectorXd::Unit(r.model.nv(), i))),
                    VectorXd(H.col(i))) < 1e-9);
    // kinetic energy and momentum against sums over the file's masses, velocities by FD of FK
    const auto lv = fd_link_velocities(r, q, v, advance_library);
    crba(r.model, d, q.base, q.theta);
    const double T_fd = fd_kinetic_energy(r, lv);
    CHECK(std::abs(0.5 * v.dot(H * v) - T_fd) < 1e-9 * T_fd);
    CHECK(std::abs(kinetic_energy(r.model, d, v) - T_fd) < 1e-9 * T_fd);
    const Vector6 h_fd = fd_momentum(r, lv, q.base.position);
    CHECK(rel_err(Vector6((H * v).head<6>()), h_fd) < 1e-9);
    CHECK(rel_err(momentum(r.model, d, v), h_fd) < 1e-9);
    // J_f against FD of the end-effector along the zero-momentum motion it predicts
    const VectorXd theta_dot = rng.vec(r.model.n(), 1.0);
    const MatrixXd Jf = generalized_jacobian(r.model, d, q.base, q.theta, r.ee);
    VectorXd vz(r.model.nv());
    vz << base_velocity_from_momentum(r.model, d, theta_dot), theta_dot;
    const Vector6 xe = Jf * theta_dot;
    CHECK(rel_err(Vector6(fd_frame_jacobian(r, q, r.ee, advance_library) * vz), xe) < 1e-9);
    // ... and that motion carries no momentum: the FD body sum cancels to 1e-9 of the sum of the
    // bodies' momentum magnitudes (the FD error of each term is O(h^2) of that term; the bus's own
    // momentum is far larger than the arm's on a clamped base, so that is not the scale)
    const auto lz = fd_link_velocities(r, q, vz, advance_library);
    double scale = 0;
    for (size_t i = 0; i < lz.size(); ++i) {
      const Inertia& in = r.links[i].inertia;
      scale += in.mass * lz[i].vc.norm() * (1.0 + (lz[i].c - q.base.position).norm()) +
               (lz[i].R * in.I * lz[i].R.transpose() * lz[i].w).norm();
    }
    // plus the rounding floor of central differences: eps |p| / h of every position, times the mass
    // (500 kg bus a few metres from the origin: ~5e-8 kg m/s, measured residuals 6e-9 .. 3e-8)
    const double rounding =
        r.model.total_mass() * std::numeric_limits<double>::epsilon() * (q.base.position.norm() + 2.0) / 1e-5;
    CHECK(fd_momentum(r, lz, q.base.position).norm() < 1e-9 * scale + rounding);
  }
}

}  // namespace

TEST_CASE("real robot samples on a 500 kg bus: H, RNEA, energy, momentum, J_f", "[urdf][real]") {
  if (!have_samples()) return;
  unsigned seed = 101;
  for (const auto& s : samples()) {
    UrdfReport rep;
    const std::string xml = read_text(samples_dir() + "/" + s.file);
    const TestRobot r = load(s.file, xml, s.opt, &rep);
    INFO(s.file);
    CHECK(r.model.body(0).name == "bus");
    CHECK(rep.repairs.empty());  // these files need no repair at the default tolerance
    // the root and every link fixed to it are merged into the bus: total mass is the file's plus 500
    double m_file = 0;
    for (const auto& l : r.links) m_file += l.inertia.mass;
    CHECK(r.model.total_mass() == Approx(m_file).epsilon(1e-14));
    CHECK(!rep.merged_links.empty());
    check_identities(r, seed++);
  }
}

TEST_CASE("the samples: what the loader reports and the joints left", "[urdf][real]") {
  if (!have_samples()) return;
  auto s = samples();
  UrdfReport rep;
  const Model panda = model_from_urdf_file(samples_dir() + "/panda.urdf", s[0].opt, &rep);
  CHECK(panda.n() == 8);  // 7 arm joints + finger 1; finger 2 mimics it
  CHECK(panda.nb() == 10);
  REQUIRE(rep.mimics.size() == 1);
  CHECK(rep.mimics[0].joint == "panda_finger_joint2");
  CHECK(rep.mimics[0].leader == "panda_finger_joint1");
  CHECK(panda.joint_names().back() == "panda_finger_joint1");
  const Model ur5 = model_from_urdf_file(samples_dir() + "/ur5_robot.urdf", s[1].opt, &rep);
  CHECK(ur5.n() == 6);
  CHECK(std::find(rep.merged_links.begin(), rep.merged_links.end(), "world") != rep.merged_links.end());
  CHECK(std::find(rep.merged_links.begin(), rep.merged_links.end(), "base_link") != rep.merged_links.end());
  const Model kinova = model_from_urdf_file(samples_dir() + "/kinova.urdf", s[2].opt, &rep);
  CHECK(kinova.n() == 6);
  // without a bus the massless root stays an error, and it names the keys that mount it
  for (const char* f : {"ur5_robot.urdf", "kinova.urdf"}) {
    try {
      (void)model_from_urdf_file(samples_dir() + "/" + f);
      FAIL("loaded without a bus: " << f);
    } catch (const ModelError& e) {
      const std::string msg = e.what();
      CHECK(msg.find("bus-mass") != std::string::npos);
      CHECK(msg.find("mount-xyz") != std::string::npos);
    }
  }
}

TEST_CASE("mimic reduction: H, C, J_bm, M_ie gradient against the full model", "[urdf][real][mimic]") {
  if (!have_samples()) return;
  // the Panda's finger mimic with a non-trivial multiplier and offset
  std::string xml = read_text(samples_dir() + "/panda.urdf");
  const std::string tag = "<mimic joint=\"panda_finger_joint1\"/>";
  const size_t at = xml.find(tag);
  REQUIRE(at != std::string::npos);
  const double mult = -0.7, off = 0.01;
  const std::string reduced_xml = std::string(xml).replace(
      at, tag.size(), "<mimic joint=\"panda_finger_joint1\" multiplier=\"-0.7\" offset=\"0.01\"/>");
  const std::string full_xml = std::string(xml).replace(at, tag.size(), "");
  UrdfOptions opt = samples()[0].opt;
  opt.end_effector = "panda_leftfinger";  // on the leader's body: both fingers' motion matters
  const TestRobot red = load("panda reduced", reduced_xml, opt);
  const TestRobot full = load("panda full", full_xml, opt);
  REQUIRE(red.model.n() == 8);
  REQUIRE(full.model.n() == 9);
  // q_full = T q + c
  MatrixXd T = MatrixXd::Zero(9, 8);
  VectorXd c = VectorXd::Zero(9);
  const auto fn = full.model.joint_names(), rn = red.model.joint_names();
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 8; ++j)
      if (fn[static_cast<size_t>(i)] == rn[static_cast<size_t>(j)]) T(i, j) = 1.0;
  const int f2 = static_cast<int>(std::find(fn.begin(), fn.end(), "panda_finger_joint2") - fn.begin());
  const int f1 = static_cast<int>(std::find(rn.begin(), rn.end(), "panda_finger_joint1") - rn.begin());
  T(f2, f1) = mult;
  c(f2) = off;
  MatrixXd Tv = MatrixXd::Identity(15, 14);
  Tv.bottomRightCorner(9, 8) = T;

  check_identities(red, 202);  // the reduced model against FD of its own forward kinematics
  Rng rng(203);
  Data dr(red.model), df(full.model);
  const Target target = [] {
    Target t;
    t.mass = 200;
    t.inertia = Vector3(100, 120, 90).asDiagonal();
    t.attitude = Quaternion(rotation_from_rpy(Vector3(0.2, -0.1, 0.4)));
    t.contact_offset = Vector3(-0.25, 0.15, 0);
    t.normal = Vector3(1, 0, 0);
    return t;
  }();
  for (int k = 0; k < 2; ++k) {
    const Config q = random_config(red.model, rng, 1.0);
    const VectorXd qf = T * q.theta + c;
    VectorXd v(14);
    v << rng.vec3(0.4), rng.vec3(0.3), rng.vec(8, 1.0);
    INFO("config " << k);
    const MatrixXd Hr = crba(red.model, dr, q.base, q.theta);
    const MatrixXd Hf = crba(full.model, df, q.base, qf);
    CHECK(rel_err(Hr, MatrixXd(Tv.transpose() * Hf * Tv)) < 1e-9);
    const VectorXd Cr = bias_forces(red.model, dr, q.base, q.theta, v);
    const VectorXd Cf = bias_forces(full.model, df, q.base, qf, Tv * v);  // the follower's motion included
    CHECK(rel_err(Cr, VectorXd(Tv.transpose() * Cf)) < 1e-9);
    crba(red.model, dr, q.base, q.theta);
    crba(full.model, df, q.base, qf);
    const MatrixXd Jr = frame_jacobian(red.model, dr, red.ee);
    const MatrixXd Jfull = frame_jacobian(full.model, df, full.ee);
    CHECK(rel_err(Jr, MatrixXd(Jfull * Tv)) < 1e-9);
    // M_ie of the constrained system from the full model's H and J at q_full = T q + c: the
    // follower's motion is T's, so H_r = T^T H T and J_r = J T (Eq. 4 and 14 with those)
    const Vector3 u = target.normal_world();
    auto M_from_full = [&](const VectorXd& theta) {
      crba(full.model, df, q.base, T * theta + c);
      const MatrixXd Jv = MatrixXd(frame_jacobian(full.model, df, full.ee)).topRows(3) * Tv;
      const MatrixXd Hred = Tv.transpose() * df.H * Tv;
      return 1.0 / (u.dot(Jv * Hred.llt().solve(Jv.transpose() * u)) + target.inverse_mass_along_normal());
    };
    VectorXd grad(8);
    const double M = integrated_effective_mass_gradient_dense(red.model, dr, q.base, q.theta, red.ee, u,
                                                              target.inverse_mass_along_normal(), grad);
    CHECK(M == Approx(M_from_full(q.theta)).epsilon(1e-12));
    // its gradient against central differences of that (h = 1e-5: truncation ~1e-10 relative)
    const double h = 1e-5;
    VectorXd fd(8);
    for (int j = 0; j < 8; ++j) {
      const VectorXd e = VectorXd::Unit(8, j) * h;
      fd(j) = (M_from_full(q.theta + e) - M_from_full(q.theta - e)) / (2 * h);
    }
    CHECK((grad - fd).cwiseAbs().maxCoeff() < 1e-9 * std::max(1.0, fd.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("mimic chains resolve -- loops and unknown leaders are ModelErrors naming the joints",
          "[model][mimic]") {
  Rng rng(301);
  auto inertia = [&](double m) { return Inertia{m, rng.vec3(0.3), rng.inertia(0.05 * m)}; };
  auto pose = [&] { return Pose::from_xyz_rpy(rng.vec3(0.6), rng.vec3(M_PI)); };
  const Inertia trunk = inertia(300);
  TestRobot r;
  r.name = "mimic chain";
  r.links.push_back({"trunk", trunk});
  ModelBuilder b("trunk", trunk);
  auto add = [&](const char* joint, JointType type, const char* parent, const char* child, double m) {
    const Inertia in = inertia(m);
    b.add_joint(joint, type, parent, pose(), rng.unit(), child, in);
    r.links.push_back({child, in});
  };
  add("j1", JointType::Revolute, "trunk", "l1", 10);
  add("j2", JointType::Revolute, "l1", "l2", 8);     // mimics j4 (declared before its leader)
  add("j3", JointType::Prismatic, "l2", "l3", 6);    // mimics j2: a chain j3 -> j2 -> j4
  add("j4", JointType::Revolute, "trunk", "l4", 5);  // another branch
  add("j5", JointType::Revolute, "l3", "l5", 4);
  b.set_mimic("j3", "j2", -0.3, 0.05).set_mimic("j2", "j4", 1.5, 0.2);
  b.set_end_effector("l5");
  r.model = b.build();
  r.ee = r.model.end_effector();
  REQUIRE(r.model.n() == 3);
  CHECK(r.model.joint_names() == std::vector<std::string>{"j1", "j4", "j5"});
  const Body& b3 = r.model.body(3);
  CHECK(b3.leader == "j4");
  CHECK(b3.multiplier == Approx(-0.45).epsilon(1e-15));  // -0.3 * 1.5
  CHECK(b3.offset == Approx(-0.3 * 0.2 + 0.05).epsilon(1e-15));
  check_identities(r, 302);

  ModelBuilder loop("base", Inertia{10, Vector3::Zero(), Matrix3::Identity()});
  loop.add_joint("a", JointType::Revolute, "base", Pose{}, Vector3::UnitZ(), "la",
                 Inertia{1, Vector3::Zero(), Matrix3::Identity()});
  loop.add_joint("b", JointType::Revolute, "la", Pose{}, Vector3::UnitZ(), "lb",
                 Inertia{1, Vector3::Zero(), Matrix3::Identity()});
  ModelBuilder unknown = loop;
  loop.set_mimic("a", "b", 1, 0).set_mimic("b", "a", 1, 0);
  CHECK_THROWS_WITH(loop.build(),
                    Catch::Contains("loop") && Catch::Contains("'a'") && Catch::Contains("'b'"));
  unknown.set_mimic("b", "ghost", 1, 0);
  CHECK_THROWS_WITH(unknown.build(), Catch::Contains("'b'") && Catch::Contains("'ghost'"));
  CHECK_THROWS_AS(unknown.build(), ModelError);
}

TEST_CASE("the tests/data mimic file loads: the follower moves with its leader", "[urdf][mimic]") {
  const Model m = model_from_urdf_file(source_path("tests/data/mimic_joint.urdf"));
  REQUIRE(m.n() == 1);
  REQUIRE(m.nb() == 3);
  Data d(m);
  VectorXd th(1);
  th << 0.3;
  forward_kinematics(m, d, BasePose{}, th);
  // link2 turns by 2 * 0.3 relative to link1: its world yaw is 0.3 + 0.6 (closed form, planar)
  const Matrix3 R2 = frame_pose(m, d, m.frame_index("link2")).R;
  CHECK(std::atan2(R2(1, 0), R2(0, 0)) == Approx(0.9).epsilon(1e-14));
}

TEST_CASE("locked joints: removed from the coordinates, the same system as the full model",
          "[urdf][real][lock]") {
  if (!have_samples()) return;
  const std::string path = samples_dir() + "/ur5_robot.urdf";
  UrdfOptions opt = samples()[1].opt;
  const Model full = model_from_urdf_file(path, opt);
  opt.locks = {{"elbow_joint", 0.5}};
  UrdfReport rep;
  const Model locked = model_from_urdf_file(path, opt, &rep);
  REQUIRE(locked.n() == 5);
  REQUIRE(rep.locked.size() == 1);
  const auto names = locked.joint_names();
  CHECK(std::find(names.begin(), names.end(), "elbow_joint") == names.end());
  Rng rng(401);
  const VectorXd q5 = rng.vec(5, 1.0);
  VectorXd q6(6);
  q6 << q5.head(2), 0.5, q5.tail(3);  // elbow_joint is the third joint of the chain
  const BasePose base = rng.base_pose();
  Data dl(locked), df(full);
  Target t;
  t.mass = 200;
  t.inertia = Matrix3::Identity() * 100;
  t.normal = Vector3(0, 1, 0);
  const double Ml = integrated_effective_mass(locked, dl, base, q5, locked.end_effector(), t);
  // the full model with the elbow held: M_ie from H with the elbow row and column removed (a locked
  // joint takes no velocity), computed from the full model's H and J
  crba(full, df, base, q6);
  frame_jacobian(full, df, full.end_effector());
  std::vector<int> keep{0, 1, 2, 3, 4, 5, 6, 7, 9, 10, 11};
  MatrixXd H(11, 11), J(3, 11);
  for (int i = 0; i < 11; ++i) {
    J.col(i) = df.J.block(0, keep[static_cast<size_t>(i)], 3, 1);
    for (int j = 0; j < 11; ++j) H(i, j) = df.H(keep[static_cast<size_t>(i)], keep[static_cast<size_t>(j)]);
  }
  const Vector3 u = t.normal_world();
  const double inv_me = u.dot(J * H.ldlt().solve(J.transpose() * u));
  CHECK(Ml == Approx(1.0 / (inv_me + t.inverse_mass_along_normal())).epsilon(1e-12));
  CHECK(
      (frame_pose(locked, dl, locked.end_effector()).p - frame_pose(full, df, full.end_effector()).p).norm() <
      1e-12);
  // a locked leader locks its mimic follower
  UrdfOptions po = samples()[0].opt;
  po.locks = {{"panda_finger_joint1", 0.02}};
  UrdfReport prep;
  const Model panda = model_from_urdf_file(samples_dir() + "/panda.urdf", po, &prep);
  CHECK(panda.n() == 7);
  CHECK(prep.locked.size() == 2);
  CHECK(panda.nb() == 8);
}

TEST_CASE("mount invariance: moving the bus frame, compensated, changes neither M_ie nor the end-effector",
          "[urdf][real]") {
  if (!have_samples()) return;
  const std::string path = samples_dir() + "/kinova.urdf";
  UrdfOptions a = samples()[2].opt;
  // the same bus described from a frame D away: bus frame B = A * D
  const Pose D = Pose::from_xyz_rpy(Vector3(0.3, -0.2, 0.15), Vector3(0.4, 0.1, -0.6));
  const Pose Dinv{-D.R.transpose() * D.p, D.R.transpose()};
  UrdfOptions b = a;
  b.bus->com = Dinv.R * a.bus->com + Dinv.p;
  b.bus->inertia = D.R.transpose() * a.bus->inertia * D.R;
  b.bus->mount = Dinv * a.bus->mount;
  const Model ma = model_from_urdf_file(path, a), mb = model_from_urdf_file(path, b);
  Rng rng(501);
  Data da(ma), db(mb);
  Target t;
  t.mass = 300;
  t.inertia = Vector3(80, 100, 120).asDiagonal();
  t.normal = Vector3(0.6, 0, 0.8);
  for (int k = 0; k < 3; ++k) {
    const BasePose base_a = rng.base_pose();
    const Pose A{base_a.position, base_a.orientation.toRotationMatrix()};
    const Pose B = A * D;
    const BasePose base_b{B.p, Quaternion(B.R)};
    const VectorXd th = rng.vec(6, 1.5);
    const double Ma = integrated_effective_mass(ma, da, base_a, th, ma.end_effector(), t);
    const double Mb = integrated_effective_mass(mb, db, base_b, th, mb.end_effector(), t);
    CHECK(Mb == Approx(Ma).epsilon(1e-12));
    CHECK((frame_pose(ma, da, ma.end_effector()).p - frame_pose(mb, db, mb.end_effector()).p).norm() < 1e-12);
  }
}

TEST_CASE("end-effector offset: the contact point where the fingers close", "[urdf][real]") {
  if (!have_samples()) return;
  // panda_hand + (0, 0, 0.1034) is where the file's own panda_hand_tcp frame is
  const std::string path = samples_dir() + "/panda.urdf";
  UrdfOptions with_offset = samples()[0].opt, tcp = with_offset;
  tcp.end_effector = "panda_hand_tcp";
  tcp.end_effector_offset.reset();
  const Model mo = model_from_urdf_file(path, with_offset), mt = model_from_urdf_file(path, tcp);
  CHECK(mo.frame(mo.end_effector()).name == "panda_hand_contact");
  Rng rng(601);
  Data d1(mo), d2(mt);
  Target t;
  t.mass = 200;
  t.inertia = Matrix3::Identity() * 100;
  t.normal = rng.unit();
  for (int k = 0; k < 2; ++k) {
    const BasePose base = rng.base_pose();
    const VectorXd th = rng.vec(8, 1.0);
    VectorXd g1(8), g2(8);
    const double M1 = integrated_effective_mass_gradient_dense(
        mo, d1, base, th, mo.end_effector(), t.normal_world(), t.inverse_mass_along_normal(), g1);
    const double M2 = integrated_effective_mass_gradient_dense(
        mt, d2, base, th, mt.end_effector(), t.normal_world(), t.inverse_mass_along_normal(), g2);
    CHECK(M1 == Approx(M2).epsilon(1e-12));
    CHECK((g1 - g2).cwiseAbs().maxCoeff() < 1e-12 * std::max(1.0, g2.cwiseAbs().maxCoeff()));
    const MatrixXd J1 = generalized_jacobian(mo, d1, base, th, mo.end_effector());
    const MatrixXd J2 = generalized_jacobian(mt, d2, base, th, mt.end_effector());
    CHECK(rel_err(J1, J2) < 1e-12);
    CHECK((frame_pose(mo, d1, mo.end_effector()).p - frame_pose(mt, d2, mt.end_effector()).p).norm() < 1e-12);
  }
  UrdfOptions bad = with_offset;
  bad.end_effector_offset = Vector3(0, std::nan(""), 0);
  CHECK_THROWS_WITH(model_from_urdf_file(path, bad), Catch::Contains("end-effector-offset"));
}

namespace {
/// A two-link arm whose link 'odd' breaks the triangle inequality (principal moments 0.1, 0.2, 0.5)
/// and whose link 'tiny' weighs 1e-9 kg.
const char* kOddUrdf = R"(<robot name="odd">
  <link name="base"><inertial><mass value="100"/><inertia ixx="10" ixy="0" ixz="0" iyy="10" iyz="0" izz="10"/></inertial></link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="odd"/><axis xyz="0 0 1"/></joint>
  <link name="odd"><inertial><mass value="2"/><origin rpy="0.3 0.2 0.1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.5"/></inertial></link>
  <joint name="j2" type="continuous"><parent link="odd"/><child link="tiny"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
  <link name="tiny"><inertial><mass value="1e-9"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
</robot>)";
}  // namespace

TEST_CASE(
    "inertia repairs: an error naming the link and the option by default -- balance and bounds when asked",
    "[urdf][repair]") {
  CHECK_THROWS_WITH(
      model_from_urdf_string(kOddUrdf, "odd.urdf", UrdfOptions{}),
      Catch::Contains("odd.urdf") && Catch::Contains("'odd'") && Catch::Contains("inertia-repair"));
  UrdfOptions o;
  o.inertia_repair = InertiaRepair::Balance;
  o.min_mass = 1e-3;
  UrdfReport rep;
  const Model m = model_from_urdf_string(kOddUrdf, "odd.urdf", o, &rep);
  REQUIRE(rep.repairs.size() == 2);
  CHECK(rep.repairs[0].link == "odd");
  // deficit 0.5 - 0.3 = 0.2 shared by the two smaller moments: (0.2, 0.3, 0.5), on the boundary
  const std::vector<double> after = rep.repairs[0].after;
  CHECK(after[0] == Approx(0.2).epsilon(1e-12));
  CHECK(after[1] == Approx(0.3).epsilon(1e-12));
  CHECK(after[2] == Approx(0.5).epsilon(1e-12));
  Eigen::SelfAdjointEigenSolver<Matrix3> es(m.body(1).inertia.I);
  CHECK(es.eigenvalues()(2) == Approx(es.eigenvalues()(0) + es.eigenvalues()(1)).epsilon(1e-12));
  CHECK(rep.repairs[1].link == "tiny");
  CHECK(rep.repairs[1].before == std::vector<double>{1e-9});
  CHECK(m.body(2).inertia.mass == 1e-3);
  // the paper robots need no repair and get none
  for (const char* f : {"robots/paper_3dof.urdf", "robots/paper_7dof.urdf"}) {
    UrdfReport none;
    (void)model_from_urdf_file(source_path(f), o, &none);
    CHECK(none.repairs.empty());
  }
  CHECK_THROWS_WITH(parse_inertia_repair("average"),
                    Catch::Contains("inertia-repair") && Catch::Contains("average"));
}

TEST_CASE("bad bus and lock options: one error naming the key", "[urdf][real]") {
  if (!have_samples()) return;
  const std::string path = samples_dir() + "/panda.urdf";
  auto error_of = [&](const UrdfOptions& o) -> std::string {
    try {
      (void)model_from_urdf_file(path, o);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  UrdfOptions o = samples()[0].opt;
  o.bus->mass = 0;
  CHECK_THAT(error_of(o), Catch::Contains("bus-mass"));
  o = samples()[0].opt;
  o.bus->inertia = Vector3(1, 1, 5).asDiagonal();
  CHECK_THAT(error_of(o), Catch::Contains("bus-inertia") && Catch::Contains("triangle"));
  o = samples()[0].opt;
  o.locks = {{"panda_joint9", 0.1}};
  CHECK_THAT(error_of(o), Catch::Contains("lock-joints") && Catch::Contains("panda_joint9") &&
                              Catch::Contains("panda_joint1"));
  o.locks = {{"panda_hand_joint", 0.0}};
  CHECK_THAT(error_of(o), Catch::Contains("lock-joints") && Catch::Contains("fixed"));
  o.locks = {{"panda_joint4", 0.5}};  // limits [-3.0718, -0.0698]
  CHECK_THAT(error_of(o), Catch::Contains("lock-joints") && Catch::Contains("outside"));
}

// ------------------------------------------------------------------------------------------------
// the command: a capture scenario per robot, and the keys' bad inputs
// ------------------------------------------------------------------------------------------------

TEST_CASE("ffsr-optimize runs a capture scenario on each sample (tests/data/<robot>.toml)", "[cli][real]") {
  if (!have_samples()) return;
  for (const char* robot : {"panda", "ur5", "kinova"}) {
    ffsr::test::TempDir tmp;
    const std::string json_path = tmp.str() + "/out.json";
    const auto r = ffsr::test::run_command(
        {FFSR_CLI, "--config", source_path(std::string("tests/data/") + robot + ".toml"), "--urdf",
         samples_dir() + "/" + (std::string(robot) == "ur5" ? "ur5_robot" : robot) + ".urdf", "--json",
         json_path, "--quiet"},
        tmp.str());
    INFO(robot << "\nstdout: " << r.out << "\nstderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(r.err.empty());  // no repair warnings for these files
    std::ifstream in(json_path);
    const nlohmann::json j = nlohmann::json::parse(in);
    CHECK(j["model_repairs"].empty());
    CHECK(j["scenario"]["bus-mass"] == 500.0);
    const double tol = j["scenario"]["tolerance"].get<double>();
    CHECK(j["optimized"]["capture_distance"].get<double>() <= tol);
    CHECK(j["optimized"]["max_total_momentum"].get<double>() < 1e-6);
  }
}

TEST_CASE("ffsr-optimize inspect: what was done to the file, and bad keys", "[cli][real]") {
  if (!have_samples()) return;
  const std::string panda = samples_dir() + "/panda.urdf";
  const std::vector<std::string> base{
      FFSR_CLI,         "inspect",    "--urdf",       panda,
      "--end-effector", "panda_hand", "--joints-deg", "0,-30,0,-120,0,90,45,0.02"};
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    ffsr::test::TempDir tmp;
    return ffsr::test::run_command(a, tmp.str());
  };
  const auto ok = run({"--bus-mass", "500", "--bus-inertia", "90,80,100", "--mount-xyz", "0.6,0,0.4",
                       "--end-effector-offset", "0,0,0.1034"});
  INFO(ok.err);
  REQUIRE(ok.exit_code == 0);
  CHECK(ok.out.find("merged into base") != std::string::npos);
  CHECK(ok.out.find("panda_finger_joint2 = 1 * panda_finger_joint1 + 0") != std::string::npos);
  struct Bad {
    std::vector<std::string> args;
    std::string must_name;
  };
  const std::vector<Bad> bad = {
      {{"--bus-mass", "0", "--bus-inertia", "90,80,100"}, "--bus-mass"},
      {{"--bus-mass", "-5", "--bus-inertia", "90,80,100"}, "--bus-mass"},
      {{"--bus-mass", "500", "--bus-inertia", "1,1,5"}, "bus-inertia"},
      {{"--mount-xyz", "0.6,0,0.4"}, "--mount-xyz"},
      {{"--bus-mass", "500", "--bus-inertia", "90,80,100", "--lock-joints", "nonexistent=0"}, "nonexistent"},
      {{"--bus-mass", "500", "--bus-inertia", "90,80,100", "--lock-joints", "panda_joint8=0"},
       "panda_joint8"},
      {{"--bus-mass", "500", "--bus-inertia", "90,80,100", "--lock-joints", "panda_joint4=0.5"},
       "panda_joint4"},
      {{"--bus-mass", "500", "--bus-inertia", "90,80,100", "--inertia-repair", "average"},
       "--inertia-repair"},
      {{"--bus-mass", "500", "--bus-inertia", "90,80,100", "--end-effector-offset", "0,0"},
       "--end-effector-offset"},
      {{"--bus-mass", "500", "--bus-inertia", "90,80,100", "--end-effector-offset", "0,nan,0"},
       "--end-effector-offset"},
      {{"--bus-mass", "500", "--bus-inertia", "90,80,100", "--lock-joints", "panda_joint7=0.1"},
       "panda_finger_joint1"},
  };
  for (const auto& b : bad) {
    const auto r = run(b.args);
    std::string joined;
    for (const auto& a : b.args) joined += a + " ";
    INFO(joined << "\nstderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.out.empty());
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.rfind("ffsr-optimize: error:", 0) == 0);
    CHECK(r.err.find(b.must_name) != std::string::npos);
    std::cout << "  " << joined << "\n    -> " << r.err;
  }
}

}  // namespace test_real_robots
