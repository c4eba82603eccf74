// tests/support/dynamics_helpers.hpp -- test-side references for the dynamics identities.
//
// Everything here is computed WITHOUT the library's velocity, momentum, Jacobian or inertia code:
// only forward_kinematics / frame_pose (world pose of a frame) are used, and velocities come from
// central finite differences of those poses along a chosen chart of the configuration space.
#pragma once

#include "ffsr/ffsr.hpp"
#include "ffsr/parsers/urdf.hpp"

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace ffsr_test {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using ffsr::BasePose;
using ffsr::Data;
using ffsr::Inertia;
using ffsr::JointType;
using ffsr::Matrix3;
using ffsr::Model;
using ffsr::ModelBuilder;
using ffsr::Pose;
using ffsr::Quaternion;
using ffsr::Vector3;
using ffsr::Vector6;

inline std::string source_path(const std::string& rel) { return std::string(FFSR_SOURCE_DIR) + "/" + rel; }

inline double deg(double d) { return d * M_PI / 180.0; }

/// Largest absolute entry of a - b divided by max(1, largest absolute entry of b): a relative error
/// with an absolute floor of one unit (kg, kg m, kg m^2 ... as the quantity is).
template <class A, class B>
double rel_err(const A& a, const B& b) {
  const double scale = std::max(1.0, b.cwiseAbs().maxCoeff());
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

/// A seeded random source (fixed seeds: the tests are reproducible).
struct Rng {
  explicit Rng(unsigned seed) : gen(seed) {}
  std::mt19937 gen;
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(gen); }
  Vector3 vec3(double a) { return {uniform(-a, a), uniform(-a, a), uniform(-a, a)}; }
  VectorXd vec(long n, double a) {
    VectorXd v(n);
    for (long i = 0; i < n; ++i) v(i) = uniform(-a, a);
    return v;
  }
  Vector3 unit() {
    for (;;) {
      const Vector3 v = vec3(1.0);
      if (v.norm() > 0.1 && v.norm() <= 1.0) return v.normalized();
    }
  }
  /// A uniformly random attitude, guaranteed at least 20 deg away from the identity.
  Quaternion quaternion() {
    std::normal_distribution<double> n(0.0, 1.0);
    for (;;) {
      Quaternion q(n(gen), n(gen), n(gen), n(gen));
      q.normalize();
      if (Eigen::AngleAxisd(q).angle() > deg(20)) return q;
    }
  }
  Matrix3 rotation() { return quaternion().toRotationMatrix(); }
  /// A physical inertia: principal moments (b+c, a+c, a+b) of second moments a, b, c >= 0 (so the
  /// triangle inequality holds), rotated by a random rotation: full, non-diagonal.
  Matrix3 inertia(double scale) {
    const double a = uniform(0.05, 1.0) * scale, b = uniform(0.05, 1.0) * scale,
                 c = uniform(0.05, 1.0) * scale;
    const Matrix3 R = rotation();
    return R * Vector3(b + c, a + c, a + b).asDiagonal() * R.transpose();
  }
  BasePose base_pose() { return {vec3(3.0) + Vector3(0.5, -0.7, 1.1), quaternion()}; }
};

/// A mass as the robot description states it: inertia about its centre of mass, given in the named
/// frame (a link frame; for a fixed child, its own frame, not merged).
struct LinkMass {
  std::string frame;
  Inertia inertia;
};

/// A robot under test: the model and the list of its masses (independently of how the model merged
/// them), plus its end-effector frame.
struct TestRobot {
  std::string name;
  ffsr::Model model;
  std::vector<LinkMass> links;
  int ee = -1;
};

/// The links of a model whose bodies carry no merged masses (the paper robots: their fixed child
/// `ee` is massless): one LinkMass per body, at the body frame.
inline std::vector<LinkMass> links_from_bodies(const ffsr::Model& m) {
  std::vector<LinkMass> links;
  for (const auto& b : m.bodies()) links.push_back({b.name, b.inertia});
  return links;
}

/// A robot of robots/ (a URDF whose masses all sit on moving or base bodies).
inline TestRobot paper_robot(const std::string& file) {
  TestRobot r{file, ffsr::model_from_urdf_file(source_path("robots/" + file)), {}, -1};
  r.links = links_from_bodies(r.model);
  r.ee = r.model.end_effector();
  return r;
}

/// A configuration of the free-floating robot.
struct Config {
  BasePose base;
  VectorXd theta;
};

/// A random configuration: a random base pose (Rng::base_pose) and joint angles in [-range, range].
inline Config random_config(const ffsr::Model& m, Rng& rng, double range = M_PI) {
  return {rng.base_pose(), rng.vec(m.n(), range)};
}

/// A chart: the configuration reached from `q` after time h along generalized velocity v, in some
/// choice of velocity coordinates.
using Chart = std::function<Config(const Config& q, const VectorXd& v, double h)>;

/// The library's coordinates (model.hpp): base origin moves by h v0 (inertial), the attitude turns by
/// exp(h [w0]) applied in the inertial frame (left), joints by h theta_dot.
inline Config advance_library(const Config& q, const VectorXd& v, double h) {
  Config r = q;
  r.base.position = q.base.position + h * v.head<3>();
  const Matrix3 R = ffsr::rotation_from_vector(h * Vector3(v.segment<3>(3))) *
                    q.base.orientation.normalized().toRotationMatrix();
  r.base.orientation = Quaternion(R);
  r.theta = q.theta + h * v.tail(v.size() - 6);
  return r;
}

/// Base velocity given in the base body frame: the origin moves by h R0 v0', the attitude turns by
/// exp(h [w0']) applied in the body frame (right).
inline Config advance_base_body_frame(const Config& q, const VectorXd& v, double h) {
  Config r = q;
  const Matrix3 R0 = q.base.orientation.normalized().toRotationMatrix();
  r.base.position = q.base.position + h * R0 * v.head<3>();
  r.base.orientation = Quaternion(Matrix3(R0 * ffsr::rotation_from_vector(h * Vector3(v.segment<3>(3)))));
  r.theta = q.theta + h * v.tail(v.size() - 6);
  return r;
}

/// World pose (centre of mass and frame rotation) of every listed mass, from forward kinematics.
struct LinkState {
  Vector3 c;
  Matrix3 R;
};
inline std::vector<LinkState> link_states(const TestRobot& r, ffsr::Data& d, const Config& q) {
  ffsr::forward_kinematics(r.model, d, q.base, q.theta);
  std::vector<LinkState> s;
  for (const auto& l : r.links) {
    const ffsr::Pose X = ffsr::frame_pose(r.model, d, r.model.frame_index(l.frame));
    s.push_back({X.p + X.R * l.inertia.com, X.R});
  }
  return s;
}

/// Centre of mass of the whole system, weighted over the listed masses.
inline Vector3 system_com(const TestRobot& r, const std::vector<LinkState>& s) {
  Vector3 c = Vector3::Zero();
  double m = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    c += r.links[i].inertia.mass * s[i].c;
    m += r.links[i].inertia.mass;
  }
  return c / m;
}

