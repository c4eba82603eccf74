// python/src/outputs.hpp -- the results of ffsr._ffsr as numpy arrays (outputs.cpp): read-only views
// into a Data (H, J, J_f, tau: no copy; the view keeps its owner alive and shows what the next call on
// it writes), new arrays for small results, and the command's JSON as Python objects.
#pragma once

#include "common.hpp"

#include <string>
#include <vector>

namespace ffsr::python {

/// A read-only numpy view into `m` (a member of the object `owner`), kept alive by `owner`.
using ArrayOut = nb::ndarray<nb::numpy, const double>;
ArrayOut view(const Eigen::MatrixXd& m, nb::handle owner);
ArrayOut view(const Eigen::VectorXd& v, nb::handle owner);

/// A new numpy array with a copy of `m`: 1-D (`as_vector`) or 2-D in C order.
using NewArray = nb::ndarray<nb::numpy, double>;
NewArray copy_out(const Eigen::Ref<const Eigen::MatrixXd>& m, bool as_vector);
/// A new 1-D array of `n` entries, uninitialised; `*data` points at them (written without the GIL).
NewArray new_array(size_t n, double** data);
/// A 1-D array from a vector of doubles (a copy).
NewArray array_of(const std::vector<double>& v);

inline NewArray out(const Vector3& v) { return copy_out(v, true); }
inline NewArray out(const Vector6& v) { return copy_out(v, true); }
inline NewArray out(const Eigen::VectorXd& v) { return copy_out(v, true); }
inline NewArray out(const Matrix3& m) { return copy_out(m, false); }
inline NewArray out(const Eigen::MatrixXd& m) { return copy_out(m, false); }
/// A quaternion as (x, y, z, w).
NewArray out_quat(const Quaternion& q);

/// A JSON text (the command's --json) as Python objects: json.loads(text).
nb::object json_loads(const std::string& text);

}  // namespace ffsr::python
