// ffsr/model/attach.hpp -- the robot and a grasped body as one model: a rigid inertia attached at a
// frame of the robot (the target held by the end-effector), so that every algorithm (CRBA, RNEA, ABA,
// Jacobians, momentum) works on the stack unchanged.
#pragma once

#include "ffsr/model/model.hpp"

#include <string>

namespace ffsr {

/// A rigid body to attach at a frame: its mass, its rotational inertia about its centre of mass in its
/// own axes, and the pose of that centre-of-mass frame in the frame it is attached to.
struct AttachedBody {
  double mass = 0.0;                  ///< kg, > 0
  Matrix3 inertia = Matrix3::Zero();  ///< about the centre of mass, body axes: SPD, triangle inequality
  Pose pose;                          ///< centre-of-mass frame in the attachment frame
  std::string name = "target";        ///< the frame the stack model gains at the centre of mass
};

namespace detail {

/// Checks that `b` is a physical rigid body with a proper pose; throws InputError naming the field.
inline void check_attached_body(const AttachedBody& b) {
  const char* w = "attach_body";
  if (!std::isfinite(b.mass) || !(b.mass > 0))
    FFSR_THROW(InputError(str(w, ": the attached mass must be positive and finite, got ", b.mass)));
  require_finite_all(b.inertia, w, "inertia");
  require_finite_all(b.pose.p, w, "pose position");
  require_finite_all(b.pose.R, w, "pose rotation");
  const double scale = b.inertia.cwiseAbs().maxCoeff();
  if ((b.inertia - b.inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
    FFSR_THROW(InputError(str(w, ": the attached inertia must be symmetric")));
  Eigen::SelfAdjointEigenSolver<Matrix3> es(b.inertia, Eigen::EigenvaluesOnly);
  const Vector3& e = es.eigenvalues();
  if (!(scale > 0) || !(e(0) > 1e-12 * scale))
    FFSR_THROW(InputError(str(w, ": the attached inertia must be positive definite, principal moments (", e(0),
                         ", ", e(1), ", ", e(2), ")")));
  if (e(2) > (e(0) + e(1)) * (1 + 1e-9))
    FFSR_THROW(InputError(str(w, ": the attached inertia's principal moments (", e(0), ", ", e(1), ", ", e(2),
                         ") break the triangle inequality")));
  if ((b.pose.R.transpose() * b.pose.R - Matrix3::Identity()).cwiseAbs().maxCoeff() > 1e-9 ||
      b.pose.R.determinant() < 0)
    FFSR_THROW(InputError(str(w, ": the pose rotation is not a proper rotation matrix")));
}

}  // namespace detail

/// The model with `body` rigidly attached at `frame`: its inertia, moved to the frame's body
/// (RBDA 2.12, the merging of a fixed joint), added to that body's, and a frame `body.name` at its
/// centre of mass. Coordinates, joints, frames and numbering are the model's, so a generalized
/// velocity of the robot is one of the stack. Throws InputError for an unknown frame, a frame name
/// already taken, or a body that is not physical (mass <= 0 or not finite, inertia not symmetric
/// positive definite or breaking the triangle inequality, a pose that is not a rotation).
inline Model attach_body(const Model& model, const std::string& frame, const AttachedBody& body) {
  using detail::str;
  detail::check_attached_body(body);
  int fi = -1;
  for (size_t i = 0; i < model.frames().size() && fi < 0; ++i)
    if (model.frames()[i].name == frame) fi = static_cast<int>(i);
  if (fi < 0) {
    std::string list;
    for (const Frame& f : model.frames()) list += (list.empty() ? "" : ", ") + f.name;
    FFSR_THROW(InputError(str("attach_body: unknown frame '", frame, "'; the model has: ", list)));
  }
  for (const Frame& f : model.frames())
    if (f.name == body.name)
      FFSR_THROW(InputError(str("attach_body: the model already has a frame '", body.name, "'")));
  Model m = model;
  const Frame& at = model.frame(fi);
  const Pose com = at.pose * body.pose;  // the body's centre-of-mass frame in the carrying body's frame
  const Inertia in{body.mass, com.p, com.R * body.inertia * com.R.transpose()};
  Inertia& carrier = m.bodies_[static_cast<size_t>(at.body)].inertia;
  carrier = detail::merged_inertia(carrier, in);
  m.inertia_diagonal_[static_cast<size_t>(at.body)] = SpatialInertia::is_diagonal(carrier.I) ? 1 : 0;
  m.frames_.push_back({body.name, at.body, com});
  return m;
}

}  // namespace ffsr