/// The system's centre of mass as the base-position coordinate: the chart moves the centre of mass
/// by h v_g (inertial), turns the attitude by exp(h [w0]) (inertial), the joints by h theta_dot, and
/// places the base origin so that the centre of mass lands where it should.
inline Chart advance_com_chart(const TestRobot& r) {
  return [&r](const Config& q, const VectorXd& v, double h) {
    ffsr::Data d(r.model);
    const Vector3 g0 = system_com(r, link_states(r, d, q));
    Config moved = q;
    const Matrix3 R = ffsr::rotation_from_vector(h * Vector3(v.segment<3>(3))) *
                      q.base.orientation.normalized().toRotationMatrix();
    moved.base.orientation = Quaternion(R);
    moved.theta = q.theta + h * v.tail(v.size() - 6);
    const Vector3 g1 = system_com(r, link_states(r, d, moved));
    moved.base.position += (g0 + h * v.head<3>()) - g1;
    return moved;
  };
}

/// Angular velocity from the central difference of rotation matrices: [w]x = (R+ - R-)/(2h) R^T.
inline Vector3 angular_velocity_fd(const Matrix3& Rp, const Matrix3& Rm, const Matrix3& R, double h) {
  const Matrix3 W = (Rp - Rm) / (2 * h) * R.transpose();
  return {0.5 * (W(2, 1) - W(1, 2)), 0.5 * (W(0, 2) - W(2, 0)), 0.5 * (W(1, 0) - W(0, 1))};
}

