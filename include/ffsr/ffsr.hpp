// ffsr/ffsr.hpp -- umbrella header of the dynamics part (Eigen only).
// The URDF loader (ffsr/io/urdf.hpp, urdfdom) and the CVODE parts (ffsr/simulate/, ffsr/optimize/)
// are included separately, so that a user who wants the dynamics pulls in only Eigen. The parts of
// the capture planner below (Eigen only) are here, so that an onboard controller can use the rate
// law without the planner: ffsr/optimize/capture.hpp composes them.
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
#include "ffsr/algorithm/articulated_effective_mass.hpp"
#include "ffsr/optimize/line_reference.hpp"
#include "ffsr/optimize/task_solver.hpp"
#include "ffsr/optimize/capture_problem.hpp"
#include "ffsr/optimize/null_space.hpp"
#include "ffsr/optimize/free_floating_step.hpp"
#include "ffsr/optimize/run_monitors.hpp"
