// ffsr/parsers/detail/urdf_document.hpp -- the URDF loader's internals, through urdfdom: the parse of the
// text (parse_urdf_document) and the model of a parsed document (model_from_urdf_document), with
// their checks. Compiled into the library of ffsr::urdf (src/parsers/urdf.cpp); included by the URDF
// collision elements (parsers/urdf_collision.hpp) and by tests. A program that loads a URDF includes
// parsers/urdf.hpp instead.
#pragma once

#include "ffsr/parsers/urdf.hpp"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

namespace ffsr {
namespace detail {

/// Throws ModelError unless `xml` is well-formed UTF-8 without NUL bytes. TinyXML (under urdfdom)
/// trusts UTF-8 lead bytes and reads past the end of a buffer that ends inside a multi-byte
/// sequence (found by fuzz_urdf under AddressSanitizer), so nothing malformed may reach it.
inline void require_utf8(const std::string& xml, const std::string& source) {
  const auto* b = reinterpret_cast<const unsigned char*>(xml.data());
  const size_t n = xml.size();
  for (size_t i = 0; i < n;) {
    const unsigned c = b[i];
    size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (c == 0 || len == 0 || i + len > n)
      throw ModelError(str(source, ": not a text file in UTF-8 (byte ", i, ")"));
    for (size_t k = 1; k < len; ++k)
      if ((b[i + k] >> 6) != 0x2)
        throw ModelError(str(source, ": not a text file in UTF-8 (byte ", i + k, ")"));
    i += len;
  }
}

/// Collects urdfdom's console_bridge messages instead of printing them (the library never prints).
class UrdfLogCapture : public console_bridge::OutputHandler {
 public:
  UrdfLogCapture() {
    previous_level_ = console_bridge::getLogLevel();
    console_bridge::useOutputHandler(this);
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);
  }
  ~UrdfLogCapture() override {
    console_bridge::restorePreviousOutputHandler();
    console_bridge::setLogLevel(previous_level_);
  }
  UrdfLogCapture(const UrdfLogCapture&) = delete;
  UrdfLogCapture& operator=(const UrdfLogCapture&) = delete;
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) messages += (messages.empty() ? "" : "; ") + text;
  }
  std::string messages;

 private:
  console_bridge::LogLevel previous_level_;
};

inline Pose urdf_pose(const urdf::Pose& p) {
  Pose out;
  out.p = Vector3(p.position.x, p.position.y, p.position.z);
  const Quaternion q(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z);
  out.R = q.norm() > 0 ? q.normalized().toRotationMatrix() : Matrix3::Identity();
  return out;
}

inline Inertia urdf_inertia(const urdf::Link& link) {
  Inertia in;
  if (!link.inertial) return in;
  const urdf::Inertial& u = *link.inertial;
  const Pose origin = urdf_pose(u.origin);
  Matrix3 I;
  I << u.ixx, u.ixy, u.ixz, u.ixy, u.iyy, u.iyz, u.ixz, u.iyz, u.izz;
  in.mass = u.mass;
  in.com = origin.p;
  in.I = origin.R * I * origin.R.transpose();
  return in;
}

/// Applies the repairs of `o` to the inertia of `link` and records each one. Principal moments are
/// changed in the principal axes, which stay. Reads o.min_mass, o.min_inertia, o.inertia_repair.
inline Inertia repaired_inertia(const Inertia& in, const std::string& link, const UrdfOptions& o,
                                std::vector<ModelRepair>& repairs) {
  Inertia out = in;
  if (!in.I.allFinite() || !std::isfinite(in.mass)) return out;    // validation reports it
  if (o.min_mass > 0 && out.mass >= 0 && out.mass < o.min_mass) {  // a negative mass stays an error
    repairs.push_back({link, "mass raised to min-mass", {out.mass}, {o.min_mass}});
    out.mass = o.min_mass;
  }
  const Matrix3 Isym = 0.5 * (in.I + in.I.transpose());
  Eigen::SelfAdjointEigenSolver<Matrix3> es(Isym);
  Vector3 e = es.eigenvalues();  // ascending
  const Vector3 before = e;
  if (o.min_inertia > 0 && e.minCoeff() < o.min_inertia) {
    for (int k = 0; k < 3; ++k) e(k) = std::max(e(k), o.min_inertia);
    repairs.push_back({link,
                       "principal moments raised to min-inertia",
                       {before(0), before(1), before(2)},
                       {e(0), e(1), e(2)}});
  }
  const double tol = 1e-9 * std::max(1.0, e.cwiseAbs().maxCoeff());  // validate_inertia's tolerance
  if (o.inertia_repair == InertiaRepair::Balance && e(2) > e(0) + e(1) + tol) {
    const Vector3 b = e;
    const double deficit = e(2) - e(0) - e(1);
    e(0) += 0.5 * deficit;
    e(1) += 0.5 * deficit;
    repairs.push_back(
        {link, "principal moments balanced (triangle inequality)", {b(0), b(1), b(2)}, {e(0), e(1), e(2)}});
  }
  if (e != before) out.I = es.eigenvectors() * e.asDiagonal() * es.eigenvectors().transpose();
  return out;
}