/// Velocity of every listed mass (centre-of-mass velocity and angular velocity, inertial) for the
/// generalized velocity v in the given chart, by central finite differences of forward kinematics.
struct LinkVelocity {
  Vector3 vc, w, c;
  Matrix3 R;
};
inline std::vector<LinkVelocity> fd_link_velocities(const TestRobot& r, const Config& q, const VectorXd& v,
                                                    const Chart& chart, double h = 1e-5) {
  ffsr::Data d(r.model);
  const auto s0 = link_states(r, d, q);
  const auto sp = link_states(r, d, chart(q, v, h));
  const auto sm = link_states(r, d, chart(q, v, -h));
  std::vector<LinkVelocity> out;
  for (size_t i = 0; i < s0.size(); ++i)
    out.push_back(
        {(sp[i].c - sm[i].c) / (2 * h), angular_velocity_fd(sp[i].R, sm[i].R, s0[i].R, h), s0[i].c, s0[i].R});
  return out;
}

/// Kinetic energy sum over the listed masses: 1/2 m |v_c|^2 + 1/2 w^T (R I R^T) w.
inline double fd_kinetic_energy(const TestRobot& r, const std::vector<LinkVelocity>& lv) {
  double T = 0;
  for (size_t i = 0; i < lv.size(); ++i) {
    const Inertia& in = r.links[i].inertia;
    T += 0.5 * in.mass * lv[i].vc.squaredNorm() +
         0.5 * lv[i].w.dot(lv[i].R * in.I * lv[i].R.transpose() * lv[i].w);
  }
  return T;
}

/// Total momentum [P; L about the point o], summed over the listed masses.
inline Vector6 fd_momentum(const TestRobot& r, const std::vector<LinkVelocity>& lv, const Vector3& o) {
  Vector6 h = Vector6::Zero();
  for (size_t i = 0; i < lv.size(); ++i) {
    const Inertia& in = r.links[i].inertia;
    h.head<3>() += in.mass * lv[i].vc;
    h.tail<3>() += (lv[i].c - o).cross(in.mass * lv[i].vc) + lv[i].R * in.I * lv[i].R.transpose() * lv[i].w;
  }
  return h;
}

/// The inertia matrix in the chart's coordinates, sum over masses of m Jv^T Jv + Jw^T I Jw with the
/// Jacobians of every mass from finite differences (one column per unit generalized velocity).
inline MatrixXd fd_inertia_matrix(const TestRobot& r, const Config& q, const Chart& chart, double h = 1e-5) {
  const long nv = r.model.nv();
  const size_t nl = r.links.size();
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> Jv(
      nl, Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, nv)),
      Jw(nl, Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, nv));
  std::vector<Matrix3> Rs(nl);
  for (long k = 0; k < nv; ++k) {
    const auto lv = fd_link_velocities(r, q, VectorXd::Unit(nv, k), chart, h);
    for (size_t i = 0; i < nl; ++i) {
      Jv[i].col(k) = lv[i].vc;
      Jw[i].col(k) = lv[i].w;
      Rs[i] = lv[i].R;
    }
  }
  MatrixXd H = MatrixXd::Zero(nv, nv);
  for (size_t i = 0; i < nl; ++i) {
    const Inertia& in = r.links[i].inertia;
    H += in.mass * Jv[i].transpose() * Jv[i] + Jw[i].transpose() * (Rs[i] * in.I * Rs[i].transpose()) * Jw[i];
  }
  return H;
}

