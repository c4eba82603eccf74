// ffsr/control/contact_grasp.hpp -- the grasp after the Hertz contact: the multibody contact run
// (simulate/multibody.hpp) from the first touch to the separation, then the plastic 6-D lock
// (algorithm/grasp.hpp) from the state the run ends in. docs/detumble.md says why the lock comes then.
#pragma once

#include "ffsr/algorithm/grasp.hpp"
#include "ffsr/simulate/multibody.hpp"

#include <string_view>

namespace ffsr {

/// The contact phase and the lock after it.
struct ContactGraspResult {
  MultibodyContactResult contact;  ///< the Hertz phase: figures, and the bodies at its start and end
  /// The impulse of the contact force on the robot's contact point over the phase, N s (inertial): minus
  /// the change of the target's linear momentum, gravity's share taken out.
  Vector3 contact_impulse = Vector3::Zero();
  GraspResult grasp;  ///< the lock from contact.end (its contact point: the frame's origin at the separation)
};

/// The contact run of simulate_contact (robot at (base, theta) approaching at `approach_speed` along the
/// target's normal under zero total momentum, the target placed touching; the law `law` with `params`;
/// `options` as there), then grasp() of the state at the separation: the robot's base pose,
/// configuration and generalized velocity, the target's pose, velocity and spin where the penetration
/// returns to zero. The lock is the rigid one of grasp() (the free joints' H: an armature or a servo of
/// `options` acts during the contact only). Throws as simulate_contact and grasp do.
inline ContactGraspResult grasp_after_contact(const Model& model, int frame, const BasePose& base,
                                              const Eigen::VectorXd& theta, const Target& target,
                                              double approach_speed, const ContactParams& params,
                                              std::string_view law,
                                              const MultibodyContactOptions& options = {}) {
  ContactGraspResult r;
  r.contact = simulate_contact(model, base, theta, frame, target, approach_speed, params, law, options);
  const ContactBodies& s = r.contact.start;
  const ContactBodies& e = r.contact.end;
  const double m = target.mass;
  r.contact_impulse =
      -(m * (e.target.velocity - s.target.velocity) - m * model.gravity * r.contact.contact_duration);
  Data data(model);
  r.grasp = grasp(model, data, e.base, e.theta, e.v, frame, e.target);
  return r;
}

}  // namespace ffsr
