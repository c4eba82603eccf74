// ffsr/io/urdf.hpp -- URDF -> Model, through urdfdom. Link with ffsr::urdf.
//
// The root link is the free-floating base. Revolute, continuous and prismatic joints move; fixed
// joints merge their child's inertia into the parent body and keep the child as a named frame.
// Joint order: depth-first from the root, siblings in the order of their <joint> elements in the
// file. The loader validates rather than repairs; every error is a ModelError naming the file and
// the element.
#pragma once

#include "ffsr/model/model.hpp"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
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
      if ((b[i + k] >> 6) != 0x2) throw ModelError(str(source, ": not a text file in UTF-8 (byte ", i + k, ")"));
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

/// Order of the <joint> elements in the document (urdfdom keeps joints in a map by name).
inline std::map<std::string, int> joint_order_in_file(const std::string& xml) {
  std::map<std::string, int> order;
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  int k = 0;
  for (const TiXmlElement* j = robot ? robot->FirstChildElement("joint") : nullptr; j; j = j->NextSiblingElement("joint"))
    if (const char* name = j->Attribute("name")) order.emplace(name, k++);
  return order;
}

/// Throws ModelError when the <joint> elements of a URDF document form a directed loop of links
/// (a link that is its own ancestor). urdfdom links a parent to its children through shared_ptr, so
/// such a loop is a reference cycle, and when urdfdom then rejects the file for another reason it
/// returns nothing and the cycle leaks (found by fuzz_urdf). The loop is rejected before urdfdom sees
/// the file. Each joint is followed once: O(joints).
inline void reject_joint_loops(const std::string& xml, const std::string& source) {
  TiXmlDocument doc;
  doc.Parse(xml.c_str());
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  struct Edge {
    std::string joint, child;
  };
  std::map<std::string, std::vector<Edge>> children;  // parent link -> joints to its children
  for (const TiXmlElement* j = robot ? robot->FirstChildElement("joint") : nullptr; j; j = j->NextSiblingElement("joint")) {
    const TiXmlElement* p = j->FirstChildElement("parent");
    const TiXmlElement* c = j->FirstChildElement("child");
    const char* parent = p ? p->Attribute("link") : nullptr;
    const char* child = c ? c->Attribute("link") : nullptr;
    const char* name = j->Attribute("name");
    if (parent && child) children[parent].push_back({name ? name : "", child});
  }
  // Depth-first search with an explicit stack; state 1 = on the current path, 2 = done.
  std::map<std::string, int> state;
  for (const auto& start : children) {
    if (state[start.first] != 0) continue;
    struct Frame {
      std::string link;
      size_t next = 0;
      std::string via;  // the joint that led here
    };
    std::vector<Frame> path{{start.first, 0, ""}};
    state[start.first] = 1;
    while (!path.empty()) {
      Frame& top = path.back();
      const auto it = children.find(top.link);
      if (it == children.end() || top.next >= it->second.size()) {
        state[top.link] = 2;
        path.pop_back();
        continue;
      }
      const Edge e = it->second[top.next++];
      int& st = state[e.child];
      if (st == 1) {  // back edge: the loop is the path from e.child to here, closed by e.joint
        std::string loop;
        size_t k = 0;
        while (path[k].link != e.child) ++k;
        for (size_t i = k + 1; i < path.size(); ++i)
          loop += str("'", path[i].via, "' ('", path[i - 1].link, "' -> '", path[i].link, "'), ");
        loop += str("'", e.joint, "' ('", top.link, "' -> '", e.child, "')");
        throw ModelError(str(source, ": the joints ", loop, " form a closed loop (closed loops are not supported)"));
      }
      if (st == 0) {
        st = 1;
        path.push_back({e.child, 0, e.joint});
      }
    }
  }
}

}  // namespace detail