/// The pose of a joint's child frame in its parent link frame with the joint at q (a locked joint).
inline Pose joint_pose_at(const Pose& origin, bool revolute, const Vector3& axis, double q) {
  const Vector3 a = axis.normalized();
  return origin * (revolute ? Pose{Vector3::Zero(), rotation_about(a, q)} : Pose{a * q, Matrix3::Identity()});
}

/// Order of the <joint> elements in the document (urdfdom keeps joints in a map by name).
inline std::map<std::string, int> joint_order_in_file(const std::string& xml) {
  std::map<std::string, int> order;
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  int k = 0;
  for (const TiXmlElement* j = robot ? robot->FirstChildElement("joint") : nullptr; j;
       j = j->NextSiblingElement("joint"))
    if (const char* name = j->Attribute("name")) order.emplace(name, k++);
  return order;
}

/// A <joint> element as an edge of the link graph: the joint's name and its child link.
struct JointEdge {
  std::string joint, child;
};

/// The <joint> elements of a URDF document as a graph of links: parent link -> edges to its
/// children, in file order. Elements without a parent or child link are left out (urdfdom rejects
/// them). Reads the document only.
inline std::map<std::string, std::vector<JointEdge>> joint_edges_in_file(const std::string& xml) {
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  std::map<std::string, std::vector<JointEdge>> children;  // parent link -> joints to its children
  for (const TiXmlElement* j = robot ? robot->FirstChildElement("joint") : nullptr; j;
       j = j->NextSiblingElement("joint")) {
    const TiXmlElement* p = j->FirstChildElement("parent");
    const TiXmlElement* c = j->FirstChildElement("child");
    const char* parent = p ? p->Attribute("link") : nullptr;
    const char* child = c ? c->Attribute("link") : nullptr;
    const char* name = j->Attribute("name");
    if (parent && child) children[parent].push_back({name ? name : "", child});
  }
  return children;
}

/// One link on the depth-first path of reject_joint_loops.
struct LinkPathStep {
  std::string link;
  size_t next = 0;
  std::string via;  // the joint that led here
};

/// The ModelError for a closed loop: the path from `e.child` to the last step, closed by `e`.
inline ModelError joint_loop_error(const std::vector<LinkPathStep>& path, const JointEdge& e,
                                   const std::string& source) {
  std::string loop;
  size_t k = 0;
  while (path[k].link != e.child) ++k;
  for (size_t i = k + 1; i < path.size(); ++i)
    loop += str("'", path[i].via, "' ('", path[i - 1].link, "' -> '", path[i].link, "'), ");
  loop += str("'", e.joint, "' ('", path.back().link, "' -> '", e.child, "')");
  return ModelError(
      str(source, ": the joints ", loop, " form a closed loop (closed loops are not supported)"));
}

/// Throws ModelError when the <joint> elements of a URDF document form a directed loop of links
/// (a link that is its own ancestor). urdfdom links a parent to its children through shared_ptr, so
/// such a loop is a reference cycle, and when urdfdom then rejects the file for another reason it
/// returns nothing and the cycle leaks (found by fuzz_urdf). The loop is rejected before urdfdom sees
/// the file. Each joint is followed once: O(joints).
inline void reject_joint_loops(const std::string& xml, const std::string& source) {
  const std::map<std::string, std::vector<JointEdge>> children = joint_edges_in_file(xml);
  // Depth-first search with an explicit stack; state 1 = on the current path, 2 = done.
  std::map<std::string, int> state;
  for (const auto& start : children) {
    if (state[start.first] != 0) continue;
    std::vector<LinkPathStep> path{{start.first, 0, ""}};
    state[start.first] = 1;
    while (!path.empty()) {
      LinkPathStep& top = path.back();
      const auto it = children.find(top.link);
      if (it == children.end() || top.next >= it->second.size()) {
        state[top.link] = 2;
        path.pop_back();
        continue;
      }
      const JointEdge e = it->second[top.next++];
      int& st = state[e.child];
      if (st == 1) throw joint_loop_error(path, e, source);  // back edge: a loop closed by e.joint
      if (st == 0) {
        st = 1;
        path.push_back({e.child, 0, e.joint});
      }
    }
  }
}

