// ffsr/ffsr.hpp -- umbrella header of the dynamics (Eigen only).
//
// It pulls in exactly this, and nothing of the planner, the simulations or the parsers:
//   errors.hpp                      the exception hierarchy
//   spatial/spatial.hpp             skew, Plücker transforms, spatial inertia
//   model/model.hpp, model/data.hpp the robot (Model, ModelBuilder) and its workspace (Data)
//   model/target.hpp                the tumbling target
//   algorithm/kinematics.hpp        forward kinematics, frame poses
//   algorithm/crba.hpp              H (composite rigid body algorithm)
//   algorithm/rnea.hpp              C (recursive Newton-Euler)
//   algorithm/jacobian.hpp          J_bm, J_f
//   algorithm/momentum.hpp          linear and angular momentum
//   algorithm/effective_mass.hpp    m_e (Eq. 4), M_ie (Eq. 14) under every joint model
//   algorithm/effective_mass_gradient.hpp
//                                   the inverse inertia at a frame, the gradients of m_e and M_ie
//   algorithm/joint_models.hpp      the contact-joint models (free, locked, armature)
//   algorithm/articulated_effective_mass.hpp
//                                   1/m_e in O(n), the recursion behind integrated_effective_mass
// Include the rest where it is needed, each with its CMake target (docs/library.md):
//   ffsr/contact/contact_law.hpp    contact laws, closed-form and exact maxima   (ffsr::ffsr)
//   ffsr/parsers/urdf.hpp                the URDF loader                              (ffsr::urdf)
//   ffsr/optimize/capture.hpp       the paper's planner and its parts            (ffsr::ffsr)
//   ffsr/control/capture_controller.hpp the onboard controller                  (ffsr::ffsr)
//   ffsr/simulate/*.hpp             CVODE integrations                           (ffsr::cvode)
//   ffsr/optimize/global.hpp        the capture-manifold search                  (ffsr::global)
// A translation unit that needs only M_ie compiles several times faster without the planner.
#pragma once

#include "ffsr/errors.hpp"
#include "ffsr/spatial/spatial.hpp"
#include "ffsr/model/model.hpp"
#include "ffsr/model/data.hpp"
#include "ffsr/model/target.hpp"
#include "ffsr/algorithm/kinematics.hpp"
#include "ffsr/algorithm/crba.hpp"
#include "ffsr/algorithm/rnea.hpp"
#include "ffsr/algorithm/jacobian.hpp"
#include "ffsr/algorithm/momentum.hpp"
#include "ffsr/algorithm/effective_mass.hpp"
#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/algorithm/articulated_effective_mass.hpp"
#include "ffsr/algorithm/joint_models.hpp"