/// The 6 x nv Jacobian [linear; angular] of a frame, by central differences along the chart.
inline MatrixXd fd_frame_jacobian(const TestRobot& r, const Config& q, int frame, const Chart& chart,
                                  double h = 1e-5) {
  const long nv = r.model.nv();
  ffsr::Data d(r.model);
  auto pose = [&](const Config& c) {
    ffsr::forward_kinematics(r.model, d, c.base, c.theta);
    return ffsr::frame_pose(r.model, d, frame);
  };
  const ffsr::Pose X0 = pose(q);
  MatrixXd J(6, nv);
  for (long k = 0; k < nv; ++k) {
    const VectorXd e = VectorXd::Unit(nv, k);
    const ffsr::Pose Xp = pose(chart(q, e, h)), Xm = pose(chart(q, e, -h));
    J.block<3, 1>(0, k) = (Xp.p - Xm.p) / (2 * h);
    J.block<3, 1>(3, k) = angular_velocity_fd(Xp.R, Xm.R, X0.R, h);
  }
  return J;
}

// -------------------------------------------------------------------------------------------------
// The models of the algorithm tests (tests/unit/test_crba.cpp, test_rnea.cpp, test_aba.cpp,
// test_kinematics.cpp, test_jacobian.cpp, test_momentum.cpp, test_effective_mass.cpp).

/// The random branched tree: 9 moving joints on three branches (a, b, c; c hangs on a1), two
/// prismatic joints, random non-unit axes, random full inertias and centre-of-mass offsets, a fixed
/// child "tool" with mass on a3 and a joint "a4" hung on the fixed frame "tool", a massless fixed
/// frame "tip" on a4 as the end-effector. Bodies are added interleaved (not depth-first).
inline TestRobot random_tree(unsigned seed) {
  Rng rng(seed);
  auto inertia = [&](double m) { return Inertia{m, rng.vec3(0.3), rng.inertia(0.05 * m)}; };
  auto pose = [&] { return Pose::from_xyz_rpy(rng.vec3(0.6), rng.vec3(M_PI)); };
  auto axis = [&] { return Vector3(rng.unit() * rng.uniform(0.5, 2.0)); };  // normalized by the builder

  const Inertia trunk = inertia(300);
  ModelBuilder b("trunk", trunk);
  TestRobot r;
  r.name = "random tree";
  r.links.push_back({"trunk", trunk});
  auto add = [&](const char* joint, JointType type, const char* parent, const char* child, double m) {
    const Inertia in = inertia(m);
    b.add_joint(joint, type, parent, pose(), axis(), child, in);
    r.links.push_back({child, in});
  };
  add("ja1", JointType::Revolute, "trunk", "a1", 12);
  add("jb1", JointType::Revolute, "trunk", "b1", 9);
  add("ja2", JointType::Prismatic, "a1", "a2", 7);
  add("jc1", JointType::Revolute, "a1", "c1", 5);
  add("jb2", JointType::Revolute, "b1", "b2", 8);
  add("ja3", JointType::Revolute, "a2", "a3", 6);
  const Inertia tool = inertia(2.5);
  b.add_fixed("tool_mount", "a3", pose(), "tool", tool);
  r.links.push_back({"tool", tool});
  add("ja4", JointType::Revolute, "tool", "a4", 3);
  add("jc2", JointType::Prismatic, "c1", "c2", 4);
  add("jb3", JointType::Revolute, "b2", "b3", 4.5);
  b.add_fixed("tip_mount", "a4", pose(), "tip", Inertia{});
  b.set_end_effector("tip");
  r.model = b.build();
  r.ee = r.model.end_effector();
  return r;
}

