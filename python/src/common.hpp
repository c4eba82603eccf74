// python/src/common.hpp -- what every translation unit of the extension ffsr._ffsr shares: the
// argument readers (numpy arrays in, checked as the library checks its own arguments) and the views
// (numpy arrays out that look into a Data without a copy).
//
// Arrays in. A vector or matrix argument is a numpy array of float64 (or anything that exports the
// buffer protocol or DLPack as float64), in C order; a Python list or tuple of numbers is taken too
// (it has no dtype or layout to get wrong). Anything else is an ffsr.InputError that names the
// function and the argument: another dtype ("theta must be an array of float64, got int64"), a
// non-contiguous array, a wrong number of dimensions or entries (the library's own message, e.g.
// "forward_kinematics: theta has 4 entries, expected 3"). Nothing is converted silently. NaN and
// infinity are refused by the library's checks with its messages.
//
// Arrays out. The matrices a C++ algorithm leaves in its Data (H, J, J_f, tau) come back as read-only
// numpy views into that Data (no copy); the view keeps the Data alive and shows what the next call on
// the same Data writes there: `.copy()` one to keep it.
#pragma once

#include <ffsr/ffsr.hpp>
#include <ffsr/algorithm/joint_models.hpp>
#include <ffsr/contact/contact_law.hpp>

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <string>
#include <vector>

namespace ffsr::python {

namespace nb = nanobind;

/// A contact law chosen by name (AnyContactLaw), as the Python class ffsr.ContactLaw.
struct ContactLaw {
  AnyContactLaw law;
};

/// A vector argument: a view of the caller's array, or the values of a list it owns.
class VecIn {
 public:
  VecIn(nb::handle h, const char* where, const char* what);
  Eigen::Map<const Eigen::VectorXd> map() const { return {data_, size_}; }
  Eigen::Index size() const { return size_; }
  /// Exactly `n` entries, else InputError "<where>: <what> has <size> entries, expected <n>".
  const VecIn& require(Eigen::Index n) const;

 private:
  Eigen::VectorXd owned_;
  const double* data_ = nullptr;
  Eigen::Index size_ = 0;
  const char *where_, *what_;
};

/// A 2-D argument, row-major (C order): a view of the caller's array, or an owned copy of nested lists.
class MatIn {
 public:
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  MatIn(nb::handle h, const char* where, const char* what);
  Eigen::Map<const RowMajor> map() const { return {data_, rows_, cols_}; }
  Eigen::Index rows() const { return rows_; }
  Eigen::Index cols() const { return cols_; }
  /// Exactly the shape (r, c) (c < 0: any number of columns), else InputError naming the shape.
  const MatIn& require(Eigen::Index r, Eigen::Index c) const;

 private:
  RowMajor owned_;
  const double* data_ = nullptr;
  Eigen::Index rows_ = 0, cols_ = 0;
  const char *where_, *what_;
};

Vector3 vec3(nb::handle h, const char* where, const char* what);
Matrix3 mat3(nb::handle h, const char* where, const char* what);
Eigen::VectorXd vecx(nb::handle h, const char* where, const char* what);
/// A quaternion given as (x, y, z, w), the order of Eigen's coefficients and of Pinocchio's
/// configuration vectors.
Quaternion quat_xyzw(nb::handle h, const char* where, const char* what);

/// A read-only numpy view into `m` (a Data member), kept alive by `owner`.
using ArrayOut = nb::ndarray<nb::numpy, const double>;
ArrayOut view(const Eigen::MatrixXd& m, nb::handle owner);
ArrayOut view(const Eigen::VectorXd& v, nb::handle owner);
/// A new numpy array with a copy of `v` (small fixed-size results: 3- and 6-vectors, 3x3 matrices).
nb::ndarray<nb::numpy, double> copy_out(const Eigen::Ref<const Eigen::MatrixXd>& m, bool as_vector);
/// A JSON text (the command's --json) as Python objects: json.loads(text).
inline nb::object json_loads(const std::string& text) { return nb::module_::import_("json").attr("loads")(text); }

inline nb::ndarray<nb::numpy, double> out(const Vector3& v) { return copy_out(v, true); }
inline nb::ndarray<nb::numpy, double> out(const Vector6& v) { return copy_out(v, true); }
inline nb::ndarray<nb::numpy, double> out(const Eigen::VectorXd& v) { return copy_out(v, true); }
inline nb::ndarray<nb::numpy, double> out(const Matrix3& m) { return copy_out(m, false); }
inline nb::ndarray<nb::numpy, double> out(const Eigen::MatrixXd& m) { return copy_out(m, false); }
nb::ndarray<nb::numpy, double> out_quat(const Quaternion& q);

/// The frame argument of the algorithms: None (the model's end-effector), an index or a frame name.
int frame_arg(const Model& model, nb::handle frame, const char* where);
/// InputError unless `data` was made from a model of the same size as `model`.
void check_data(const Model& model, const Data& data, const char* where);
/// The joint model of the contact ("free", "locked", "armature") with the armature per coordinate
/// (None: zeros; one number for every joint; or one per joint), as the scenario keys contact-joints and
/// armature.
ContactJoints joints_arg(const Model& model, const std::string& joints, nb::handle armature);

void bind_model(nb::module_& m);
void bind_algorithms(nb::module_& m);
void bind_contact(nb::module_& m);
void bind_batch(nb::module_& m);

}  // namespace ffsr::python