// --- the loader's steps, in the order model_from_urdf_string runs them --------------------------

/// urdfdom's model of a file, owned so that the links' child pointers are cleared when it goes:
/// urdfdom's links own their children through shared_ptr, and a loop in a malformed file is a cycle
/// that would leak. The cycles are broken on every way out of the loader.
struct UrdfDocument {
  urdf::ModelInterfaceSharedPtr model;
  explicit UrdfDocument(urdf::ModelInterfaceSharedPtr m) : model(std::move(m)) {}
  UrdfDocument(UrdfDocument&&) = default;
  UrdfDocument(const UrdfDocument&) = delete;
  UrdfDocument& operator=(const UrdfDocument&) = delete;
  ~UrdfDocument() {
    if (model)
      for (const auto& lp : model->links_) lp.second->child_links.clear();
  }
};

/// Throws ModelError when a link is the child of two joints. urdfdom keeps only the last parent
/// joint of a link with several, so a closed loop is found here, by child name: every joint must
/// be reachable from the root exactly once (one tree).
inline void require_one_parent_per_link(const urdf::ModelInterface& urdf, const std::string& source) {
  std::map<std::string, std::string> parent_joint_of;
  for (const auto& jp : urdf.joints_) {
    const auto [it, inserted] = parent_joint_of.emplace(jp.second->child_link_name, jp.first);
    if (!inserted)
      throw ModelError(str(source, ": link '", jp.second->child_link_name, "' has two parent joints ('",
                           it->second, "' and '", jp.first, "'): closed loops are not supported"));
  }
}

/// Parses and validates the file as a document: UTF-8 text, no loop of joints, accepted by
/// urdfdom without a logged error, a root link, one parent joint per link. Every error is a
/// ModelError naming `source`. Reads `xml` only.
inline UrdfDocument parse_urdf_document(const std::string& xml, const std::string& source) {
  require_utf8(xml, source);
  urdf::ModelInterfaceSharedPtr parsed;
  std::string urdf_errors;
  reject_joint_loops(xml, source);
  {
    UrdfLogCapture capture;
    try {
      parsed = urdf::parseURDF(xml);
    } catch (const std::exception& e) {
      throw ModelError(str(source, ": malformed URDF: ", e.what()));
    }
    if (!parsed)
      throw ModelError(
          str(source, ": malformed URDF", capture.messages.empty() ? "" : ": " + capture.messages));
    urdf_errors = capture.messages;
  }
  UrdfDocument doc(std::move(parsed));  // breaks the cycles from here on, also on the throws below
  // urdfdom ignores the result of parsing a <link>: a link whose <inertial> fails to parse (a mass
  // or moment that is not a number, "inf") is kept with zeros after logging an error. Any error it
  // logged is a malformed file.
  if (!urdf_errors.empty()) throw ModelError(str(source, ": malformed URDF: ", urdf_errors));
  if (!doc.model->getRoot()) throw ModelError(str(source, ": URDF has no root link"));
  require_one_parent_per_link(*doc.model, source);
  return doc;
}

/// True for the joint types that move (revolute, continuous, prismatic).
inline bool urdf_joint_moves(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::PRISMATIC ||
         j.type == urdf::Joint::CONTINUOUS;
}

/// The names of the moving joints, comma-separated (for the message of an unknown lock).
inline std::string moving_joint_list(const urdf::ModelInterface& urdf) {
  std::string list;
  for (const auto& jp : urdf.joints_)
    if (jp.second->type != urdf::Joint::FIXED) list += (list.empty() ? "" : ", ") + jp.first;
  return list;
}

