// python/src/module.cpp -- the module ffsr._ffsr: its docstring and its parts (bindings.hpp), bound in
// an order where every class exists before a signature or a method names it.
#include "bindings.hpp"

using namespace ffsr::python;

NB_MODULE(_ffsr, m) {
  m.doc() =
      "ffsr: capture-configuration optimization for free-floating space robots (Zhang, Aerospace 2022, 9, "
      "69).\n"
      "Bindings over the C++ library: SI units and radians, 6-vectors linear first, names as in C++.";
  bind_exceptions(m);

  bind_pose(m);
  bind_base_pose(m);
  bind_inertia(m);
  bind_tree(m);
  bind_bus(m);
  bind_urdf_report(m);
  bind_model(m);
  bind_model_builder(m);
  bind_data(m);
  bind_target(m);

  bind_kinematics(m);
  bind_dynamics(m);
  bind_momentum(m);
  bind_effective_mass(m);
  bind_integrated_effective_mass(m);

  bind_contact_params(m);
  bind_contact_law(m);
  bind_contact_functions(m);
  bind_single_body(m);
  bind_multibody_contact(m);

  bind_batch(m);
  bind_bench_timing(m);

  bind_capture_result(m);
  bind_run_result(m);
  bind_scenario(m);
  bind_base_disturbance(m);
  bind_inspect(m);
  bind_contact_job(m);
  bind_closed_loop(m);
  bind_map(m);
  bind_robust(m);
  bind_pareto(m);

  bind_target_estimate(m);
  bind_controller(m);
  bind_detumble(m);
}
