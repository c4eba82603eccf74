// ffsr/geometry/distance.hpp -- distances between the robot, its bus and the target (FCL), with the
// nearest points, and their gradient with respect to the joint angles.
#pragma once

#include "ffsr/algorithm/kinematics.hpp"
#include "ffsr/geometry/shape.hpp"

#include <fcl/narrowphase/distance.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>

#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

// Pairs (CollisionChecker::pairs), each between two bodies with shapes (geometry/shape.hpp):
//   arm-target  every body (the base/bus included) against the target's shape;
//   arm-bus     every moving body whose parent is not the base, against the base;
//   self        two moving bodies unless one is the other's parent, or the joint origins between
//               them lie less than 4 link radii apart along the chain (they share a joint housing:
//               the capsules meet at every configuration).
// The distance of a pair is the least over its shapes (FCL's signed distance: negative when they
// overlap), with the nearest points in the inertial frame.
//
// Contact exemption. The end-effector touches the target at the capture, and the links just behind
// it are close to the target then. The last `exemption` metres of the arm before the contact point,
// measured along the chain's centre lines (the end-effector body's from its joint origin to the
// contact point, then each parent's from its joint origin to its child's), are not checked against
// the target, at every time of the path: a body wholly inside them has no arm-target pair; the
// body where they end is checked with its centre-line capsule (radius link-radius) cut short there,
// instead of its own shapes. On the paper's robots the end-effector link is longer than the default
// 0.2 m, so only its last 0.2 m is exempt; on a wrist whose last links are short (UR5, Kinova) the
// exemption reaches back across them. With a capsule of radius r a straight kept part stays at least
// `clearance` away from the target's face when the arm meets the face within
// acos((clearance + r) / exemption) of its normal.
//
// Gradient (distance_gradient). For a pair with nearest points p_a on body a and p_b on body b and
// distance d != 0, n = (p_a - p_b) / d is the unit direction along which d grows when p_a moves
// (for overlapping shapes too: then d < 0 and p_a - p_b points into b). With the base pose and the
// target held fixed (the capture-manifold search holds the base at its pose at T, as the constraints
// c(theta) = 0 do, global.hpp) d(d)/d(theta) = n^T (J_a(p_a) - J_b(p_b)), J_x(p) the joint columns of
// the Jacobian of the body-fixed point p: for each joint k supporting the body,
// S_k,lin + S_k,ang x (p - p_0) (data.S of forward_kinematics). The base and the target do not move
// with theta there, so their J is 0. Component ffsr::geometry (FCL, Debian libfcl-dev).

namespace ffsr {

enum class PairKind { ArmTarget, ArmBus, Self };

inline const char* pair_kind_name(PairKind k) {
  return k == PairKind::ArmTarget ? "arm-target" : k == PairKind::ArmBus ? "arm-bus" : "self";
}

/// One pair of bodies; b = -1 is the target.
struct BodyPair {
  int a = 0, b = 0;
  PairKind kind = PairKind::Self;
};

/// The distance of a pair and where it is reached (inertial frame).
struct PairDistance {
  int pair = -1;  ///< index into CollisionChecker::pairs()
  double distance = std::numeric_limits<double>::infinity();
  Vector3 p_a = Vector3::Zero(), p_b = Vector3::Zero();
};

namespace detail {

/// The centre segment of a capsule or sphere (world pose P): end points a, b.
inline void round_segment(const Shape& s, const Pose& P, Vector3& a, Vector3& b) {
  const Vector3 h = P.R.col(2) * (s.kind == Shape::Kind::Capsule ? 0.5 * s.length : 0.0);
  a = P.p - h;
  b = P.p + h;
}

/// Closest points of segments p1-q1 and p2-q2 (Ericson, Real-Time Collision Detection, 5.1.9).
inline void segment_segment(const Vector3& p1, const Vector3& q1, const Vector3& p2, const Vector3& q2,
                            Vector3& c1, Vector3& c2) {
  const Vector3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double eps = 1e-300;
  double s = 0, t = 0;
  if (a <= eps && e <= eps) {
  } else if (a <= eps) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= eps) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), den = a * e - b * b;
      s = den > 1e-14 * a * e ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + s * d1;
  c2 = p2 + t * d2;
}