/// The locked joints of `opt.locks` by name, each checked: a moving joint of the file, locked
/// once, at a finite value inside its limits. Throws InputError naming the option.
inline std::map<std::string, double> locked_joint_values(const urdf::ModelInterface& urdf,
                                                         const UrdfOptions& opt) {
  std::map<std::string, double> locked;
  for (const auto& [name, value] : opt.locks) {
    const auto it = urdf.joints_.find(name);
    if (it == urdf.joints_.end())
      throw InputError(
          str("lock-joints: unknown joint '", name, "'; the moving joints are: ", moving_joint_list(urdf)));
    const urdf::Joint& j = *it->second;
    if (j.type == urdf::Joint::FIXED)
      throw InputError(str("lock-joints: joint '", name, "' is a fixed joint already"));
    if (!urdf_joint_moves(j))
      throw InputError(str("lock-joints: joint '", name, "' is not revolute, continuous or prismatic"));
    if (!std::isfinite(value))
      throw InputError(str("lock-joints: joint '", name, "': the value must be finite"));
    if (j.type != urdf::Joint::CONTINUOUS && j.limits &&
        !(j.limits->lower == 0.0 && j.limits->upper == 0.0) &&
        (value < j.limits->lower || value > j.limits->upper))
      throw InputError(str("lock-joints: '", name, "=", value, "' is outside the joint's limits [",
                           j.limits->lower, ", ", j.limits->upper, "]"));
    if (!locked.emplace(name, value).second)
      throw InputError(str("lock-joints: joint '", name, "' is locked twice"));
  }
  return locked;
}

/// The value the joint `j` is locked at: its own (in `locked`), or through its chain of mimic
/// leaders, q_f = m q_l + o composed along the chain. None when neither it nor a leader is locked,
/// and for an unknown leader or a mimic loop (ModelBuilder::build reports those).
inline std::optional<double> locked_value(const urdf::ModelInterface& urdf,
                                          const std::map<std::string, double>& locked, const urdf::Joint& j) {
  const urdf::Joint* cur = &j;
  double mult = 1.0, off = 0.0;
  for (size_t depth = 0; depth <= urdf.joints_.size(); ++depth) {
    const auto it = locked.find(cur->name);
    if (it != locked.end()) return mult * it->second + off;
    if (!cur->mimic) return std::nullopt;
    const auto lt = urdf.joints_.find(cur->mimic->joint_name);
    if (lt == urdf.joints_.end()) return std::nullopt;  // unknown leader: ModelBuilder::build reports it
    off += mult * cur->mimic->offset;
    mult *= cur->mimic->multiplier;
    cur = lt->second.get();
  }
  return std::nullopt;  // a mimic loop: ModelBuilder::build reports it
}

/// The inertia of `link` in its frame, repaired as `opt` asks (each repair appended to `repairs`),
/// then validated; a ModelError names the link and the options that would load the file as it is.
inline Inertia checked_link_inertia(const urdf::Link& l, const UrdfOptions& opt,
                                    std::vector<ModelRepair>& repairs) {
  Inertia in = urdf_inertia(l);
  if (l.inertial) in = repaired_inertia(in, l.name, opt, repairs);
  try {
    validate_inertia(in, "link '" + l.name + "'", false);
  } catch (const ModelError& e) {
    throw ModelError(
        str(e.what(), " (to load the file as it is: inertia-repair = \"balance\", min-mass, min-inertia)"));
  }
  return in;
}

/// Throws InputError, naming the option, unless the bus has a positive finite mass, finite
/// centre of mass and mount pose, and a valid inertia.
inline void validate_bus(const Bus& bus) {
  if (!std::isfinite(bus.mass) || bus.mass <= 0)
    throw InputError(str("bus-mass: must be positive and finite, got ", bus.mass));
  if (!bus.com.allFinite()) throw InputError("bus-com: values must be finite");
  if (!bus.mount.p.allFinite() || !bus.mount.R.allFinite())
    throw InputError("mount-xyz/mount-rpy-deg: values must be finite");
  try {
    validate_inertia({bus.mass, bus.com, bus.inertia}, "the bus", true);
  } catch (const ModelError& e) {
    throw InputError(str("bus-inertia: ", e.what()));
  }
}

