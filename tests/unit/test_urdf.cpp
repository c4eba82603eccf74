// tests/test_urdf.cpp -- the URDF loader: bad files rejected with a clear message, good files read
// as written (fixed-child merging, prismatic joints, joint order, end-effector, gravity).
#include "support/dynamics_helpers.hpp"

#include <catch2/catch.hpp>

#include <cstdio>
#include <tuple>
#include <fcntl.h>
#include <unistd.h>

namespace test_urdf {

using namespace ffsr;
using namespace ffsr_test;

namespace {

/// Redirects the process's stdout and stderr (file descriptors 1 and 2) to a temporary file while
/// alive; text() returns what was written. The library never prints: urdfdom's console_bridge output
/// must end up in the exception message, not on the terminal.
class CaptureOutput {
 public:
  CaptureOutput() : file_(std::tmpfile()) {
    std::fflush(stdout);
    std::fflush(stderr);
    saved_out_ = dup(1);
    saved_err_ = dup(2);
    dup2(fileno(file_), 1);
    dup2(fileno(file_), 2);
  }
  std::string text() {
    restore();
    std::string s;
    std::rewind(file_);
    for (int c; (c = std::fgetc(file_)) != EOF;) s += static_cast<char>(c);
    return s;
  }
  ~CaptureOutput() {
    restore();
    std::fclose(file_);
  }
  CaptureOutput(const CaptureOutput&) = delete;
  CaptureOutput& operator=(const CaptureOutput&) = delete;

 private:
  void restore() {
    if (saved_out_ < 0) return;
    std::fflush(stdout);
    std::fflush(stderr);
    dup2(saved_out_, 1);
    dup2(saved_err_, 2);
    close(saved_out_);
    close(saved_err_);
    saved_out_ = saved_err_ = -1;
  }
  std::FILE* file_;
  int saved_out_ = -1, saved_err_ = -1;
};

enum class Kind { Model, Input };

struct BadFile {
  const char* file;
  Kind kind;
  std::vector<std::string> must_mention;  ///< the element's name and what is wrong
};

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// The message of the ModelError that loading `xml` (as file `name`) throws; fails when none is thrown.
std::string model_error(const std::string& xml, const std::string& name) {
  try {
    (void)model_from_urdf_string(xml, name);
  } catch (const ModelError& e) {
    return e.what();
  }
  FAIL("no exception");
  return {};
}

}  // namespace

TEST_CASE("malformed or unphysical URDF files are rejected with a message naming file and element",
          "[urdf]") {
  const std::vector<BadFile> cases{
      {"not_xml.urdf", Kind::Model, {"malformed URDF"}},
      {"empty.urdf", Kind::Model, {"malformed URDF"}},
      {"no_robot_element.urdf", Kind::Model, {"'robot' element"}},
      {"two_roots.urdf", Kind::Model, {"floating_island", "root"}},
      {"closed_loop.urdf", Kind::Model, {"loop_link", "joint_a", "joint_b", "closed loop"}},
      {"floating_joint.urdf", Kind::Model, {"free_joint", "unsupported joint type"}},
      {"planar_joint.urdf", Kind::Model, {"slide_plane", "unsupported joint type"}},
      {"zero_mass_moving_link.urdf", Kind::Model, {"massless_arm", "mass must be positive"}},
      {"moving_link_without_inertial.urdf", Kind::Model, {"no_inertial_arm", "mass must be positive"}},
      {"negative_mass.urdf", Kind::Model, {"antimatter", "mass must be positive"}},
      {"negative_mass_fixed_child.urdf", Kind::Model, {"negative_tool", "mass must be positive"}},
      {"negative_moment.urdf", Kind::Model, {"negative_moment_link", "positive semi-definite"}},
      {"indefinite_inertia.urdf", Kind::Model, {"indefinite_link", "positive semi-definite"}},
      {"triangle_inequality.urdf", Kind::Model, {"impossible_link", "triangle inequality"}},
      {"zero_axis.urdf", Kind::Model, {"pointless_joint", "axis"}},
      {"nan_origin.urdf", Kind::Model, {"nan_joint", "nan"}},
      {"inf_mass.urdf", Kind::Model, {"heavy_link", "inf"}},
      {"unparseable_inertia.urdf", Kind::Model, {"typo_link", "ixx"}},
      {"unknown_parent_link.urdf", Kind::Model, {"ghost_link", "orphan_joint"}},
      {"revolute_without_limits.urdf", Kind::Model, {"unlimited_joint", "limits"}},
      {"mimic_loop.urdf", Kind::Model, {"copy_joint", "joint1", "loop"}},
      {"mimic_unknown_leader.urdf", Kind::Model, {"copy_joint", "phantom_joint"}},
      {"zero_mass_base.urdf", Kind::Model, {"weightless_base", "mass must be positive"}},
      {"no_moving_joint.urdf", Kind::Model, {"no moving joint"}},
      {"inverted_limits.urdf", Kind::Model, {"inverted_slider", "lower <= upper"}},
      {"duplicate_link.urdf", Kind::Model, {"twin_link", "not unique"}},
      {"two_leaves.urdf", Kind::Input, {"left_hand", "right_hand", "ambiguous"}},
  };
  CHECK(cases.size() >= 18);
  for (const auto& c : cases) {
    const std::string path = source_path(std::string("tests/data/bad_urdf/") + c.file);
    INFO(path);
    std::string message, kind = "no exception";
    CaptureOutput out;
    try {
      (void)model_from_urdf_file(path);
    } catch (const ModelError& e) {
      kind = "ModelError";
      message = e.what();
    } catch (const InputError& e) {
      kind = "InputError";
      message = e.what();
    } catch (const std::exception& e) {
      kind = std::string("another exception: ") + e.what();
    }
    const std::string printed = out.text();
    INFO("message: " << message);
    CHECK(kind == (c.kind == Kind::Model ? "ModelError" : "InputError"));
    CHECK(contains(message, path));
    for (const auto& part : c.must_mention) CHECK(contains(message, part));
    CHECK(printed.empty());  // nothing on the terminal: urdfdom's log goes into the message
  }
}

TEST_CASE("a closed loop is reported as such whatever the order of its joints", "[urdf]") {
  // urdfdom keeps only one parent joint of a link with two: the error must not depend on which.
  const std::string links = R"(<?xml version="1.0"?><robot name="loop">
    <link name="base"><inertial><mass value="10"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <link name="l2"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>)";
  const std::string xml = links + R"(
    <joint name="z_first" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
    <joint name="a_second" type="continuous"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/></joint>
    <joint name="m_back" type="continuous"><parent link="l2"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  </robot>)";
  // a loop detached from the base: every link in it has one parent, so it is found as links the
  // root does not reach (and urdfdom's cycle of shared_ptrs must not leak: run under ASan)
  const std::string detached = links + R"(
    <joint name="there" type="continuous"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/></joint>
    <joint name="back" type="continuous"><parent link="l2"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  </robot>)";
  // each message names the file and the links (and, for the attached loop, says what it is)
  const std::vector<std::tuple<std::string, std::string, std::vector<std::string>>> cases{
      {xml, "loop.urdf", {"loop.urdf", "'l1'", "closed loop"}}, {detached, "detached.urdf", {"detached.urdf", "l1", "l2"}}};
  for (const auto& [text, file, parts] : cases) {
    const std::string m = model_error(text, file);
    INFO(m);
    for (const auto& part : parts) CHECK(contains(m, part));
  }
}