/// The paper's 3-DOF and 7-DOF robots and the random tree (seed 7), with their lists of masses.
inline std::vector<TestRobot> robots_under_test() {
  return {paper_robot("paper_3dof.urdf"), paper_robot("paper_7dof.urdf"), random_tree(7)};
}

/// The common loop of the identity checks: for every robot under test, `samples` random
/// configurations drawn from one generator seeded with `seed`, each handed to
/// body(robot, its Data, the generator, configuration, sample index); the body draws whatever else
/// it needs from the same generator, so the sequence is fixed by the seed.
template <class Body>
void for_each_config(unsigned seed, int samples, Body body) {
  Rng rng(seed);
  for (const auto& r : robots_under_test()) {
    Data d(r.model);
    for (int k = 0; k < samples; ++k) {
      const Config q = random_config(r.model, rng);
      body(r, d, rng, q, k);
    }
  }
}

/// A generalized velocity: base ~ 0.4 m/s and 0.3 rad/s, joints ~ 1 rad/s (or m/s).
inline VectorXd random_velocity(const Model& m, Rng& rng) {
  VectorXd v(m.nv());
  v << rng.vec3(0.4), rng.vec3(0.3), rng.vec(m.n(), 1.0);
  return v;
}

/// The library's chart (advance_library), as a Chart.
inline const Chart library_chart = advance_library;

