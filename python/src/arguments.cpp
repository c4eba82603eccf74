// python/src/arguments.cpp -- the argument readers of ffsr._ffsr (arguments.hpp): arrays as numpy
// converts them, numbers, frames, joint models.
#include "arguments.hpp"

#include <nanobind/stl/string.h>

#include <Python.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace ffsr::python {
namespace {

using detail::str;
using namespace nb::literals;
using AnyArray = nb::ndarray<nb::ro>;

/// True when the entries of `a` lie in C order without gaps (an empty array always does).
bool c_contiguous(const AnyArray& a) {
  int64_t expected = 1;
  for (size_t i = a.ndim(); i-- > 0;) {
    if (a.shape(i) == 0) return true;
    if (a.shape(i) != 1 && a.stride(i) != expected) return false;
    expected *= static_cast<int64_t>(a.shape(i));
  }
  return true;
}

/// numpy.ascontiguousarray, held for the interpreter's lifetime (never released: no destructor runs
/// after finalization).
nb::handle ascontiguousarray() {
  static PyObject* f = nb::object(nb::module_::import_("numpy").attr("ascontiguousarray")).release().ptr();
  return f;
}

/// The caller's object as a C-contiguous float64 array in CPU memory: the object itself when it is
/// one (no copy), else numpy.ascontiguousarray(x, dtype=float64), which is numpy.asarray's conversion
/// laid out in C order; InputError with numpy's reason when numpy cannot convert it.
AnyArray float64_array(nb::handle h, const char* where, const char* what) {
  AnyArray a;
  if (nb::try_cast(h, a, false) && a.dtype() == nb::dtype<double>() &&
      a.device_type() == nb::device::cpu::value && c_contiguous(a))
    return a;
  nb::object converted;
  try {
    converted = ascontiguousarray()(h, "dtype"_a = "float64");
  } catch (nb::python_error& e) {
    const std::string kind = nb::cast<std::string>(nb::str(nb::handle(e.type()).attr("__name__")));
    throw InputError(str(where, ": ", what, " cannot be read as an array of float64 (", kind, ": ",
                         nb::cast<std::string>(nb::str(e.value())), ")"));
  }
  if (!nb::try_cast(converted, a, false) || a.dtype() != nb::dtype<double>())
    throw InputError(
        str(where, ": ", what, " cannot be read as an array of float64 (got ", py_type_name(h), ")"));
  return a;
}

}  // namespace

std::string py_type_name(nb::handle h) { return nb::cast<std::string>(nb::str(h.type().attr("__name__"))); }

double speed_arg(double x, const char* where, const char* what) {
  if (!(std::isfinite(x) && x > 0))
    throw InputError(str(where, ": ", what, " must be positive (m/s), got ", x));
  return x;
}

std::string keyword_message(const std::string& message, const std::string& where,
                            const std::vector<std::string>& keywords) {
  if (message.rfind("--", 0) != 0) return message;
  const size_t end = std::min(message.find_first_of(": "), message.size());
  std::vector<std::string> names;  // the flags before the first ':' or ' ', "--a/--b", as keywords
  for (size_t at = 0; at < end;) {
    const size_t slash = std::min(message.find('/', at), end);
    std::string n = message.substr(at, slash - at);
    if (n.rfind("--", 0) != 0) return message;  // not a list of flags
    n = n.substr(2);
    for (char& c : n)
      if (c == '-') c = '_';
    names.push_back(n);
    at = slash + 1;
  }
  bool keyword = false;
  for (const std::string& n : names) keyword = keyword || std::count(keywords.begin(), keywords.end(), n) > 0;
  if (!keyword) return message;
  std::string text = where + ": ";
  for (size_t i = 0; i < names.size(); ++i) text += (i == 0 ? "" : "/") + names[i];
  return text + message.substr(end);
}

double number(nb::handle x, const char* where, const char* what) {
  if (!PyFloat_Check(x.ptr()) && !PyLong_Check(x.ptr()))
    throw InputError(str(where, ": ", what, " must hold numbers, got ", py_type_name(x)));
  const double v = PyFloat_AsDouble(x.ptr());
  if (v == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    throw InputError(str(where, ": ", what, " holds a number that does not fit a double"));
  }
  return v;
}