TEST_CASE("end-effector names and missing files", "[urdf]") {
  const std::string path = source_path("robots/paper_3dof.urdf");
  SECTION("an unknown end-effector name is an InputError listing the frames") {
    try {
      (void)model_from_urdf_file(path, "gripper");
      FAIL("no exception");
    } catch (const InputError& e) {
      const std::string m = e.what();
      INFO(m);
      CHECK(contains(m, path));
      CHECK(contains(m, "gripper"));
      for (const char* f : {"base", "link1", "link2", "link3", "ee"}) CHECK(contains(m, f));
    }
  }
  SECTION("a named end-effector is used; an inner link is allowed") {
    const Model m = model_from_urdf_file(path, "link2");
    CHECK(m.frame(m.end_effector()).name == "link2");
  }
  SECTION("a missing file is a ModelError naming the path") {
    const std::string missing = source_path("tests/data/bad_urdf/does_not_exist.urdf");
    try {
      (void)model_from_urdf_file(missing);
      FAIL("no exception");
    } catch (const ModelError& e) {
      CHECK(contains(e.what(), missing));
    }
  }
}

TEST_CASE("a thin rod's zero axial moment is valid", "[urdf]") {
  // m = 3, L = 2: (0, m L^2/12, m L^2/12) = (0, 1, 1)
  const Model m = model_from_urdf_file(source_path("tests/data/thin_rod.urdf"));
  CHECK(m.n() == 1);
  CHECK((m.body(1).inertia.I - Matrix3(Vector3(0, 1, 1).asDiagonal())).cwiseAbs().maxCoeff() == 0.0);
  CHECK(m.frame(m.end_effector()).name == "rod");  // the single leaf
  // and the same in code
  CHECK_NOTHROW(ModelBuilder("b", {10, Vector3::Zero(), Matrix3::Identity()})
                    .add_joint("j", JointType::Revolute, "b", Pose{}, Vector3::UnitZ(), "rod",
                               {3, Vector3(1, 0, 0), Matrix3(Vector3(0, 1, 1).asDiagonal())})
                    .build());
}