/// A serial chain of n revolute joints with random axes, offsets and inertias (the size tests of the
/// articulated-body recursion).
inline Model random_chain(int n, unsigned seed) {
  Rng rng(seed);
  ModelBuilder b("base", Inertia{400, rng.vec3(0.2), rng.inertia(100)});
  std::string parent = "base";
  for (int i = 0; i < n; ++i) {
    const std::string child = "l" + std::to_string(i + 1);
    b.add_joint("j" + std::to_string(i + 1), JointType::Revolute, parent,
                Pose::from_xyz_rpy(rng.vec3(0.4), rng.vec3(M_PI)), Vector3(rng.unit()), child,
                Inertia{rng.uniform(1, 10), rng.vec3(0.2), rng.inertia(0.5)});
    parent = child;
  }
  b.add_fixed("tip_mount", parent, Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

/// A model with the name the tests print.
struct NamedModel {
  std::string name;
  Model model;
};

/// A serial chain of n joints; `unit_axes`: axes +-x, +-y, +-z in turn and every third joint origin
/// without rotation; else random axes and rotations. Inertias full, every other one diagonal.
inline Model serial_chain(int n, unsigned seed, bool unit_axes,
                          const Vector3& gravity = Vector3::Zero()) {
  Rng rng(seed);
  ModelBuilder b("base", Inertia{400, rng.vec3(0.2), rng.inertia(100)});
  b.set_gravity(gravity);
  std::string parent = "base";
  const Vector3 axes[] = {Vector3::UnitX(), -Vector3::UnitY(), Vector3::UnitZ(),
                          -Vector3::UnitX(), Vector3::UnitY(), -Vector3::UnitZ()};
  for (int i = 0; i < n; ++i) {
    const std::string child = "l" + std::to_string(i + 1);
    const Vector3 rpy = unit_axes && i % 3 == 0 ? Vector3::Zero() : rng.vec3(M_PI);
    const Vector3 axis = unit_axes ? axes[i % 6] : rng.unit();
    const Matrix3 I = i % 2 ? Matrix3(Vector3(0.2, 0.3, 0.4).asDiagonal()) : rng.inertia(0.5);
    b.add_joint("j" + std::to_string(i + 1), JointType::Revolute, parent,
                Pose::from_xyz_rpy(rng.vec3(0.4), rpy), axis, child,
                Inertia{rng.uniform(1, 10), rng.vec3(0.2), I});
    parent = child;
  }
  b.add_fixed("tip_mount", parent, Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

/// A branched tree: trunk with branches a (a1 - a2 (prismatic) - a3, and c1 - c2 on a1) and b
/// (b1 - b2), end-effector on a3. `depth_first`: bodies added so that every subtree is a contiguous
/// range (a1 a2 a3 c1 c2 b1 b2); else interleaved (a1 b1 a2 c1 b2 a3 c2).
inline Model branched_tree(unsigned seed, bool depth_first) {
  Rng rng(seed);
  ModelBuilder b("trunk", Inertia{300, rng.vec3(0.3), rng.inertia(20)});
  struct J {
    const char *joint, *parent, *child;
    JointType type;
  };
  const JointType R = JointType::Revolute, P = JointType::Prismatic;
  const std::vector<J> dfs = {{"ja1", "trunk", "a1", R}, {"ja2", "a1", "a2", P}, {"ja3", "a2", "a3", R},
                              {"jc1", "a1", "c1", R},    {"jc2", "c1", "c2", P}, {"jb1", "trunk", "b1", R},
                              {"jb2", "b1", "b2", R}};
  const std::vector<int> interleaved = {0, 5, 1, 3, 6, 2, 4};
  for (int k = 0; k < 7; ++k) {
    const J& j = dfs[static_cast<size_t>(depth_first ? k : interleaved[static_cast<size_t>(k)])];
    b.add_joint(j.joint, j.type, j.parent, Pose::from_xyz_rpy(rng.vec3(0.6), rng.vec3(M_PI)), rng.unit(),
                j.child, Inertia{rng.uniform(2, 12), rng.vec3(0.3), rng.inertia(0.5)});
  }
  b.add_fixed("tip_mount", "a3", Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

/// A chain of 5 joints whose joint j4 mimics j2 (multiplier -0.7, offset 0.2).
inline Model mimic_chain(unsigned seed) {
  Rng rng(seed);
  ModelBuilder b("base", Inertia{200, rng.vec3(0.2), rng.inertia(50)});
  std::string parent = "base";
  for (int i = 0; i < 5; ++i) {
    const std::string child = "l" + std::to_string(i + 1);
    b.add_joint("j" + std::to_string(i + 1), JointType::Revolute, parent,
                Pose::from_xyz_rpy(rng.vec3(0.4), rng.vec3(M_PI)), rng.unit(), child,
                Inertia{rng.uniform(1, 10), rng.vec3(0.2), rng.inertia(0.5)});
    parent = child;
  }
  b.set_mimic("j4", "j2", -0.7, 0.2);
  b.add_fixed("tip_mount", parent, Pose::from_xyz_rpy(rng.vec3(0.3), Vector3::Zero()), "tip", Inertia{});
  b.set_end_effector("tip");
  return b.build();
}

/// Every kind of tree the library builds: the paper's robots (URDF, unit joint axes), serial chains of
/// 1 to 28 joints with random axes, a chain with axes along +-x, +-y, +-z, a branched tree numbered
/// depth-first (as the URDF loader numbers it: the contiguous-subtree path of crba) and the same tree
/// added out of depth-first order (the ancestor-walk path). In this order (tests index it).
inline std::vector<NamedModel> models_of_every_kind() {
  std::vector<NamedModel> m;
  m.push_back({"paper 3-DOF", ffsr::model_from_urdf_file(source_path("robots/paper_3dof.urdf"))});
  m.push_back({"paper 7-DOF", ffsr::model_from_urdf_file(source_path("robots/paper_7dof.urdf"))});
  for (int n : {1, 3, 7, 14, 28})
    m.push_back({"chain " + std::to_string(n), serial_chain(n, 100u + unsigned(n), false)});
  m.push_back({"unit-axis chain 12", serial_chain(12, 7, true)});
  m.push_back({"depth-first tree", branched_tree(5, true)});
  m.push_back({"interleaved tree", branched_tree(5, false)});
  return m;
}

}  // namespace ffsr_test