/// The builder with its base: the bus (opt.bus) with the root link merged into it at the mount
/// pose, or the root link itself, which then needs an <inertial> with a positive mass.
inline ModelBuilder base_builder(const urdf::Link& root, const Inertia& root_inertia,
                                 const UrdfOptions& opt) {
  if (opt.bus) {
    const Bus& bus = *opt.bus;
    validate_bus(bus);
    ModelBuilder builder(bus.name, Inertia{bus.mass, bus.com, bus.inertia});
    builder.add_fixed("mount", bus.name, bus.mount, root.name, root_inertia);
    return builder;
  }
  const char* hint =
      "; to mount the arm on a spacecraft bus give bus-mass, bus-inertia, bus-com, mount-xyz, "
      "mount-rpy-deg";
  if (!root.inertial)
    throw ModelError(str("base link '", root.name, "': has no <inertial> (the base needs a mass", hint, ")"));
  if (root.inertial->mass <= 0)
    throw ModelError(
        str("base link '", root.name, "': mass must be positive, got ", root.inertial->mass, hint));
  return ModelBuilder(root.name, root_inertia);
}

/// Adds the moving joint `j` locked at `q` as a fixed joint: the child frame at its pose for q
/// (joint_pose_at), the link merged into its parent's body. Records the lock in `rep.locked`.
inline void add_locked_joint(ModelBuilder& builder, const urdf::Joint& j, const urdf::Link& link,
                             const Pose& origin, const Inertia& inertia, double q, UrdfReport& rep) {
  const Vector3 axis(j.axis.x, j.axis.y, j.axis.z);
  if (!axis.allFinite() || axis.norm() < 1e-12)
    throw ModelError(str("joint '", j.name, "': axis must be a finite non-zero vector"));
  builder.add_fixed(j.name, j.parent_link_name,
                    joint_pose_at(origin, j.type != urdf::Joint::PRISMATIC, axis, q), link.name, inertia);
  rep.locked.emplace_back(j.name, q);
}

/// Adds the joint `j` to `link` as it is in the file: a fixed joint merges the link into its
/// parent's body (ModelBuilder::add_fixed); a revolute or prismatic joint keeps its limits (none
/// when both are 0, URDF's default); a continuous joint is an unlimited revolute one; a moving
/// joint with <mimic> follows its leader (ModelBuilder::set_mimic). Other types are a ModelError.
inline void add_urdf_joint(ModelBuilder& builder, const urdf::Joint& j, const urdf::Link& link,
                           const Pose& origin, const Inertia& inertia) {
  const Vector3 axis(j.axis.x, j.axis.y, j.axis.z);
  switch (j.type) {
    case urdf::Joint::FIXED:
      builder.add_fixed(j.name, j.parent_link_name, origin, link.name, inertia);
      break;
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::PRISMATIC: {
      if (!j.limits)
        throw ModelError(str("joint '", j.name, "': a revolute or prismatic joint needs <limit>"));
      const double lo = j.limits->lower, hi = j.limits->upper;
      const bool unlimited = lo == 0.0 && hi == 0.0;  // URDF's default when lower/upper are omitted
      builder.add_joint(j.name, j.type == urdf::Joint::REVOLUTE ? JointType::Revolute : JointType::Prismatic,
                        j.parent_link_name, origin, axis, link.name, inertia,
                        unlimited ? -std::numeric_limits<double>::infinity() : lo,
                        unlimited ? std::numeric_limits<double>::infinity() : hi, j.limits->effort);
      break;
    }
    case urdf::Joint::CONTINUOUS:
      builder.add_joint(j.name, JointType::Revolute, j.parent_link_name, origin, axis, link.name, inertia,
                        -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                        j.limits ? j.limits->effort : 0.0);
      break;
    default:
      throw ModelError(str("joint '", j.name,
                           "': unsupported joint type (only revolute, continuous, prismatic "
                           "and fixed are supported)"));
  }
  if (urdf_joint_moves(j) && j.mimic)
    builder.set_mimic(j.name, j.mimic->joint_name, j.mimic->multiplier, j.mimic->offset);
}

