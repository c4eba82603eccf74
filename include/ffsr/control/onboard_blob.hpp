// ffsr/control/onboard_blob.hpp -- a controller's whole set-up as one array of doubles (the onboard
// blob): written on the host from a validated problem (capture_blob, detumble_blob), read back on the
// flight computer into the same Model, problem and settings (read_capture_blob, read_detumble_blob)
// without exceptions, with a status for every defect. The C interface (ffsr/onboard.h) builds its
// controllers from it.
//
// Layout (every entry a double; integers and flags are exact integers):
//   header  [0] magic 1718383474 ("ffsr"), [1] version, [2] kind (1 capture, 2 detumble), [3] count
//           of entries, [4] [5] the checksum of entries 8..count as two 32-bit halves (FNV-1a over
//           each entry's 64 bits), [6] [7] zero
//   model   bodies, frames, end-effector frame (-1: none), gravity (3); per body: parent, joint type
//           (0 revolute, 1 prismatic), axis (3), lower, upper, effort, origin position (3) and
//           rotation (9, row-major), mass, centre of mass (3), inertia (9), leader body (-1: none),
//           multiplier, offset; per frame: body, position (3), rotation (9)
//   capture frame, base position (3), quaternion (x y z w), joint angles (n), target (mass, inertia
//           (9), position (3), attitude (4), velocity (3), angular velocity (3), contact offset (3),
//           normal (3)), K, alpha, c_r, contact law (index in contact_law_names()), approach speed,
//           joint model, armature (n), task (kind, three axes, has orientation, orientation (9)),
//           options (duration, step, gain, feedback, tolerance, orientation tolerance, objective,
//           singular value threshold, largest damping, largest joint rate, hold base attitude),
//           controller options (quaternion tolerance, prediction window), policy (0 gradient, 1
//           servo), servo gain, servo goal (n)
//   detumble gripper frame, attached body (mass, inertia (9), position (3), rotation (9)), joint
//           torque limits (n), actuator (0 none, 1 wheels, 2 thrusters), wheel torque and momentum,
//           thruster force and torque, gripper force and moment limits (inf: none), largest decay,
//           largest base decay, rest rate, stop stack spin, hold, tick; the stack's state at the start
//           (base position (3), quaternion (4), joint angles (n), velocity (6 + n), wheel momentum (3))
//
// The host writes a blob only from a problem the library accepted (the controller is built from the
// blob read back before it is returned), so a blob whose checksum holds builds its controller; the
// reader checks the header, the checksum, the counts, the indices and that every value is finite
// (joint limits may be infinite), and reports the first defect.
#pragma once

#include "ffsr/control/capture_controller.hpp"
#include "ffsr/control/detumble_controller.hpp"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace ffsr {

inline constexpr double kOnboardBlobMagic = 1718383474.0;  // the bytes "ffsr" read as a big-endian integer
inline constexpr int kOnboardBlobVersion = 1;
inline constexpr int kOnboardBlobHeader = 8;

enum class BlobKind { Capture = 1, Detumble = 2 };

/// The first defect a reader found (Ok: none).
enum class BlobStatus { Ok, TooShort, Magic, Version, Kind, Count, Checksum, Layout, NotFinite };

inline const char* blob_status_name(BlobStatus s) noexcept {
  switch (s) {
    case BlobStatus::Ok:
      return "ok";
    case BlobStatus::TooShort:
      return "shorter than its header";
    case BlobStatus::Magic:
      return "not an ffsr blob (magic)";
    case BlobStatus::Version:
      return "another version of the blob";
    case BlobStatus::Kind:
      return "a blob of another controller";
    case BlobStatus::Count:
      return "its count of entries is not its length";
    case BlobStatus::Checksum:
      return "its checksum does not hold (altered or truncated)";
    case BlobStatus::Layout:
      return "a count or an index out of range";
    case BlobStatus::NotFinite:
      return "a value that is not finite";
  }
  return "?";
}

/// The capture controller's set-up read from a blob. Holds the Model the problem points at: it is
/// neither copied nor moved (the problem's pointer would dangle).
struct CaptureBlob {
  Model model;
  CaptureProblem problem;
  CaptureTask task;
  CaptureOptions options;
  ControllerOptions controller;
  bool servo = false;  ///< the servo policy (else the gradient policy, the paper's method)
  ServoPolicy servo_policy;
  CaptureBlob() = default;
  CaptureBlob(const CaptureBlob&) = delete;
  CaptureBlob& operator=(const CaptureBlob&) = delete;
};