/// Signed distance of two capsules/spheres (exact, also when they overlap) and the nearest points
/// (on each surface along the line between the closest centre points).
inline void round_round(const Shape& sa, const Pose& A, const Shape& sb, const Pose& B, double& d,
                        Vector3& pa, Vector3& pb) {
  Vector3 a0, a1, b0, b1, ca, cb;
  round_segment(sa, A, a0, a1);
  round_segment(sb, B, b0, b1);
  segment_segment(a0, a1, b0, b1, ca, cb);
  const double c = (cb - ca).norm();
  const Vector3 u = c > 0 ? Vector3((cb - ca) / c) : Vector3(A.R.col(0));
  d = c - sa.radius - sb.radius;
  pa = ca + sa.radius * u;
  pb = cb - sb.radius * u;
}

/// Signed distance function of a box (world pose B, full sizes) at x, and its gradient.
inline double box_sdf(const Shape& box, const Pose& B, const Vector3& x, Vector3* grad) {
  const Vector3 q = B.R.transpose() * (x - B.p);
  const Vector3 h = 0.5 * box.size;
  const Vector3 e = q.cwiseAbs() - h;
  if (e.maxCoeff() > 0) {
    const Vector3 o = e.cwiseMax(0.0);
    const double d = o.norm();
    if (grad) *grad = B.R * Vector3(o.array() * q.array().sign() / d);
    return d;
  }
  Eigen::Index k;
  const double d = e.maxCoeff(&k);
  if (grad) *grad = B.R.col(k) * (q(k) < 0 ? -1.0 : 1.0);
  return d;
}

/// A capsule/sphere that reaches into a box: the least signed distance of the box along the centre
/// segment minus the radius, a depth continuous with the distance outside, and the nearest points:
/// the deepest point of the round shape and its centre point's projection on the box's surface.
/// Exact: in the box frame, g(t) = max_i (|q_i(t)| - h_i) is the largest of six linear functions of
/// the segment parameter, a lower bound of the signed distance equal to it inside the box; the
/// segment reaches the box, so min g <= 0 is the least signed distance, and the minimum of a maximum
/// of lines on [0, 1] lies at an end or where two of them cross (at most 15 points). The centre
/// segment a-b, in the box frame q0 + t dq, comes from round_box.
inline void round_box_depth(const Shape& s, const Vector3& a, const Vector3& b, const Shape& box, const Pose& B,
                            const Vector3& q0, const Vector3& dq, double& d, Vector3& ps, Vector3& pbox) {
  const Vector3 h = 0.5 * box.size;
  std::array<double, 6> c{}, k{};  // the lines c_j + k_j t
  for (int i = 0; i < 3; ++i) {
    c[static_cast<size_t>(2 * i)] = q0(i) - h(i), k[static_cast<size_t>(2 * i)] = dq(i);
    c[static_cast<size_t>(2 * i + 1)] = -q0(i) - h(i), k[static_cast<size_t>(2 * i + 1)] = -dq(i);
  }
  auto g = [&](double t) {
    double m = c[0] + k[0] * t;
    for (size_t j = 1; j < 6; ++j) m = std::max(m, c[j] + k[j] * t);
    return m;
  };
  double best_t = 0, best = g(0.0);
  auto consider = [&](double t) {
    const double v = g(t);
    if (v < best) best = v, best_t = t;
  };
  consider(1.0);
  for (size_t j = 0; j < 6; ++j)
    for (size_t l = j + 1; l < 6; ++l)
      if (k[j] != k[l]) {
        const double t = (c[l] - c[j]) / (k[j] - k[l]);
        if (t > 0 && t < 1) consider(t);
      }
  const Vector3 x = a + best_t * (b - a);
  Vector3 n;
  const double sd = box_sdf(box, B, x, &n);
  d = sd - s.radius;
  ps = x - s.radius * n;  // deepest point of the round shape into the box
  pbox = x - sd * n;      // the box surface point nearest to the centre point
}