/// Visits every link below `root` depth-first, siblings in the file order of their joints
/// (`file_order`, from joint_order_in_file), calling `visit(link, parent_joint)`. Throws
/// ModelError for a link without a parent joint or reached twice. Returns the names reached,
/// the root included.
template <class Visit>
std::set<std::string> walk_urdf_tree(const urdf::LinkConstSharedPtr& root,
                                     const std::map<std::string, int>& file_order, Visit&& visit) {
  auto in_file_order = [&](const urdf::LinkSharedPtr& a, const urdf::LinkSharedPtr& b) {
    const auto ia = file_order.find(a->parent_joint->name), ib = file_order.find(b->parent_joint->name);
    const int oa = ia == file_order.end() ? 0 : ia->second, ob = ib == file_order.end() ? 0 : ib->second;
    return oa != ob ? oa < ob : a->parent_joint->name < b->parent_joint->name;
  };
  std::set<std::string> visited{root->name};
  std::vector<urdf::LinkConstSharedPtr> stack{root};
  while (!stack.empty()) {
    const urdf::LinkConstSharedPtr link = stack.back();
    stack.pop_back();
    std::vector<urdf::LinkSharedPtr> children = link->child_links;
    std::sort(children.begin(), children.end(), in_file_order);
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back(*it);  // DFS in file order
    if (link == root) continue;
    const urdf::JointConstSharedPtr j = link->parent_joint;
    if (!j) throw ModelError(str("link '", link->name, "' has no parent joint"));
    if (!visited.insert(link->name).second)
      throw ModelError(str("link '", link->name, "' is reached twice (closed loop)"));
    visit(*link, *j);
  }
  return visited;
}

/// Throws ModelError naming the links of the file that `visited` (walk_urdf_tree) lacks.
inline void require_all_links_reached(const urdf::ModelInterface& urdf,
                                      const std::set<std::string>& visited) {
  if (visited.size() == urdf.links_.size()) return;
  std::string orphans;
  for (const auto& l : urdf.links_)
    if (!visited.count(l.first)) orphans += (orphans.empty() ? "" : ", ") + l.first;
  throw ModelError(str("links not connected to the root '", urdf.getRoot()->name, "': ", orphans));
}

/// Sets the end-effector of `opt` (name, contact offset) and builds the model (mimic chains
/// resolved, moving links validated: ModelBuilder::build).
inline Model built_model(ModelBuilder& builder, const UrdfOptions& opt) {
  if (!opt.end_effector.empty()) builder.set_end_effector(opt.end_effector);
  if (opt.end_effector_offset) {
    if (!opt.end_effector_offset->allFinite())
      throw InputError("end-effector-offset: expected 3 finite numbers");
    builder.set_end_effector_offset(*opt.end_effector_offset);
  }
  return builder.build();
}

/// Adds to `rep` what the built model shows: the links merged into the base body (its frames other
/// than the base's own and the end-effector's) and the mimic joints with their resolved leaders.
inline void report_merged_links_and_mimics(const Model& model, UrdfReport& rep) {
  for (const auto& f : model.frames())
    if (f.body == 0 && f.name != model.body(0).name && f.name != model.frame(model.end_effector()).name)
      rep.merged_links.push_back(f.name);
  for (const auto& b : model.bodies())
    if (!b.leader.empty()) rep.mimics.push_back({b.joint.name, b.leader, b.multiplier, b.offset});
}

/// The model of a parsed document (parse_urdf_document): locks checked, the base built, every
/// link added in the tree walk (locked, fixed and merged, or moving), all links reached, then
/// built. Errors name the element or the option; model_from_urdf_string prefixes the file.
inline Model model_from_urdf_document(const urdf::ModelInterface& urdf, const std::string& xml,
                                      const std::string& source, const UrdfOptions& opt, UrdfReport* report) {
  const std::map<std::string, int> file_order = joint_order_in_file(xml);
  UrdfReport rep;
  const std::map<std::string, double> locked = locked_joint_values(urdf, opt);
  const urdf::LinkConstSharedPtr root = urdf.getRoot();
  ModelBuilder builder = base_builder(*root, checked_link_inertia(*root, opt, rep.repairs), opt);
  builder.set_source(source);
  const std::set<std::string> visited =
      walk_urdf_tree(root, file_order, [&](const urdf::Link& link, const urdf::Joint& j) {
        const Pose origin = urdf_pose(j.parent_to_joint_origin_transform);
        const Inertia inertia = checked_link_inertia(link, opt, rep.repairs);
        const std::optional<double> q = urdf_joint_moves(j) ? locked_value(urdf, locked, j) : std::nullopt;
        if (q)
          add_locked_joint(builder, j, link, origin, inertia, *q, rep);
        else
          add_urdf_joint(builder, j, link, origin, inertia);
      });
  require_all_links_reached(urdf, visited);
  Model model = built_model(builder, opt);
  if (report) {
    report_merged_links_and_mimics(model, rep);
    *report = std::move(rep);
  }
  return model;
}

}  // namespace detail

}  // namespace ffsr
