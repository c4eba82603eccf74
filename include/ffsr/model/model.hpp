// ffsr/model/model.hpp -- the free-floating robot: a tree of rigid bodies on a 6-DoF base.
#pragma once

#include "ffsr/errors.hpp"
#include "ffsr/spatial/spatial.hpp"

#include <limits>
#include <string>
#include <utility>
#include <vector>

// Coordinates (the one place they are fixed; see also README "Conventions"):
//  - Configuration: the base pose (position of the base link frame origin and its attitude,
//    both in the inertial frame o) and the joint positions theta (radians or metres), one per
//    independent moving joint (a coordinate), in model order: for a URDF, depth-first from the base
//    with siblings in the order of their <joint> elements in the file; for a ModelBuilder, the order
//    the joints were added (every parent before its children).
//  - Mimic joints: a follower joint moves as q_f = multiplier * theta_c + offset with theta_c the
//    coordinate of its (resolved) leader. It is a body of the tree but no coordinate: n() counts
//    coordinates, nb() bodies. Every algorithm maps body i to its coordinate body(i).coord and
//    takes the motion subspace of body i per unit rate of that coordinate (S_i * multiplier), so a
//    coordinate that drives several joints gets the sum of their contributions (H = T^T H_full T for
//    the constant map q_full = T theta + c).
//  - Generalized velocity (6+n): [v0, w0, theta_dot] with v0 the linear velocity of the base
//    link frame origin and w0 the angular velocity of the base, both in the inertial frame.
//  - Generalized acceleration: the time derivative of that vector.
//  - The first six generalized forces are the force and the moment about the base frame
//    origin acting on the base, both in the inertial frame.
//
// A Model is constant once built. Algorithms write only into a Data (model/data.hpp).

namespace ffsr {

/// Pose of a frame b in a frame a: p is the origin of b in a, R = aRb.
struct Pose {
  Vector3 p = Vector3::Zero();
  Matrix3 R = Matrix3::Identity();
  static Pose from_xyz_rpy(const Vector3& xyz, const Vector3& rpy) { return {xyz, rotation_from_rpy(rpy)}; }
  Pose operator*(const Pose& b) const { return {p + R * b.p, R * b.R}; }
};

/// The pose of the base in the inertial frame.
struct BasePose {
  Vector3 position = Vector3::Zero();
  Quaternion orientation = Quaternion::Identity();
};

/// Mass, centre of mass and inertia about the centre of mass, in the link frame.
struct Inertia {
  double mass = 0.0;
  Vector3 com = Vector3::Zero();
  Matrix3 I = Matrix3::Zero();
};

enum class JointType { Revolute, Prismatic };

struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  Vector3 axis = Vector3::UnitZ();  ///< unit axis in the child (joint) frame
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  double effort = 0;  ///< the URDF's <limit effort>, N m (N prismatic); 0: not given
  bool has_limits() const { return std::isfinite(lower) || std::isfinite(upper); }
};

/// One rigid body. Body 0 is the free-floating base; body i > 0 hangs on joint i - 1.
struct Body {
  std::string name;
  int parent = -1;          ///< index of the parent body, -1 for the base; parent < own index
  Joint joint;              ///< the joint from the parent (unused for the base)
  Pose tree;                ///< joint frame in the parent body frame at zero joint position
  Inertia inertia;          ///< in this body's frame, fixed-joint children merged in
  int coord = -1;           ///< the coordinate (index into theta) that drives the joint (-1 for the base)
  double multiplier = 1.0;  ///< joint position = multiplier * theta(coord) + offset (1, 0 unless a mimic)
  double offset = 0.0;
  std::string leader;  ///< the joint this one mimics, resolved to an independent joint ("" if none)
  /// The joint position of this body for the coordinates theta.
  double joint_position(const Eigen::Ref<const Eigen::VectorXd>& theta) const {
    return multiplier * theta(coord) + offset;
  }
};