TEST_CASE("a fixed child merges its mass: same H as the robot built in code", "[urdf]") {
  const Model from_file = model_from_urdf_file(source_path("tests/data/fixed_child_merge.urdf"));
  // The same robot in code, the merge worked out here (parallel-axis theorem), not by the builder.
  auto inertial = [](double m, const Vector3& xyz, const Vector3& rpy, const Matrix3& I) {
    const Matrix3 R = rotation_from_rpy(rpy);
    return Inertia{m, xyz, R * I * R.transpose()};
  };
  Matrix3 I_arm;
  I_arm << 0.05, 0.01, 0, 0.01, 0.4, 0.02, 0, 0.02, 0.42;
  const Inertia arm = inertial(6, {0.4, 0, 0.05}, {0.3, -0.2, 0.5}, I_arm);
  const Inertia tool_own = inertial(2, {0.05, 0.02, 0}, {0, 0, 0.7}, Vector3(0.01, 0.02, 0.025).asDiagonal());
  const Pose X_tool = Pose::from_xyz_rpy({0.8, 0, 0.1}, {0, 0.5, 0});  // tool frame in arm frame
  const Vector3 c_tool = X_tool.p + X_tool.R * tool_own.com;
  const Matrix3 I_tool = X_tool.R * tool_own.I * X_tool.R.transpose();
  const double m = arm.mass + tool_own.mass;
  const Vector3 c = (arm.mass * arm.com + tool_own.mass * c_tool) / m;
  auto shift = [](double mk, const Vector3& d) {
    return Matrix3(mk * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose()));
  };
  const Inertia merged{m, c,
                       arm.I + shift(arm.mass, arm.com - c) + I_tool + shift(tool_own.mass, c_tool - c)};

  const Model in_code =
      ModelBuilder("base", {200, {0.1, 0, 0}, Vector3(50, 60, 70).asDiagonal()})
          .add_joint("shoulder", JointType::Revolute, "base",
                     Pose::from_xyz_rpy({0.3, 0.1, 0.2}, {0.1, 0.2, 0.3}), Vector3(0, 1, 1), "arm", merged)
          .add_joint("wrist", JointType::Revolute, "arm",
                     X_tool * Pose::from_xyz_rpy({0.1, 0, 0}, {0.4, 0, 0}), Vector3::UnitX(), "hand",
                     {1.5, {0.1, 0, 0}, Vector3(0.002, 0.006, 0.006).asDiagonal()})
          .add_fixed("ee_mount", "hand", Pose{{0.2, 0, 0}, Matrix3::Identity()}, "ee", Inertia{})
          .build();

  CHECK(from_file.n() == 2);
  CHECK(from_file.joint_names() == std::vector<std::string>{"shoulder", "wrist"});
  CHECK(from_file.total_mass() == Approx(200 + 6 + 2 + 1.5).epsilon(1e-15));
  CHECK(from_file.frame(from_file.frame_index("tool")).body == 1);  // the tool frame rides on arm
  CHECK(from_file.frame(from_file.end_effector()).name == "ee");
  CHECK(from_file.body(1).joint.lower == -2.0);
  CHECK(from_file.body(1).joint.upper == 2.0);

  Rng rng(31);
  Data d1(from_file), d2(in_code);
  for (int k = 0; k < 4; ++k) {
    const BasePose base = rng.base_pose();
    const Eigen::VectorXd theta = rng.vec(2, 2.0);
    INFO("config " << k);
    // same robot, two routes: rounding only, 1e-12 relative
    CHECK(rel_err(MatrixXd(crba(from_file, d1, base, theta)), MatrixXd(crba(in_code, d2, base, theta))) <
          1e-12);
    CHECK((frame_pose(from_file, d1, from_file.end_effector()).p -
           frame_pose(in_code, d2, in_code.end_effector()).p)
              .norm() < 1e-12);
  }
}