VecIn::VecIn(nb::handle h, const char* where, const char* what, Values values) : where_(where), what_(what) {
  const AnyArray a = float64_array(h, where, what);
  if (a.ndim() != 1)
    throw InputError(str(where, ": ", what, " must be a 1-dimensional array, got ", a.ndim(), " dimensions"));
  array_ = a;
  data_ = static_cast<const double*>(a.data());
  size_ = static_cast<Eigen::Index>(a.shape(0));
  if (values == Values::Finite) detail::require_finite_all(map(), where, what);
}

const VecIn& VecIn::require(Eigen::Index n) const {
  detail::require_size(size_, n, where_, what_);
  return *this;
}

MatIn::MatIn(nb::handle h, const char* where, const char* what, Values values) : where_(where), what_(what) {
  const AnyArray a = float64_array(h, where, what);
  if (a.ndim() != 2)
    throw InputError(str(where, ": ", what, " must be a 2-dimensional array, got ", a.ndim(), " dimensions"));
  array_ = a;
  data_ = static_cast<const double*>(a.data());
  rows_ = static_cast<Eigen::Index>(a.shape(0));
  cols_ = static_cast<Eigen::Index>(a.shape(1));
  if (values == Values::Finite) detail::require_finite_all(map(), where, what);
}

const MatIn& MatIn::require(Eigen::Index r, Eigen::Index c) const {
  if (rows_ != r || (c >= 0 && cols_ != c))
    throw InputError(str(where_, ": ", what_, " has shape (", rows_, ", ", cols_, "), expected (", r, ", ",
                         c >= 0 ? str(c) : std::string("any"), ")"));
  return *this;
}

Vector3 vec3(nb::handle h, const char* where, const char* what, Values values) {
  const VecIn v(h, where, what, values);
  v.require(3);
  return v.map();
}

Matrix3 mat3(nb::handle h, const char* where, const char* what) {
  const MatIn a(h, where, what);
  a.require(3, 3);
  return a.map();
}

Eigen::VectorXd vecx(nb::handle h, const char* where, const char* what) {
  return VecIn(h, where, what).map();
}

Quaternion quat_xyzw(nb::handle h, const char* where, const char* what, Values values) {
  const VecIn v(h, where, what, values);
  v.require(4);
  const auto q = v.map();
  return Quaternion(q(3), q(0), q(1), q(2));
}

int frame_arg(const Model& model, nb::handle frame, const char* where) {
  if (frame.is_none()) return model.end_effector();
  if (PyIndex_Check(frame.ptr())) {  // a Python or numpy integer
    const nb::object index = nb::steal(PyNumber_Index(frame.ptr()));
    if (!index.is_valid()) throw nb::python_error();
    long k = PyLong_AsLong(index.ptr());
    if (k == -1 && PyErr_Occurred()) PyErr_Clear();
    if (k < 0 || k >= long(model.frames().size()))
      throw InputError(str(where, ": frame index ", k, " out of range (the model has ", model.frames().size(),
                           " frames)"));
    return int(k);
  }
  if (PyUnicode_Check(frame.ptr())) return model.frame_index(nb::cast<std::string>(frame));
  throw InputError(str(where, ": frame must be None, an index or a frame name, got ", py_type_name(frame)));
}

void check_data(const Model& model, const Data& data, const char* where) {
  if (data.H.rows() != model.nv() || data.R.size() != size_t(model.nb()))
    throw InputError(str(where, ": data was made for a model with ", data.H.rows() - 6, " joints and ",
                         data.R.size(), " bodies, this model has ", model.n(), " and ", model.nb(),
                         "; make one with Data(model)"));
}

ContactJoints joints_arg(const Model& model, const std::string& joints, nb::handle armature,
                         const char* where) {
  ContactJoints cj;
  cj.model = parse_joint_model(joints, "joints");
  std::vector<double> values;
  if (!armature.is_none()) {
    if (PyFloat_Check(armature.ptr()) || PyLong_Check(armature.ptr())) {
      values.push_back(number(armature, where, "armature"));
    } else {
      const VecIn v(armature, where, "armature");
      values.assign(v.map().data(), v.map().data() + v.size());
    }
  }
  cj.armature = per_joint_values(values, model, "armature");
  return cj;
}

const Target& target_or_default(const Target* t) {
  static const Target paper;
  return t ? *t : paper;
}

}  // namespace ffsr::python
