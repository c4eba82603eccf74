// python/src/data.cpp -- ffsr.Data, the workspace every algorithm writes into: its matrices as read-only
// views (outputs.hpp), the body frames as copies.
#include "bindings.hpp"
#include "outputs.hpp"

#include <nanobind/stl/vector.h>

#include <vector>

namespace ffsr::python {

using namespace nb::literals;

void bind_data(nb::module_& m) {
  nb::class_<Data>(
      m, "Data",
      "The workspace every algorithm writes into, made once from a Model (one per thread).\n"
      "H, L, J, Jf and tau are read-only views into it: the next call on this Data overwrites them.")
      .def(nb::init<const Model&>(), "model"_a)
      .def_prop_ro(
          "H", [](nb::handle s) { return view(nb::cast<Data&>(s).H, s); }, "H of the last crba, (6+n, 6+n).",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "L", [](nb::handle s) { return view(nb::cast<Data&>(s).L, s); }, "Cholesky factor of H (lower).",
          nb::rv_policy::automatic)
      .def_prop_ro(
          "J", [](nb::handle s) { return view(nb::cast<Data&>(s).J, s); },
          "J_bm of the last frame_jacobian, (6, 6+n).", nb::rv_policy::automatic)
      .def_prop_ro(
          "Jf", [](nb::handle s) { return view(nb::cast<Data&>(s).Jf, s); },
          "J_f of the last generalized_jacobian, (6, n).", nb::rv_policy::automatic)
      .def_prop_ro(
          "tau", [](nb::handle s) { return view(nb::cast<Data&>(s).tau, s); },
          "tau of the last rnea, (6+n,).", nb::rv_policy::automatic)
      .def_prop_ro(
          "positions",
          [](const Data& d) {
            Eigen::MatrixXd P(d.p.size(), 3);
            for (size_t i = 0; i < d.p.size(); ++i) P.row(Eigen::Index(i)) = d.p[i].transpose();
            return out(P);
          },
          "Body frame origins in the inertial frame, (nb, 3) (a copy).", nb::rv_policy::automatic)
      .def_prop_ro(
          "rotations",
          [](const Data& d) {
            std::vector<nb::ndarray<nb::numpy, double>> Rs;
            for (const auto& R : d.R) Rs.push_back(out(R));
            return Rs;
          },
          "Body frame rotations oR_i, a list of (3, 3) (copies).", nb::rv_policy::automatic);
}

}  // namespace ffsr::python