/// Signed distance of a capsule/sphere and a box, and the nearest points. Outside, exactly: in the
/// box frame the squared distance of the centre segment's point q(t) to the box is a sum of squares
/// of the coordinates beyond the box's half sizes, a quadratic in t between the t where a coordinate
/// crosses a face plane; its least value over those pieces is the segment's distance (minus the
/// radius: the capsule's). When the segment reaches the box, the depth of round_box_depth. Replaces
/// FCL's GJK for these pairs: the global search evaluates them most.
inline void round_box(const Shape& s, const Pose& S, const Shape& box, const Pose& B, double& d, Vector3& ps,
                      Vector3& pbox) {
  Vector3 a, b;
  round_segment(s, S, a, b);
  const Vector3 q0 = B.R.transpose() * (a - B.p), dq = B.R.transpose() * (b - a), h = 0.5 * box.size;
  std::array<double, 8> ts{};
  int m = 0;
  ts[static_cast<size_t>(m++)] = 0;
  for (int i = 0; i < 3; ++i)
    if (dq(i) != 0)
      for (double face : {-h(i), h(i)}) {
        const double t = (face - q0(i)) / dq(i);
        if (t > 0 && t < 1) ts[static_cast<size_t>(m++)] = t;
      }
  ts[static_cast<size_t>(m++)] = 1;
  for (int i = 1; i < m; ++i)  // insertion sort of at most 8
    for (int j = i; j > 0 && ts[static_cast<size_t>(j)] < ts[static_cast<size_t>(j - 1)]; --j)
      std::swap(ts[static_cast<size_t>(j)], ts[static_cast<size_t>(j - 1)]);
  auto outside2 = [&](double t) { return ((q0 + t * dq).cwiseAbs() - h).cwiseMax(0.0).squaredNorm(); };
  double best_t = 0, best = outside2(0);
  for (int k = 0; k + 1 < m; ++k) {
    const double t0 = ts[static_cast<size_t>(k)], t1 = ts[static_cast<size_t>(k + 1)];
    const Vector3 mid = q0 + 0.5 * (t0 + t1) * dq;
    double num = 0, den = 0;  // the piece's quadratic: sum over the coordinates beyond a face
    for (int i = 0; i < 3; ++i) {
      if (std::abs(mid(i)) <= h(i)) continue;
      const double c = q0(i) - (mid(i) > 0 ? h(i) : -h(i));
      num -= c * dq(i);
      den += dq(i) * dq(i);
    }
    if (den == 0) {  // every coordinate within the box on this piece: the segment is inside there
      best = 0;      // (at the piece's ends the squared distance is 0 only up to rounding)
      break;
    }
    const double t = std::clamp(num / den, t0, t1);
    for (double x : {t, t1}) {
      const double g = outside2(x);
      if (g < best) best = g, best_t = x;
    }
  }
  if (!(best > 0)) {
    round_box_depth(s, a, b, box, B, q0, dq, d, ps, pbox);
    return;
  }
  // outside: the nearest box point is the centre point clamped to the box (box frame)
  const Vector3 xq = q0 + best_t * dq, cq = xq.cwiseMax(-h).cwiseMin(h), nq = (xq - cq) / std::sqrt(best);
  d = std::sqrt(best) - s.radius;
  pbox = B.p + B.R * cq;
  ps = a + best_t * (b - a) - s.radius * (B.R * nq);
}

}  // namespace detail

