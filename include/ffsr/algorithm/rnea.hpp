// ffsr/algorithm/rnea.hpp -- recursive Newton-Euler inverse dynamics of the free-floating tree.
#pragma once

#include "ffsr/algorithm/kinematics.hpp"

namespace ffsr {

/// Inverse dynamics tau = H(q) a + C(q, v) of Eq. 1 by the recursive Newton-Euler algorithm
/// (RBDA 5.3, Featherstone's body-coordinate form, linear-first 6-vectors), with gravity
/// model.gravity. v and a are the generalized velocity and acceleration of model.hpp, 6+n each.
/// The first six entries of tau are the force and the moment about the base frame origin on the
/// base, in the inertial frame. Computed independently of crba (body coordinates, no composites).
/// Reads base, theta, v, a. Writes data.Xup, data.V, data.A, data.F, data.tau. Returns data.tau.
/// NumericalError when finite v and a give forces past double precision.
inline const Eigen::VectorXd& rnea(const Model& model, Data& data, const BasePose& base,
                                   const Eigen::Ref<const Eigen::VectorXd>& theta,
                                   const Eigen::Ref<const Eigen::VectorXd>& v,
                                   const Eigen::Ref<const Eigen::VectorXd>& a) {
  detail::check_configuration(model, base, theta, "rnea");
  detail::require_size(v.size(), model.nv(), "rnea", "v");
  detail::require_size(a.size(), model.nv(), "rnea", "a");
  detail::require_finite_all(v, "rnea", "v");
  detail::require_finite_all(a, "rnea", "a");
  const Matrix3 R0 = base.orientation.normalized().toRotationMatrix();
  const Vector3 v0 = v.head<3>(), w0 = v.segment<3>(3);
  // Base: spatial velocity and (spatial) acceleration in base coordinates. The spatial acceleration
  // of the base-fixed origin is its classical acceleration minus w0 x v0; gravity enters as a
  // fictitious upward acceleration of the base.
  data.V[0] << R0.transpose() * v0, R0.transpose() * w0;
  data.A[0] << R0.transpose() * (a.head<3>() - w0.cross(v0) - model.gravity),
      R0.transpose() * a.segment<3>(3);
  const int nb = model.nb();
  auto body_force = [&](int i) {
    const auto ui = static_cast<size_t>(i);
    const Inertia& in = model.body(i).inertia;
    const SpatialInertia I = SpatialInertia::from_com(in.mass, in.com, in.I);
    data.F[ui] = I * data.A[ui] + cross_force(data.V[ui], I * data.V[ui]);
  };
  body_force(0);
  for (int i = 1; i < nb; ++i) {
    const Body& b = model.body(i);
    const auto ui = static_cast<size_t>(i);
    const auto pi = static_cast<size_t>(b.parent);
    // joint position; rate and acceleration of its coordinate (S carries the mimic multiplier)
    const double q = b.joint_position(theta), qd = v(6 + b.coord), qdd = a(6 + b.coord);
    Pose X = b.tree;  // pose of body i in its parent
    Vector6 S;
    if (b.joint.type == JointType::Revolute) {
      X.R = b.tree.R * rotation_about(b.joint.axis, q);
      S << Vector3::Zero(), b.multiplier * b.joint.axis;
    } else {
      X.p = b.tree.p + b.tree.R * b.joint.axis * q;
      S << b.multiplier * b.joint.axis, Vector3::Zero();
    }
    data.Xup[ui] = X;
    // motion transform parent -> child: w_c = R^T w_p, v_c = R^T (v_p + w_p x p)
    auto to_child = [&X](const Vector6& m) {
      Vector6 r;
      r << X.R.transpose() * (m.head<3>() + m.tail<3>().cross(X.p)), X.R.transpose() * m.tail<3>();
      return r;
    };
    data.V[ui] = to_child(data.V[pi]) + S * qd;
    data.A[ui] = to_child(data.A[pi]) + S * qdd + cross_motion(data.V[ui], S * qd);
    body_force(i);
  }
  data.tau.setZero();
  for (int i = nb - 1; i > 0; --i) {
    const auto ui = static_cast<size_t>(i);
    const Body& b = model.body(i);
    const Pose& X = data.Xup[ui];
    const Vector6& f = data.F[ui];
    // a coordinate that drives several joints (mimics) gets the sum: tau = T^T tau_full
    data.tau(6 + b.coord) +=
        b.multiplier *
        (b.joint.type == JointType::Revolute ? b.joint.axis.dot(f.tail<3>()) : b.joint.axis.dot(f.head<3>()));
    // force transform child -> parent: f_p = R f_c, n_p = R n_c + p x (R f_c)
    const Vector3 fp = X.R * f.head<3>();
    data.F[static_cast<size_t>(b.parent)].head<3>() += fp;
    data.F[static_cast<size_t>(b.parent)].tail<3>() += X.R * f.tail<3>() + X.p.cross(fp);
  }
  data.tau.head<3>() = R0 * data.F[0].head<3>();
  data.tau.segment<3>(3) = R0 * data.F[0].tail<3>();
  if (!data.tau.allFinite())  // finite velocities whose products pass double precision
    FFSR_THROW(NumericalError("rnea: the generalized forces overflow double precision"));
  return data.tau;
}

/// The bias C(q, v) of Eq. 1 (velocity terms and gravity): rnea with zero acceleration.
/// Writes what rnea writes. Returns data.tau.
inline const Eigen::VectorXd& bias_forces(const Model& model, Data& data, const BasePose& base,
                                          const Eigen::Ref<const Eigen::VectorXd>& theta,
                                          const Eigen::Ref<const Eigen::VectorXd>& v) {
  data.y.setZero();
  return rnea(model, data, base, theta, v, data.y);
}

}  // namespace ffsr