/// A named frame rigidly attached to a body (every link, including those merged by fixed joints).
struct Frame {
  std::string name;
  int body = 0;
  Pose pose;  ///< in the body frame
};

/// Checks that an inertia is physical: finite, mass >= 0 (> 0 when `require_positive_mass`),
/// the rotational inertia symmetric positive semi-definite and satisfying the triangle inequality
/// (a thin rod's zero axial moment is valid). Throws ModelError naming `what`.
inline void validate_inertia(const Inertia& in, const std::string& what, bool require_positive_mass) {
  using detail::str;
  if (!std::isfinite(in.mass) || !in.com.allFinite() || !in.I.allFinite())
    FFSR_THROW(ModelError(str(what, ": inertial values must be finite")));
  if (in.mass < 0 || (require_positive_mass && in.mass <= 0))
    FFSR_THROW(ModelError(str(what, ": mass must be positive, got ", in.mass)));
  const double scale = std::max(1.0, in.I.cwiseAbs().maxCoeff());
  if ((in.I - in.I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
    FFSR_THROW(ModelError(str(what, ": inertia matrix is not symmetric")));
  Eigen::SelfAdjointEigenSolver<Matrix3> es(in.I, Eigen::EigenvaluesOnly);
  const Vector3& e = es.eigenvalues();
  const double tol = 1e-9 * scale;
  if (e.minCoeff() < -tol)
    FFSR_THROW(ModelError(str(what, ": inertia matrix is not positive semi-definite (smallest principal moment ",
                         e.minCoeff(), ")")));
  if (e(2) > e(0) + e(1) + tol)
    FFSR_THROW(ModelError(
        str(what, ": principal moments (", e(0), ", ", e(1), ", ", e(2), ") break the triangle inequality")));
}

namespace detail {

/// The inertia `in` of a link expressed in the frame where the link frame has pose `pose`: the
/// centre of mass moved and the rotational inertia (about it) rotated, I' = R I R^T.
inline Inertia inertia_in_frame(const Inertia& in, const Pose& pose) {
  return {in.mass, pose.p + pose.R * in.com, pose.R * in.I * pose.R.transpose()};
}

/// The composite inertia of two bodies given in the same frame (the link merging of a fixed
/// joint): masses add, the centre of mass is the mass-weighted mean c, and each rotational
/// inertia moves to c by the parallel-axis theorem, I_c = I + m (|d|^2 1 - d d^T), d = com - c
/// (RBDA 2.12). Two massless bodies give zero mass and the sum of their inertias.
inline Inertia merged_inertia(const Inertia& a, const Inertia& b) {
  const double m = a.mass + b.mass;
  if (m <= 0) return {0.0, Vector3::Zero(), a.I + b.I};
  const Vector3 c = (a.mass * a.com + b.mass * b.com) / m;
  auto about_c = [&](const Inertia& x) {
    const Vector3 d = x.com - c;
    return Matrix3(x.I + x.mass * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose()));
  };
  return {m, c, about_c(a) + about_c(b)};
}

/// What forward_kinematics reads of a body's joint besides Body itself, fixed when the model is built
/// (ModelBuilder::build): which of its shortcuts apply, and for a revolute joint about a general unit
/// axis k the constant parts of tree.R rot(k, q) = tree.R + s B + (1 - c) D (Rodrigues' formula
/// 1 + s [k]x + (1 - c) [k]x^2 multiplied by tree.R; [k]x^2 = k k^T - 1 for a unit k), so that the
/// rotation of the body costs one 3x3 product on the chain of the tree, not two plus the formula.
struct JointKinematics {
  bool tree_identity = true;  ///< tree.R is exactly the identity (rpy 0 0 0, most URDF joints)
  int axis = -1;              ///< 0, 1 or 2: the axis is exactly +-x, +-y or +-z; -1 otherwise
  int next1 = 0, next2 = 0;   ///< (axis + 1) % 3 and (axis + 2) % 3: the columns a plane rotation turns
  Matrix3 B = Matrix3::Zero(), D = Matrix3::Zero();  ///< tree.R [k]x and tree.R (k k^T - 1)
  Vector3 z = Vector3::UnitZ();  ///< tree.R k: the joint axis in the parent body's axes
};

/// 0, 1 or 2 when the unit vector `axis` is +-x, +-y or +-z exactly (as most URDF joint axes are), else -1.
inline int coordinate_axis(const Vector3& axis) {
  if (axis.y() == 0.0 && axis.z() == 0.0) return 0;
  if (axis.x() == 0.0 && axis.z() == 0.0) return 1;
  if (axis.x() == 0.0 && axis.y() == 0.0) return 2;
  return -1;
}

/// The JointKinematics of body b (for the base, body 0, unused).
inline JointKinematics joint_kinematics(const Body& b) {
  JointKinematics k;
  const Vector3& ax = b.joint.axis;
  k.tree_identity = b.tree.R == Matrix3::Identity();
  k.axis = coordinate_axis(ax);
  k.next1 = (k.axis + 1) % 3;
  k.next2 = (k.axis + 2) % 3;
  k.B = b.tree.R * skew(ax);
  k.z = b.tree.R * ax;
  k.D = k.z * ax.transpose() - b.tree.R;
  return k;
}

}  // namespace detail

class ModelBuilder;
class Model;
struct AttachedBody;
/// The model with a rigid body attached at a frame (model/attach.hpp).
inline Model attach_body(const Model& model, const std::string& frame, const AttachedBody& body);

/// A free-floating multibody tree. Constant after it is built (see ModelBuilder).
class Model {
 public:
  /// Number of coordinates n (independent moving joints; the joint-space dimension).
  int n() const { return static_cast<int>(coord_body_.size()); }
  /// Number of bodies, the base included (n() + 1 unless there are mimic joints).
  int nb() const { return static_cast<int>(bodies_.size()); }
  /// The body whose joint is coordinate k (the leader of its mimics).
  int coordinate_body(int k) const { return coord_body_[static_cast<size_t>(k)]; }
  /// The joint of coordinate k (name, type, limits).
  const Joint& joint(int k) const { return body(coordinate_body(k)).joint; }
  /// Dimension of the generalized velocity, 6 + n.
  int nv() const { return n() + 6; }
  const std::vector<Body>& bodies() const { return bodies_; }
  const Body& body(int i) const { return bodies_[static_cast<size_t>(i)]; }
  const std::vector<Frame>& frames() const { return frames_; }
  const Frame& frame(int i) const { return frames_[static_cast<size_t>(i)]; }
  /// The constants of body i's joint that forward_kinematics reads (derived from body(i) by build()).
  const detail::JointKinematics& joint_kinematics(int i) const { return kin_[static_cast<size_t>(i)]; }
  /// True when body i's inertia about its centre of mass is diagonal (URDF principal axes): the
  /// shortcut of SpatialInertia::from_body, decided once (build()).
  bool inertia_diagonal(int i) const { return inertia_diagonal_[static_cast<size_t>(i)] != 0; }
  /// The largest body index in the subtree of body i (i itself for a leaf).
  int subtree_last(int i) const { return subtree_last_[static_cast<size_t>(i)]; }
  /// True when every subtree is the contiguous range of bodies [i, subtree_last(i)] (the depth-first
  /// numbering the URDF loader makes) and no joint is a mimic (body i drives coordinate i - 1): the
  /// algorithms then take contiguous blocks of their matrices for a subtree.
  bool depth_first() const { return depth_first_; }
  /// The index of a named frame; throws InputError listing the frames when the name is unknown.
  int frame_index(const std::string& name) const {
    for (size_t i = 0; i < frames_.size(); ++i)
      if (frames_[i].name == name) return static_cast<int>(i);
    std::string list;
    for (const auto& f : frames_) list += (list.empty() ? "" : ", ") + f.name;
    FFSR_THROW(InputError(detail::str("unknown frame '", name, "'; the model has: ", list)));
  }
  /// The default end-effector frame (the single leaf, or the one set by the builder).
  int end_effector() const { return end_effector_; }
  /// The names of the coordinates' joints, in coordinate order.
  std::vector<std::string> joint_names() const {
    std::vector<std::string> names;
    for (int b : coord_body_) names.push_back(body(b).joint.name);
    return names;
  }
  double total_mass() const {
    double m = 0;
    for (const auto& b : bodies_) m += b.inertia.mass;
    return m;
  }
  /// Gravity in the inertial frame (zero by default: the robot floats freely).
  Vector3 gravity = Vector3::Zero();
  /// A label for error messages (the URDF file, or "model").
  std::string source = "model";

 private:
  friend class ModelBuilder;
  friend Model attach_body(const Model& model, const std::string& frame, const AttachedBody& body);
  std::vector<Body> bodies_;
  std::vector<Frame> frames_;
  std::vector<int> coord_body_;
  std::vector<detail::JointKinematics> kin_;  ///< one per body, from the bodies (build())
  std::vector<int> subtree_last_;             ///< per body (build())
  std::vector<char> inertia_diagonal_;        ///< per body (build())
  bool depth_first_ = false;                  ///< (build())
  int end_effector_ = -1;
};

/// Builds a Model in code, or from a URDF (parsers/urdf.hpp uses it).
///
///   Model m = ModelBuilder("base", {500, {0,0,0}, 200 * Matrix3::Identity()})
///                 .add_joint("j1", JointType::Revolute, "base", Pose{{0.6,0,0}}, Vector3::UnitZ(),
///                            "link1", {5, {0.7,0,0}, Vector3(0.01,0.82,0.82).asDiagonal()})
///                 ...
///                 .build();
class ModelBuilder {
 public:
  ModelBuilder(const std::string& base_name, const Inertia& base_inertia) {
    validate_inertia(base_inertia, "base link '" + base_name + "'", false);
    Body b;
    b.name = base_name;
    b.inertia = base_inertia;
    model_.bodies_.push_back(b);
    model_.frames_.push_back({base_name, 0, Pose{}});
  }

  /// Adds a moving joint from the frame `parent` (a link or frame name) to a new link `child`.
  ModelBuilder& add_joint(const std::string& name, JointType type, const std::string& parent,
                          const Pose& origin, const Vector3& axis, const std::string& child,
                          const Inertia& inertia, double lower = -std::numeric_limits<double>::infinity(),
                          double upper = std::numeric_limits<double>::infinity(), double effort = 0) {
    using detail::str;
    const Frame pf = find_parent(parent, name);
    check_new_name(child, name);
    check_pose(origin, "joint '" + name + "' origin");
    if (!axis.allFinite() || axis.norm() < 1e-12)
      FFSR_THROW(ModelError(str("joint '", name, "': axis must be a finite non-zero vector")));
    if (std::isnan(lower) || std::isnan(upper) || lower > upper)
      FFSR_THROW(ModelError(
          str("joint '", name, "': limits must satisfy lower <= upper, got [", lower, ", ", upper, "]")));
    if (!(effort >= 0) || !std::isfinite(effort))
      FFSR_THROW(ModelError(str("joint '", name, "': effort must be finite and >= 0, got ", effort)));
    validate_inertia(inertia, "link '" + child + "'", false);
    Body b;
    b.name = child;
    b.parent = pf.body;
    b.joint = Joint{name, type, axis.normalized(), lower, upper, effort};
    b.tree = pf.pose * origin;
    b.inertia = inertia;
    model_.bodies_.push_back(b);
    frame_parent_.push_back(frame_position(parent));
    model_.frames_.push_back({child, static_cast<int>(model_.bodies_.size()) - 1, Pose{}});
    return *this;
  }

  /// Adds a fixed joint: the link `child` is merged into the body carrying `parent` (its inertia is
  /// added there) and keeps a named frame.
  ModelBuilder& add_fixed(const std::string& name, const std::string& parent, const Pose& origin,
                          const std::string& child, const Inertia& inertia) {
    const Frame pf = find_parent(parent, name);
    check_new_name(child, name);
    check_pose(origin, "joint '" + name + "' origin");
    validate_inertia(inertia, "link '" + child + "'", false);
    const Pose pose = pf.pose * origin;
    Inertia& target = model_.bodies_[static_cast<size_t>(pf.body)].inertia;
    target = detail::merged_inertia(target, detail::inertia_in_frame(inertia, pose));
    frame_parent_.push_back(frame_position(parent));
    model_.frames_.push_back({child, pf.body, pose});
    return *this;
  }

  /// Names the end-effector frame (default: the single leaf link).
  ModelBuilder& set_end_effector(const std::string& frame) {
    ee_name_ = frame;
    return *this;
  }

  /// Puts the contact point at `xyz` in the end-effector frame (where the fingers close rather than
  /// at a link origin): build() adds the frame "<end-effector>_contact" there, on the same body, and
  /// makes it the end-effector, so every quantity of the end-effector (J_f, m_e, M_ie) uses it.
  ModelBuilder& set_end_effector_offset(const Vector3& xyz) {
    if (!xyz.allFinite()) FFSR_THROW(InputError("end-effector-offset: expected 3 finite numbers"));
    ee_offset_ = xyz;
    has_ee_offset_ = true;
    return *this;
  }

  /// Makes the moving joint `follower` a mimic of `leader`: q_follower = multiplier * q_leader + offset
  /// (URDF <mimic>). The follower is then no coordinate of its own. Leaders may themselves be mimics
  /// (chains resolve in build()); the joints may be added before or after this call.
  ModelBuilder& set_mimic(const std::string& follower, const std::string& leader, double multiplier,
                          double offset) {
    if (!std::isfinite(multiplier) || !std::isfinite(offset))
      FFSR_THROW(ModelError(detail::str("mimic joint '", follower, "': multiplier and offset must be finite")));
    mimic_.push_back({follower, leader, multiplier, offset});
    return *this;
  }

  /// Validates the tree and returns the model. Throws ModelError (moving link without mass,
  /// no joint) or InputError (unknown or ambiguous end-effector).
  Model build() const {
    using detail::str;
    Model m = model_;
    if (m.nb() < 2) FFSR_THROW(ModelError("the robot has no moving joint"));
    resolve_mimics(m);
    validate_inertia(m.bodies_[0].inertia, "base link '" + m.bodies_[0].name + "'", true);
    for (int i = 1; i <= m.n(); ++i)
      validate_inertia(m.body(i).inertia, "link '" + m.body(i).name + "' (moving)", true);
    if (!ee_name_.empty()) {
      m.end_effector_ = m.frame_index(ee_name_);
    } else {
      std::vector<std::string> leaves = leaf_frames(m);
      if (leaves.size() != 1) {
        std::string list;
        for (const auto& l : leaves) list += (list.empty() ? "" : ", ") + l;
        FFSR_THROW(InputError(str("the end-effector is ambiguous: the tree has ", leaves.size(), " leaf links (",
                             list, "); name one")));
      }
      m.end_effector_ = m.frame_index(leaves.front());
    }
    if (has_ee_offset_) {
      const Frame ee = m.frames_[static_cast<size_t>(m.end_effector_)];
      const std::string name = ee.name + "_contact";
      for (const auto& f : m.frames_)
        if (f.name == name) FFSR_THROW(ModelError(str("end-effector-offset: a frame '", name, "' already exists")));
      m.frames_.push_back({name, ee.body, ee.pose * Pose{ee_offset_, Matrix3::Identity()}});
      m.end_effector_ = static_cast<int>(m.frames_.size()) - 1;
    }
    m.kin_.clear();
    for (const Body& b : m.bodies_) m.kin_.push_back(detail::joint_kinematics(b));
    number_subtrees(m);
    return m;
  }

  /// The model whose bodies(), frames(), end_effector() and gravity are these, as another Model held
  /// them: the way back from a serialized model (control/onboard_blob.hpp), exact to the bit (nothing
  /// is renormalized or merged again). The parts are taken as they are; their reader checks their
  /// shape (each parent before its child, frames on existing bodies, leaders naming a joint).
  static Model assemble(std::vector<Body> bodies, std::vector<Frame> frames, int end_effector,
                        const Vector3& gravity) {
    Model m;
    m.bodies_ = std::move(bodies);
    m.frames_ = std::move(frames);
    m.end_effector_ = end_effector;
    m.gravity = gravity;
    number_coordinates(m);
    for (const Body& b : m.bodies_) m.kin_.push_back(detail::joint_kinematics(b));
    number_subtrees(m);
    return m;
  }

  /// Source label for error messages.
  ModelBuilder& set_source(const std::string& s) {
    model_.source = s;
    return *this;
  }
  ModelBuilder& set_gravity(const Vector3& g) {
    if (!g.allFinite()) FFSR_THROW(InputError("gravity must be finite"));
    model_.gravity = g;
    return *this;
  }

 private:
  /// Model::subtree_last and Model::depth_first, by one backward pass (a parent before its children).
  static void number_subtrees(Model& m) {
    const auto nb = static_cast<size_t>(m.nb());
    std::vector<int> size(nb, 1);
    m.subtree_last_.resize(nb);
    m.inertia_diagonal_.resize(nb);
    for (size_t i = 0; i < nb; ++i) {
      m.subtree_last_[i] = static_cast<int>(i);
      m.inertia_diagonal_[i] = SpatialInertia::is_diagonal(m.bodies_[i].inertia.I) ? 1 : 0;
    }
    for (size_t i = nb - 1; i > 0; --i) {
      const auto up = static_cast<size_t>(m.bodies_[i].parent);
      m.subtree_last_[up] = std::max(m.subtree_last_[up], m.subtree_last_[i]);
      size[up] += size[i];
    }
    m.depth_first_ = m.nb() - 1 == m.n();
    for (size_t i = 0; i < nb; ++i)
      if (size[i] != m.subtree_last_[i] - static_cast<int>(i) + 1) m.depth_first_ = false;
  }
  Frame find_parent(const std::string& parent, const std::string& joint) const {
    for (const auto& f : model_.frames_)
      if (f.name == parent) return f;
    FFSR_THROW(ModelError(detail::str("joint '", joint, "': unknown parent link '", parent, "'")));
  }
  void check_new_name(const std::string& child, const std::string& joint) const {
    for (const auto& f : model_.frames_)
      if (f.name == child)
        FFSR_THROW(ModelError(detail::str("joint '", joint, "': link '", child,
                                     "' already has a parent (closed loop or duplicate link)")));
  }
  static void check_pose(const Pose& p, const std::string& what) {
    if (!p.p.allFinite() || !p.R.allFinite()) FFSR_THROW(ModelError(what + ": values must be finite"));
  }
  std::vector<std::string> leaf_frames(const Model& m) const {
    // A leaf is a link frame that is no other link's parent (fixed children count as children).
    std::vector<char> is_parent(m.frames_.size(), 0);
    for (int p : frame_parent_)
      if (p >= 0) is_parent[static_cast<size_t>(p)] = 1;
    std::vector<std::string> leaves;
    for (size_t fi = 0; fi < m.frames_.size(); ++fi)
      if (!is_parent[fi]) leaves.push_back(m.frames_[fi].name);
    return leaves;
  }
  int frame_position(const std::string& name) const {
    for (size_t i = 0; i < model_.frames_.size(); ++i)
      if (model_.frames_[i].name == name) return static_cast<int>(i);
    return -1;
  }
  struct MimicSpec {
    std::string follower, leader;
    double multiplier, offset;
  };
  /// The body whose moving joint is named `joint`, or -1.
  static int body_of_joint(const Model& m, const std::string& joint) {
    for (int i = 1; i < m.nb(); ++i)
      if (m.bodies_[static_cast<size_t>(i)].joint.name == joint) return i;
    return -1;
  }
  /// The <mimic> of the follower `joint`, or null.
  const MimicSpec* mimic_of(const std::string& joint) const {
    for (const auto& s : mimic_)
      if (s.follower == joint) return &s;
    return nullptr;
  }
  /// Follows the mimic chain of body i's joint to its independent leader and writes the body's
  /// leader (empty for an independent joint) and the composed multiplier and offset:
  /// q_f = mult * (m q_l + o) + off at each link of the chain. Throws ModelError for a leader that
  /// is no moving joint, or a loop. Reads mimic_. Writes m.bodies_[i].leader, multiplier, offset.
  void resolve_mimic_chain(Model& m, int i) const {
    using detail::str;
    Body& b = m.bodies_[static_cast<size_t>(i)];
    std::vector<std::string> chain{b.joint.name};
    double mult = 1.0, off = 0.0;
    for (const MimicSpec* s = mimic_of(b.joint.name); s; s = mimic_of(chain.back())) {
      if (body_of_joint(m, s->leader) < 0)
        FFSR_THROW(ModelError(str("mimic joint '", s->follower, "': its leader '", s->leader,
                             "' is not a moving joint of the model")));
      off += mult * s->offset;  // q_f = mult * (m q_l + o) + off
      mult *= s->multiplier;
      for (const auto& c : chain)
        if (c == s->leader) {
          std::string loop;
          for (const auto& x : chain) loop += "'" + x + "' -> ";
          FFSR_THROW(ModelError(str("mimic joints form a loop: ", loop, "'", s->leader, "'")));
        }
      chain.push_back(s->leader);
    }
    b.multiplier = mult;
    b.offset = off;
    b.leader = chain.size() > 1 ? chain.back() : std::string();
  }
  /// Numbers the coordinates: every joint without a leader is one, in body order; a follower
  /// takes its leader's. Reads m.bodies_[i].leader. Writes m.bodies_[i].coord, m.coord_body_.
  static void number_coordinates(Model& m) {
    m.coord_body_.clear();
    for (int i = 1; i < m.nb(); ++i) {
      Body& b = m.bodies_[static_cast<size_t>(i)];
      if (b.leader.empty()) {
        b.coord = m.n();
        m.coord_body_.push_back(i);
      }
    }
    for (int i = 1; i < m.nb(); ++i) {
      Body& b = m.bodies_[static_cast<size_t>(i)];
      if (!b.leader.empty()) b.coord = m.bodies_[static_cast<size_t>(body_of_joint(m, b.leader))].coord;
    }
  }
  /// Resolves the mimic chains to independent joints and numbers the coordinates: every joint that
  /// mimics no other is a coordinate, in body order; a follower takes its resolved leader's
  /// coordinate with the composed multiplier and offset. O(bodies * chain length).
  void resolve_mimics(Model& m) const {
    for (const auto& s : mimic_)
      if (body_of_joint(m, s.follower) < 0)
        FFSR_THROW(ModelError(detail::str("mimic joint '", s.follower, "': not a moving joint of the model")));
    for (int i = 1; i < m.nb(); ++i) resolve_mimic_chain(m, i);
    number_coordinates(m);
  }
  std::vector<MimicSpec> mimic_;
  Vector3 ee_offset_ = Vector3::Zero();
  bool has_ee_offset_ = false;
  Model model_;
  std::vector<int> frame_parent_{-1};  ///< for each frame, the frame it hangs on (-1 for the base)
  std::string ee_name_;
};

}  // namespace ffsr