/// The detumbling controller's set-up read from a blob (the stack model, the robot with the target
/// attached at the gripper; the state at the start).
struct DetumbleBlob {
  Model stack;
  int gripper = -1;
  AttachedBody body;
  DetumbleLimits limits;
  DetumbleOptions options;
  double tick = 0.01;
  DetumbleState start;
};

namespace detail {

/// FNV-1a over the 64 bits of each entry (the same on every IEEE-754 target, whatever its byte order).
inline std::uint64_t blob_checksum(const double* x, std::size_t count) noexcept {
  std::uint64_t h = 14695981039346656037ULL;
  for (std::size_t i = 0; i < count; ++i) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &x[i], sizeof bits);
    for (int byte = 0; byte < 8; ++byte) {
      h ^= (bits >> (8 * byte)) & 0xffU;
      h *= 1099511628211ULL;
    }
  }
  return h;
}

/// Appends values to a blob.
class BlobWriter {
 public:
  explicit BlobWriter(BlobKind kind) : v_(kOnboardBlobHeader, 0.0) {
    v_[0] = kOnboardBlobMagic;
    v_[1] = kOnboardBlobVersion;
    v_[2] = static_cast<double>(kind);
  }
  void put(double x) { v_.push_back(x); }
  template <class Derived>
  void put(const Eigen::MatrixBase<Derived>& m) {  // row-major
    for (Eigen::Index r = 0; r < m.rows(); ++r)
      for (Eigen::Index c = 0; c < m.cols(); ++c) v_.push_back(m(r, c));
  }
  void put(const Quaternion& q) { put(q.coeffs()); }  // x y z w
  std::vector<double> finish() {
    v_[3] = static_cast<double>(v_.size());
    const std::uint64_t h = blob_checksum(v_.data() + kOnboardBlobHeader, v_.size() - kOnboardBlobHeader);
    v_[4] = static_cast<double>(h >> 32);
    v_[5] = static_cast<double>(h & 0xffffffffULL);
    return std::move(v_);
  }

 private:
  std::vector<double> v_;
};

/// Reads values from a blob; the first defect sticks (later reads give 0).
class BlobReader {
 public:
  BlobReader(const double* x, std::size_t count) noexcept : x_(x), n_(count), i_(kOnboardBlobHeader) {}
  BlobStatus status() const noexcept { return status_; }
  bool ok() const noexcept { return status_ == BlobStatus::Ok; }
  void fail(BlobStatus s) noexcept {
    if (ok()) status_ = s;
  }
  bool at_end() const noexcept { return i_ == n_; }
  /// A finite value (or, with `infinite_ok`, an infinite one; never NaN).
  double real(bool infinite_ok = false) noexcept {
    if (!ok()) return 0;
    if (i_ >= n_) {
      fail(BlobStatus::Layout);
      return 0;
    }
    const double v = x_[i_++];
    if (std::isnan(v) || (!infinite_ok && std::isinf(v))) {
      fail(BlobStatus::NotFinite);
      return 0;
    }
    return v;
  }
  /// An integer in [lo, hi].
  int integer(int lo, int hi) noexcept {
    const double v = real();
    if (!ok()) return lo;
    if (v != std::floor(v) || v < lo || v > hi) {
      fail(BlobStatus::Layout);
      return lo;
    }
    return static_cast<int>(v);
  }
  bool flag() noexcept { return integer(0, 1) == 1; }
  template <class Derived>
  void get(Eigen::MatrixBase<Derived>& m) noexcept {  // row-major
    for (Eigen::Index r = 0; r < m.rows(); ++r)
      for (Eigen::Index c = 0; c < m.cols(); ++c) m(r, c) = real();
  }
  void get(Quaternion& q) noexcept {
    Eigen::Vector4d c;
    get(c);
    q.coeffs() = c;
  }

 private:
  const double* x_;
  std::size_t n_, i_;
  BlobStatus status_ = BlobStatus::Ok;
};

/// The header's checks: magic, version, kind, count, checksum.
inline BlobStatus check_blob_header(const double* x, std::size_t count, BlobKind kind) noexcept {
  if (x == nullptr || count < static_cast<std::size_t>(kOnboardBlobHeader)) return BlobStatus::TooShort;
  if (x[0] != kOnboardBlobMagic) return BlobStatus::Magic;
  if (x[1] != kOnboardBlobVersion) return BlobStatus::Version;
  if (x[2] != static_cast<double>(kind)) return BlobStatus::Kind;
  if (x[3] != static_cast<double>(count)) return BlobStatus::Count;
  const std::uint64_t h = blob_checksum(x + kOnboardBlobHeader, count - kOnboardBlobHeader);
  if (x[4] != static_cast<double>(h >> 32) || x[5] != static_cast<double>(h & 0xffffffffULL))
    return BlobStatus::Checksum;
  return BlobStatus::Ok;
}