/// Builds a Model from URDF text. `source` names the file in error messages. `end_effector` names
/// the end-effector frame (a link name); empty means the single leaf link.
inline Model model_from_urdf_string(const std::string& xml, const std::string& source = "<string>",
                                    const std::string& end_effector = "") {
  using detail::str;
  detail::require_utf8(xml, source);
  urdf::ModelInterfaceSharedPtr urdf;
  std::string urdf_errors;
  detail::reject_joint_loops(xml, source);
  {
    detail::UrdfLogCapture capture;
    try {
      urdf = urdf::parseURDF(xml);
    } catch (const std::exception& e) {
      throw ModelError(str(source, ": malformed URDF: ", e.what()));
    }
    if (!urdf)
      throw ModelError(str(source, ": malformed URDF", capture.messages.empty() ? "" : ": " + capture.messages));
    urdf_errors = capture.messages;
  }
  // urdfdom's links own their children through shared_ptr: a loop in a malformed file is a cycle that
  // would leak. Break it on every way out of this function (set up before the first throw below).
  struct BreakCycles {
    urdf::ModelInterface& m;
    ~BreakCycles() {
      for (const auto& lp : m.links_) lp.second->child_links.clear();
    }
  } break_cycles{*urdf};
  // urdfdom ignores the result of parsing a <link>: a link whose <inertial> fails to parse (a mass
  // or moment that is not a number, "inf") is kept with zeros after logging an error. Any error it
  // logged is a malformed file.
  if (!urdf_errors.empty()) throw ModelError(str(source, ": malformed URDF: ", urdf_errors));
  const urdf::LinkConstSharedPtr root = urdf->getRoot();
  if (!root) throw ModelError(str(source, ": URDF has no root link"));

  // Every joint must be reachable from the root exactly once (no loops, one tree). urdfdom keeps only
  // the last parent joint of a link with several, so a closed loop is found here, by child name.
  {
    std::map<std::string, std::string> parent_joint_of;
    for (const auto& jp : urdf->joints_) {
      const auto [it, inserted] = parent_joint_of.emplace(jp.second->child_link_name, jp.first);
      if (!inserted)
        throw ModelError(str(source, ": link '", jp.second->child_link_name, "' has two parent joints ('", it->second,
                             "' and '", jp.first, "'): closed loops are not supported"));
    }
  }
  const std::map<std::string, int> file_order = detail::joint_order_in_file(xml);
  auto in_file_order = [&](const urdf::LinkSharedPtr& a, const urdf::LinkSharedPtr& b) {
    const auto ia = file_order.find(a->parent_joint->name), ib = file_order.find(b->parent_joint->name);
    const int oa = ia == file_order.end() ? 0 : ia->second, ob = ib == file_order.end() ? 0 : ib->second;
    return oa != ob ? oa < ob : a->parent_joint->name < b->parent_joint->name;
  };

  try {
    ModelBuilder builder(root->name, detail::urdf_inertia(*root));
    builder.set_source(source);
    if (root->inertial && root->inertial->mass <= 0)
      throw ModelError(str("base link '", root->name, "': mass must be positive, got ", root->inertial->mass));
    if (!root->inertial) throw ModelError(str("base link '", root->name, "': has no <inertial> (the base needs a mass)"));
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
      if (!visited.insert(link->name).second) throw ModelError(str("link '", link->name, "' is reached twice (closed loop)"));
      if (j->mimic) throw ModelError(str("joint '", j->name, "': mimic joints are not supported"));
      const Pose origin = detail::urdf_pose(j->parent_to_joint_origin_transform);
      const Inertia inertia = detail::urdf_inertia(*link);
      const Vector3 axis(j->axis.x, j->axis.y, j->axis.z);
      switch (j->type) {
        case urdf::Joint::FIXED:
          builder.add_fixed(j->name, j->parent_link_name, origin, link->name, inertia);
          break;
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::PRISMATIC: {
          if (!j->limits) throw ModelError(str("joint '", j->name, "': a revolute or prismatic joint needs <limit>"));
          const double lo = j->limits->lower, hi = j->limits->upper;
          const bool unlimited = lo == 0.0 && hi == 0.0;  // URDF's default when lower/upper are omitted
          builder.add_joint(j->name, j->type == urdf::Joint::REVOLUTE ? JointType::Revolute : JointType::Prismatic,
                            j->parent_link_name, origin, axis, link->name, inertia,
                            unlimited ? -std::numeric_limits<double>::infinity() : lo,
                            unlimited ? std::numeric_limits<double>::infinity() : hi);
          break;
        }
        case urdf::Joint::CONTINUOUS:
          builder.add_joint(j->name, JointType::Revolute, j->parent_link_name, origin, axis, link->name, inertia);
          break;
        default:
          throw ModelError(str("joint '", j->name, "': unsupported joint type (only revolute, continuous, prismatic "
                               "and fixed are supported)"));
      }
    }
    if (visited.size() != urdf->links_.size()) {
      std::string orphans;
      for (const auto& l : urdf->links_)
        if (!visited.count(l.first)) orphans += (orphans.empty() ? "" : ", ") + l.first;
      throw ModelError(str("links not connected to the root '", root->name, "': ", orphans));
    }
    if (!end_effector.empty()) builder.set_end_effector(end_effector);
    return builder.build();
  } catch (const ModelError& e) {
    throw ModelError(str(source, ": ", e.what()));
  } catch (const InputError& e) {
    throw InputError(str(source, ": ", e.what()));
  }
}

/// Builds a Model from a URDF file (see model_from_urdf_string).
inline Model model_from_urdf_file(const std::string& path, const std::string& end_effector = "") {
  // Only regular files of a sane size: /dev/zero or a FIFO would be read forever.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw ModelError(detail::str(path, ": cannot open the URDF file"));
  if (!std::filesystem::is_regular_file(status)) throw ModelError(detail::str(path, ": not a regular file"));
  const auto size = std::filesystem::file_size(path, ec);
  constexpr std::uintmax_t kMaxBytes = 64u << 20;
  if (ec || size > kMaxBytes) throw ModelError(detail::str(path, ": the URDF file is larger than 64 MiB"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelError(detail::str(path, ": cannot open the URDF file"));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ModelError(detail::str(path, ": cannot read the URDF file"));
  return model_from_urdf_string(ss.str(), path, end_effector);
}

}  // namespace ffsr
