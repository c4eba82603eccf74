// ffsr/algorithm/kinematics.hpp -- forward kinematics of the free-floating tree.
#pragma once

#include "ffsr/model/data.hpp"

namespace ffsr {
namespace detail {

/// Checks the configuration arguments of a public entry point (sizes, finiteness, quaternion).
inline void check_configuration(const Model& model, const BasePose& base,
                                const Eigen::Ref<const Eigen::VectorXd>& theta, const char* where) {
  require_size(theta.size(), model.n(), where, "theta");
  require_finite_all(theta, where, "theta");
  require_finite_all(base.position, where, "base position");
  require_finite_all(base.orientation.coeffs(), where, "base orientation");
  const double qn = base.orientation.norm();
  if (qn < 1e-9) throw InputError(str(where, ": base orientation quaternion has zero norm"));
}

/// 0, 1 or 2 when the unit vector `axis` is +-x, +-y or +-z exactly (as most URDF joint axes are), else -1.
inline int coordinate_axis(const Vector3& axis) {
  if (axis.y() == 0.0 && axis.z() == 0.0) return 0;
  if (axis.x() == 0.0 && axis.z() == 0.0) return 1;
  if (axis.x() == 0.0 && axis.y() == 0.0) return 2;
  return -1;
}

}  // namespace detail

/// Forward kinematics (RBDA 4.1, in the inertial frame).
/// Reads base, theta. Writes data.base, data.R, data.p (every body frame in o) and data.S (the joint
/// motion subspaces in inertial axes about the base frame origin, per unit rate of each body's
/// coordinate: mimic joints carry their multiplier). The base quaternion is normalized.
inline void forward_kinematics(const Model& model, Data& data, const BasePose& base,
                               const Eigen::Ref<const Eigen::VectorXd>& theta) {
  detail::check_configuration(model, base, theta, "forward_kinematics");
  data.base.position = base.position;
  data.base.orientation = base.orientation.normalized();
  data.R[0] = data.base.orientation.toRotationMatrix();
  data.p[0] = base.position;
  const int nb = model.nb();
  for (int i = 1; i < nb; ++i) {
    const Body& b = model.body(i);
    const auto ui = static_cast<size_t>(i);
    const auto pi = static_cast<size_t>(b.parent);
    const Matrix3 Rj = data.R[pi].lazyProduct(b.tree.R);
    const Vector3 pj = data.p[pi] + data.R[pi] * b.tree.p;
    const Vector3 z = Rj * b.joint.axis;
    const double q = b.joint_position(theta), k = b.multiplier;
    if (b.joint.type == JointType::Revolute) {
      const int a = detail::coordinate_axis(b.joint.axis);
      if (a >= 0) {  // about +-x, +-y or +-z: a plane rotation of two columns (12 products, not 27 + 15)
        double s, c;
        detail::sin_cos(q, s, c);
        s *= b.joint.axis(a);
        const int c1 = (a + 1) % 3, c2 = (a + 2) % 3;
        Matrix3& R = data.R[ui];
        R.col(a) = Rj.col(a);
        R.col(c1) = c * Rj.col(c1) + s * Rj.col(c2);
        R.col(c2) = c * Rj.col(c2) - s * Rj.col(c1);
      } else {
        data.R[ui].noalias() = Rj.lazyProduct(rotation_about(b.joint.axis, q));
      }
      data.p[ui] = pj;
      data.S.col(i - 1) << k * (pj - data.p[0]).cross(z), k * z;
    } else {
      data.R[ui] = Rj;
      data.p[ui] = pj + z * q;
      data.S.col(i - 1) << k * z, Vector3::Zero();
    }
  }
}

/// World pose of a frame after forward_kinematics. Reads data.R, data.p.
inline Pose frame_pose(const Model& model, const Data& data, int frame) {
  const Frame& f = model.frame(frame);
  const auto b = static_cast<size_t>(f.body);
  return {data.p[b] + data.R[b] * f.pose.p, data.R[b] * f.pose.R};
}

/// True when body `ancestor` is `body` or on its path to the base.
inline bool supports(const Model& model, int ancestor, int body) {
  for (int i = body; i >= 0; i = model.body(i).parent)
    if (i == ancestor) return true;
  return false;
}

}  // namespace ffsr
