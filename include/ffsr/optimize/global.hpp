// ffsr/optimize/global.hpp -- the global capture optimization: the capture configuration is chosen
// first, globally, on the capture manifold, and the approach is planned to reach it (the paper's law,
// Eq. 30, descends the gradient in the null space and so ends in the basin it starts in). Needs NLopt
// (and SUNDIALS CVODE for the multibody objective): the CMake target ffsr::global.
#pragma once

// The three modules:
//   capture_manifold.hpp  the manifold C(B) at a fixed base pose: residual, projection, inequality
//                         constraints (the base-rate constraint; the clearance in clearance.hpp)
//   manifold_search.hpp   the SLSQP adapter, the one local-optimum routine, the multistart with its
//                         branch stage and the ranking (search_capture_manifold)
//   shooting.hpp          the reaching planner (plan_capture_global)
// The objective at a configuration is the capture objective of objective.hpp (joint model, kind).
#include "ffsr/optimize/capture_manifold.hpp"
#include "ffsr/optimize/manifold_search.hpp"
#include "ffsr/optimize/shooting.hpp"