/// The largest model a blob carries: bodies and frames (a bound on what a reader allocates).
inline constexpr int kBlobMaxBodies = 64;
inline constexpr int kBlobMaxFrames = 256;

inline void write_model(BlobWriter& w, const Model& m) {
  w.put(m.nb());
  w.put(static_cast<double>(m.frames().size()));
  w.put(m.end_effector());
  w.put(m.gravity);
  for (int i = 0; i < m.nb(); ++i) {
    const Body& b = m.body(i);
    w.put(b.parent);
    w.put(b.joint.type == JointType::Prismatic ? 1 : 0);
    w.put(b.joint.axis);
    w.put(b.joint.lower);
    w.put(b.joint.upper);
    w.put(b.joint.effort);
    w.put(b.tree.p);
    w.put(b.tree.R);
    w.put(b.inertia.mass);
    w.put(b.inertia.com);
    w.put(b.inertia.I);
    int leader = -1;
    for (int j = 1; j < m.nb() && !b.leader.empty(); ++j)
      if (m.body(j).joint.name == b.leader) leader = j;
    w.put(leader);
    w.put(b.multiplier);
    w.put(b.offset);
  }
  for (const Frame& f : m.frames()) {
    w.put(f.body);
    w.put(f.pose.p);
    w.put(f.pose.R);
  }
}

/// The model of a blob (ModelBuilder::assemble); bodies are named "link<i>", joints "joint<i>", frames
/// "frame<i>" (the robot's names stay on the host).
inline Model read_model(BlobReader& r) {
  const int nb = r.integer(2, kBlobMaxBodies), nf = r.integer(1, kBlobMaxFrames);
  const int ee = r.integer(-1, nf - 1);
  Vector3 g;
  r.get(g);
  std::vector<Body> bodies(static_cast<std::size_t>(r.ok() ? nb : 0));
  std::vector<int> leaders(bodies.size(), -1);
  for (int i = 0; i < static_cast<int>(bodies.size()) && r.ok(); ++i) {
    Body& b = bodies[static_cast<std::size_t>(i)];
    b.name = "link" + std::to_string(i);
    b.joint.name = "joint" + std::to_string(i);
    b.parent = r.integer(i == 0 ? -1 : 0, i - 1);
    b.joint.type = r.integer(0, 1) == 1 ? JointType::Prismatic : JointType::Revolute;
    r.get(b.joint.axis);
    b.joint.lower = r.real(true);
    b.joint.upper = r.real(true);
    b.joint.effort = r.real();
    r.get(b.tree.p);
    r.get(b.tree.R);
    b.inertia.mass = r.real();
    r.get(b.inertia.com);
    r.get(b.inertia.I);
    const int leader = r.integer(-1, nb - 1);
    if (leader == 0 || leader == i) r.fail(BlobStatus::Layout);
    if (leader > 0) b.leader = "joint" + std::to_string(leader);
    leaders[static_cast<std::size_t>(i)] = leader;
    b.multiplier = r.real();
    b.offset = r.real();
    if (r.ok() && (i == 0) != (b.parent == -1)) r.fail(BlobStatus::Layout);
  }
  for (int leader : leaders)  // a leader is an independent joint (the writer resolves the chains)
    if (leader > 0 && !bodies[static_cast<std::size_t>(leader)].leader.empty()) r.fail(BlobStatus::Layout);
  std::vector<Frame> frames(static_cast<std::size_t>(r.ok() ? nf : 0));
  for (int i = 0; i < static_cast<int>(frames.size()) && r.ok(); ++i) {
    Frame& f = frames[static_cast<std::size_t>(i)];
    f.name = "frame" + std::to_string(i);
    f.body = r.integer(0, nb - 1);
    r.get(f.pose.p);
    r.get(f.pose.R);
  }
  if (!r.ok()) return Model{};
  return ModelBuilder::assemble(std::move(bodies), std::move(frames), ee, g);
}

}  // namespace detail

}  // namespace ffsr

#include "ffsr/control/detail/onboard_blob.hxx"