class CollisionChecker {
 public:
  /// `target`: the target's shape (target frame), or none (no arm-target pairs). `exemption`: the
  /// contact exemption, m (>= 0). Throws InputError on a negative or non-finite exemption.
  CollisionChecker(const Model& model, RobotGeometry geometry, std::optional<Shape> target, double exemption)
      : g_(std::move(geometry)), target_(std::move(target)), exemption_(exemption) {
    if (!std::isfinite(exemption) || exemption < 0)
      throw InputError(detail::str("--contact-exemption: must be >= 0 and finite, got ", exemption));
    const int nb = model.nb();
    geoms_.resize(static_cast<size_t>(nb));
    for (int b = 0; b < nb; ++b)
      for (const Shape& s : g_.shapes[static_cast<size_t>(b)])
        geoms_[static_cast<size_t>(b)].push_back(fcl_of(s));
    if (target_) target_geom_ = fcl_of(*target_);
    make_exemption(model);
    make_pairs(model);
  }

  const std::vector<BodyPair>& pairs() const { return pairs_; }
  const RobotGeometry& geometry() const { return g_; }
  const std::optional<Shape>& target_shape() const { return target_; }
  /// Body b's trimmed centre-line capsule checked against the target instead of its shapes (body
  /// frame), if the contact exemption ends on b.
  const std::optional<Shape>& exempt_capsule(int b) const { return trimmed_[static_cast<size_t>(b)]; }
  /// Whether body b lies wholly inside the contact exemption (no arm-target pair).
  bool exempt(int b) const { return exempt_[static_cast<size_t>(b)] != 0; }
  double exemption() const { return exemption_; }

  /// "link3 - target" for a pair.
  std::string pair_name(int pair) const {
    const BodyPair& p = pairs_[static_cast<size_t>(pair)];
    return g_.names[static_cast<size_t>(p.a)] + " - " +
           (p.b < 0 ? std::string("target") : g_.names[static_cast<size_t>(p.b)]);
  }

  /// The distance of every pair at the kinematics of `data` (forward_kinematics run) and the target
  /// pose `target` (target frame in o). Writes out (one per pair, in pairs() order).
  void distances(const Data& data, const Pose& target, std::vector<PairDistance>& out) const {
    out.resize(pairs_.size());
    for (size_t i = 0; i < pairs_.size(); ++i) out[i] = pair_distance(data, target, static_cast<int>(i));
  }

  /// The distance of pair i (see distances).
  PairDistance pair_distance(const Data& data, const Pose& target, int i) const {
    const BodyPair& p = pairs_[static_cast<size_t>(i)];
    PairDistance best;
    best.pair = i;
    const Pose A = body_pose(data, p.a);
    const auto& ga = geoms_[static_cast<size_t>(p.a)];
    const auto& sa = g_.shapes[static_cast<size_t>(p.a)];
    if (p.b < 0) {
      const std::optional<Shape>& cut = trimmed_[static_cast<size_t>(p.a)];
      if (cut) {
        closest(*cut, trimmed_geom_[static_cast<size_t>(p.a)].get(), A * cut->pose, *target_,
                target_geom_.get(), target * target_->pose, best);
      } else {
        for (size_t k = 0; k < sa.size(); ++k)
          closest(sa[k], ga[k].get(), A * sa[k].pose, *target_, target_geom_.get(), target * target_->pose,
                  best);
      }
      return best;
    }
    const Pose B = body_pose(data, p.b);
    const auto& gb = geoms_[static_cast<size_t>(p.b)];
    const auto& sb = g_.shapes[static_cast<size_t>(p.b)];
    for (size_t k = 0; k < sa.size(); ++k)
      for (size_t l = 0; l < sb.size(); ++l)
        closest(sa[k], ga[k].get(), A * sa[k].pose, sb[l], gb[l].get(), B * sb[l].pose, best);
    return best;
  }

