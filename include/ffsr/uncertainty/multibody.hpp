// ffsr/uncertainty/multibody.hpp -- F_max of an uncertain sample from the multibody CVODE reference
// (simulate/multibody.hpp, Figure 2): the robot at the capture configuration meets the sample's target
// (nominal attitude at the capture; the sample's mass, inertia, contact offset, normal, spin, velocity)
// at the sample's contact point p_e + rho, moving at the sample's approach speed along u.
// Needs ffsr::cvode (SUNDIALS).
#pragma once

#include "ffsr/simulate/multibody.hpp"
#include "ffsr/uncertainty/sampling.hpp"

namespace ffsr {

/// M_ie, delta_dot^- and the peak force of the multibody contact simulation for sample `s` at the
/// capture configuration (base, theta); `options.robot_contact_offset` is replaced by the sample's rho.
/// Reads model. Allocates its own Data and CVODE workspace,
/// so concurrent calls are safe. Throws what simulate_contact throws.
inline SampleForce sample_force_multibody(const Model& model, const BasePose& base,
                                          const Eigen::Ref<const Eigen::VectorXd>& theta, int frame,
                                          const UncertainSample& s, std::string_view law,
                                          const MultibodyContactOptions& options = {}) {
  MultibodyContactOptions o = options;
  o.robot_contact_offset = s.robot_offset;
  const MultibodyContactResult r =
      simulate_contact(model, base, theta, frame, s.target, s.approach_speed, s.contact, law, o);
  return {r.integrated_effective_mass, r.approach_velocity, r.f_max};
}

}  // namespace ffsr
