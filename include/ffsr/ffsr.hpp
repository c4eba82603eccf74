// ffsr/ffsr.hpp -- umbrella header of the dynamics (Eigen only): exactly the headers below, nothing of
// the planner, the simulations or the parsers. A translation unit that needs only M_ie compiles several
// times faster without the planner. Include the rest where it is needed, each with its CMake target
// (docs/library.md; the list at the end of this file).
#pragma once

#include "ffsr/errors.hpp"                    // the exception hierarchy
#include "ffsr/spatial/spatial.hpp"           // skew, Plücker transforms, spatial inertia
#include "ffsr/model/model.hpp"               // the robot (Model, ModelBuilder)
#include "ffsr/model/data.hpp"                // its workspace (Data)
#include "ffsr/model/target.hpp"              // the tumbling target
#include "ffsr/algorithm/kinematics.hpp"      // forward kinematics, frame poses
#include "ffsr/algorithm/crba.hpp"            // H (composite rigid body algorithm)
#include "ffsr/algorithm/rnea.hpp"            // C (recursive Newton-Euler)
#include "ffsr/algorithm/jacobian.hpp"        // J_bm, J_f
#include "ffsr/algorithm/momentum.hpp"        // linear and angular momentum
#include "ffsr/algorithm/effective_mass.hpp"  // m_e (Eq. 4), M_ie (Eq. 14) under every joint model
// the inverse inertia at a frame, the gradients of m_e and M_ie
#include "ffsr/algorithm/effective_mass_gradient.hpp"
#include "ffsr/algorithm/joint_models.hpp"  // the contact-joint models (free, locked, armature)
// 1/m_e in O(n), the recursion behind integrated_effective_mass
#include "ffsr/algorithm/articulated_effective_mass.hpp"

// The rest, with its CMake target:
//   ffsr/contact/contact_law.hpp         contact laws, closed-form and exact maxima   (ffsr::ffsr)
//   ffsr/parsers/urdf.hpp                the URDF loader                              (ffsr::urdf)
//   ffsr/optimize/capture.hpp            the paper's planner and its parts            (ffsr::ffsr)
//   ffsr/control/capture_controller.hpp  the onboard controller                       (ffsr::ffsr)
//   ffsr/simulate/*.hpp                  CVODE integrations                           (ffsr::cvode)
//   ffsr/optimize/global.hpp             the capture-manifold search                  (ffsr::global)