  /// The least distance over every pair (pair -1 when there is no pair).
  PairDistance min_distance(const Data& data, const Pose& target) const {
    PairDistance best;
    for (size_t i = 0; i < pairs_.size(); ++i) {
      const PairDistance d = pair_distance(data, target, static_cast<int>(i));
      if (d.distance < best.distance) best = d;
    }
    return best;
  }

  /// d(distance)/d(theta) of `d` with the base pose and the target fixed (see the notes after the includes).
  /// Reads data.p, data.S (forward_kinematics at the configuration of d). Writes grad (n).
  void distance_gradient(const Model& model, const Data& data, const PairDistance& d,
                         Eigen::Ref<Eigen::VectorXd> grad) const {
    grad.setZero();
    if (d.distance == 0 || !std::isfinite(d.distance)) return;
    const BodyPair& p = pairs_[static_cast<size_t>(d.pair)];
    const Vector3 n = (d.p_a - d.p_b) / d.distance;
    add_point_gradient(model, data, p.a, d.p_a, n, grad);
    if (p.b > 0) add_point_gradient(model, data, p.b, d.p_b, -n, grad);
  }

 private:
  using Geom = std::shared_ptr<fcl::CollisionGeometryd>;

  static Geom fcl_of(const Shape& s) {
    switch (s.kind) {
      case Shape::Kind::Box:
        return std::make_shared<fcl::Boxd>(s.size.x(), s.size.y(), s.size.z());
      case Shape::Kind::Sphere:
        return std::make_shared<fcl::Sphered>(s.radius);
      case Shape::Kind::Cylinder:
        return std::make_shared<fcl::Cylinderd>(s.radius, s.length);
      case Shape::Kind::Capsule:
        if (s.length < 1e-12) return std::make_shared<fcl::Sphered>(s.radius);
        return std::make_shared<fcl::Capsuled>(s.radius, s.length);
    }
    return nullptr;
  }

  static fcl::Transform3d transform(const Pose& p) {
    fcl::Transform3d t = fcl::Transform3d::Identity();
    t.linear() = p.R;
    t.translation() = p.p;
    return t;
  }

  static Pose body_pose(const Data& data, int b) {
    return {data.p[static_cast<size_t>(b)], data.R[static_cast<size_t>(b)]};
  }

  /// The distance between shapes sa (pose A: world pose of the shape) and sb, folded into best.
  static void closest(const Shape& sa, const fcl::CollisionGeometryd* a, const Pose& A, const Shape& sb,
                      const fcl::CollisionGeometryd* b, const Pose& B, PairDistance& best) {
    double d;
    Vector3 pa, pb;
    if (round(sa) && round(sb)) {
      detail::round_round(sa, A, sb, B, d, pa, pb);
    } else if (round(sa) && sb.kind == Shape::Kind::Box) {
      detail::round_box(sa, A, sb, B, d, pa, pb);
    } else if (round(sb) && sa.kind == Shape::Kind::Box) {
      detail::round_box(sb, B, sa, A, d, pb, pa);
    } else {
      fcl::DistanceRequestd req(true);
      req.distance_tolerance = 1e-12;
      req.gjk_solver_type = fcl::GST_LIBCCD;
      fcl::DistanceResultd res;
      fcl::distance(a, transform(A), b, transform(B), req, res);
      d = res.min_distance;
      pa = res.nearest_points[0];
      pb = res.nearest_points[1];
      if (d <= 0) d = 0;  // overlapping: FCL gives no depth (round shapes in boxes have one, above)
    }
    if (d < best.distance) {
      best.distance = d;
      best.p_a = pa;
      best.p_b = pb;
    }
  }

  static bool round(const Shape& s) {
    return s.kind == Shape::Kind::Capsule || s.kind == Shape::Kind::Sphere;
  }

