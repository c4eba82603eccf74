// python/src/bindings.hpp -- every part of the module ffsr._ffsr, one function per class or group of
// functions, defined in the source of its area and called in this order by module.cpp.
#pragma once

#include <nanobind/nanobind.h>

namespace ffsr::python {

// exceptions.cpp: ffsr.Error and its subclasses, the translation of the library's exceptions
void bind_exceptions(nanobind::module_& m);

// model.cpp: the model and what it is built from
void bind_pose(nanobind::module_& m);
void bind_base_pose(nanobind::module_& m);
void bind_inertia(nanobind::module_& m);
void bind_tree(nanobind::module_& m);  // JointType, Joint, Body, Frame
void bind_bus(nanobind::module_& m);
void bind_urdf_report(nanobind::module_& m);
void bind_model(nanobind::module_& m);
void bind_model_builder(nanobind::module_& m);
// data.cpp, target.cpp
void bind_data(nanobind::module_& m);
void bind_target(nanobind::module_& m);

// algorithms.cpp: the dynamics, the effective masses
void bind_kinematics(nanobind::module_& m);
void bind_dynamics(nanobind::module_& m);  // crba, rnea, bias_forces, inverse_inertia_matrix
void bind_momentum(nanobind::module_& m);
void bind_effective_mass(nanobind::module_& m);
void bind_integrated_effective_mass(nanobind::module_& m);

// contact.cpp: the contact laws and the contact runs
void bind_contact_params(nanobind::module_& m);
void bind_contact_law(nanobind::module_& m);
void bind_contact_functions(nanobind::module_& m);
void bind_single_body(nanobind::module_& m);
void bind_multibody_contact(nanobind::module_& m);

// batch.cpp: many configurations in one call
void bind_batch(nanobind::module_& m);
void bind_bench_timing(nanobind::module_& m);

// scenario.cpp: scenario files and the main job
void bind_capture_result(nanobind::module_& m);
void bind_run_result(nanobind::module_& m);
void bind_scenario(nanobind::module_& m);

// jobs.cpp: the one-configuration jobs, as methods of Scenario
void bind_base_disturbance(nanobind::module_& m);
void bind_inspect(nanobind::module_& m);
void bind_contact_job(nanobind::module_& m);
void bind_closed_loop(nanobind::module_& m);

// studies.cpp: the jobs over many configurations or samples, as methods of Scenario
void bind_map(nanobind::module_& m);
void bind_robust(nanobind::module_& m);
void bind_robust_merge(nanobind::module_& m);
void bind_pareto(nanobind::module_& m);

// controller.cpp: the capture controller
void bind_target_estimate(nanobind::module_& m);
void bind_controller(nanobind::module_& m);

// detumble.cpp: the post-capture phase (the stack model, the grasp, the detumbling controller, its run)
void bind_detumble(nanobind::module_& m);

}  // namespace ffsr::python