TEST_CASE("a prismatic joint moves its child along the normalized axis", "[urdf]") {
  const Model m = model_from_urdf_file(source_path("tests/data/prismatic.urdf"));
  REQUIRE(m.n() == 2);
  CHECK(m.body(1).joint.type == JointType::Prismatic);
  CHECK(m.body(1).joint.lower == -0.5);
  CHECK(m.body(1).joint.upper == 1.5);
  CHECK(m.body(2).joint.type == JointType::Revolute);
  Data d(m);
  Rng rng(32);
  const BasePose base = rng.base_pose();
  const Matrix3 R0 = base.orientation.toRotationMatrix();
  for (double s : {-0.4, 0.0, 0.7, 1.3}) {
    forward_kinematics(m, d, base, Eigen::Vector2d(s, 0.3));
    // joint origin (0.2, 0, 0.3) rpy (0, 0, 0.5); axis (0, 0, 2) normalized = z of the joint frame,
    // which the yaw leaves unchanged: the carriage origin is at (0.2, 0, 0.3 + s) in the base frame
    CHECK((d.p[1] - (base.position + R0 * Vector3(0.2, 0, 0.3 + s))).norm() < 1e-12);
    CHECK((d.R[1] - R0 * rotation_from_rpy({0, 0, 0.5})).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("joints are ordered depth-first, siblings in file order", "[urdf]") {
  const Model m = model_from_urdf_file(source_path("tests/data/sibling_order.urdf"), "zz");
  CHECK(m.joint_names() ==
        std::vector<std::string>{"zulu_joint", "mike_joint", "alpha_joint", "bravo_joint"});
  CHECK(m.body(0).name == "base");  // the root, although listed third
  CHECK(m.body(1).name == "z");
  CHECK(m.body(2).name == "zz");
  CHECK(m.body(2).parent == 1);
  CHECK(m.body(3).name == "a");
  CHECK(m.body(4).name == "b");
  CHECK(m.body(4).parent == 0);
}

TEST_CASE("gravity is zero by default", "[urdf]") {
  for (const char* f :
       {"robots/paper_3dof.urdf", "robots/paper_7dof.urdf", "tests/data/fixed_child_merge.urdf"})
    CHECK(model_from_urdf_file(source_path(f)).gravity == Vector3::Zero());
  CHECK(ModelBuilder("b", {1, Vector3::Zero(), Matrix3::Identity()})
            .add_joint("j", JointType::Revolute, "b", Pose{}, Vector3::UnitZ(), "l",
                       {1, Vector3::Zero(), Matrix3::Identity()})
            .build()
            .gravity == Vector3::Zero());
}

TEST_CASE("bad trees built in code", "[urdf]") {
  const Inertia ok{1, Vector3::Zero(), Matrix3::Identity()};
  auto base = [&] { return ModelBuilder("b", {10, Vector3::Zero(), Matrix3::Identity()}); };
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const ModelError& e) {
      return std::string("ModelError: ") + e.what();
    } catch (const InputError& e) {
      return std::string("InputError: ") + e.what();
    }
    return "no exception";
  };
  const double inf = std::numeric_limits<double>::infinity();
  CHECK(contains(message([&] {
                   base().add_joint("j", JointType::Revolute, "b", Pose{}, Vector3::UnitZ(), "big",
                                    {inf, Vector3::Zero(), Matrix3::Identity()});
                 }),
                 "ModelError: link 'big': inertial values must be finite"));
  CHECK(contains(
      message([&] { base().add_joint("j", JointType::Revolute, "b", Pose{}, Vector3::Zero(), "l", ok); }),
      "ModelError: joint 'j': axis"));
  CHECK(contains(message([&] {
                   base().add_joint("j", JointType::Revolute, "nowhere", Pose{}, Vector3::UnitZ(), "l", ok);
                 }),
                 "ModelError: joint 'j': unknown parent link 'nowhere'"));
  CHECK(contains(message([&] {
                   base()
                       .add_joint("j1", JointType::Revolute, "b", Pose{}, Vector3::UnitZ(), "l", ok)
                       .add_joint("j2", JointType::Revolute, "b", Pose{}, Vector3::UnitZ(), "l", ok);
                 }),
                 "ModelError: joint 'j2': link 'l' already has a parent"));
  CHECK(contains(message([&] {
                   base()
                       .add_joint("j1", JointType::Revolute, "b", Pose{}, Vector3::UnitZ(), "l1", ok)
                       .add_joint("j2", JointType::Prismatic, "b", Pose{}, Vector3::UnitX(), "l2", ok)
                       .build();
                 }),
                 "InputError: the end-effector is ambiguous: the tree has 2 leaf links (l1, l2)"));
  Pose nan_pose;
  nan_pose.p.x() = std::nan("");
  CHECK(contains(
      message([&] { base().add_joint("jn", JointType::Revolute, "b", nan_pose, Vector3::UnitZ(), "l", ok); }),
      "ModelError: joint 'jn' origin: values must be finite"));
}

}  // namespace test_urdf