  /// The contact exemption (see the notes after the includes): walks from the contact point back along the
  /// chain's centre lines, marking the bodies it covers and cutting the capsule of the one it ends on.
  void make_exemption(const Model& model) {
    const size_t nb = static_cast<size_t>(model.nb());
    trimmed_.assign(nb, std::nullopt);
    trimmed_geom_.assign(nb, nullptr);
    exempt_.assign(nb, 0);
    if (g_.ee_body < 0 || !target_) return;
    int b = g_.ee_body;
    Vector3 a = g_.ee_line_start, e = g_.ee_line_end;  // body frame of b
    double left = exemption_;
    while (b > 0) {
      const double L = (e - a).norm();
      if (L > left) {
        const double r =
            static_cast<size_t>(b) < g_.line_radius.size() ? g_.line_radius[static_cast<size_t>(b)] : 0.0;
        trimmed_[static_cast<size_t>(b)] = Shape::capsule_between(a, a + (e - a) * ((L - left) / L), r);
        trimmed_geom_[static_cast<size_t>(b)] = fcl_of(*trimmed_[static_cast<size_t>(b)]);
        return;
      }
      exempt_[static_cast<size_t>(b)] = 1;
      left -= L;
      e = model.body(b).tree.p;  // the parent's centre line: its joint origin to b's
      a = Vector3::Zero();
      b = model.body(b).parent;
    }
  }

  /// Length along the tree between the joint origins of body a's child towards d and of d, when
  /// a is an ancestor of d (else infinity).
  static double chain_gap(const Model& model, int a, int d) {
    double gap = 0;
    int x = d;
    while (x >= 0 && model.body(x).parent != a) {
      gap += model.body(x).tree.p.norm();
      x = model.body(x).parent;
    }
    return x < 0 ? std::numeric_limits<double>::infinity() : gap;
  }

  void make_pairs(const Model& model) {
    const int nb = model.nb();
    auto has = [&](int b) { return !g_.shapes[static_cast<size_t>(b)].empty(); };
    if (target_)
      for (int b = 0; b < nb; ++b)
        if (!exempt(b) && (trimmed_[static_cast<size_t>(b)] || has(b)))
          pairs_.push_back({b, -1, PairKind::ArmTarget});
    if (has(0))
      for (int b = 1; b < nb; ++b)
        if (has(b) && model.body(b).parent != 0) pairs_.push_back({b, 0, PairKind::ArmBus});
    for (int a = 1; a < nb; ++a)
      for (int d = a + 1; d < nb; ++d) {
        if (!has(a) || !has(d) || model.body(d).parent == a) continue;
        const double r = 2 * (radius_of(a) + radius_of(d));
        if (chain_gap(model, a, d) < r) continue;
        pairs_.push_back({d, a, PairKind::Self});
      }
  }

  double radius_of(int b) const {
    double r = 0;
    for (const Shape& s : g_.shapes[static_cast<size_t>(b)])
      r = std::max(r, s.kind == Shape::Kind::Box ? 0.5 * s.size.minCoeff() : s.radius);
    return r;
  }

  static void add_point_gradient(const Model& model, const Data& data, int body, const Vector3& point,
                                 const Vector3& n, Eigen::Ref<Eigen::VectorXd> grad) {
    const Vector3 r = point - data.p[0];
    for (int k = body; k > 0; k = model.body(k).parent) {
      const auto S = data.S.col(k - 1);
      const Vector3 v = S.head<3>() + S.tail<3>().cross(r);
      grad(model.body(k).coord) += n.dot(v);
    }
  }

  RobotGeometry g_;
  std::optional<Shape> target_;
  double exemption_ = 0;
  std::vector<std::vector<Geom>> geoms_;
  Geom target_geom_;
  std::vector<std::optional<Shape>>
      trimmed_;  ///< per body: the cut centre-line capsule, if the exemption ends there
  std::vector<Geom> trimmed_geom_;
  std::vector<char> exempt_;  ///< per body: 1 when wholly inside the exemption
  std::vector<BodyPair> pairs_;
};

}  // namespace ffsr
