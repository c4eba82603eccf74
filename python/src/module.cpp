// python/src/module.cpp -- the module ffsr._ffsr: the exception classes, the argument readers of
// common.hpp, and the parts bound by the other files (model.cpp, algorithms.cpp, contact.cpp, batch.cpp).
#include "common.hpp"

#include <nanobind/stl/string.h>

#include <Python.h>

namespace ffsr::python {
namespace {

using detail::str;

std::string dtype_name(const nb::dlpack::dtype& t) {
  switch (static_cast<nb::dlpack::dtype_code>(t.code)) {
    case nb::dlpack::dtype_code::Int:
      return str("int", int(t.bits));
    case nb::dlpack::dtype_code::UInt:
      return str("uint", int(t.bits));
    case nb::dlpack::dtype_code::Float:
      return str("float", int(t.bits));
    case nb::dlpack::dtype_code::Complex:
      return str("complex", int(t.bits));
    case nb::dlpack::dtype_code::Bool:
      return "bool";
    default:
      return "an unknown type";
  }
}

std::string py_type_name(nb::handle h) { return nb::cast<std::string>(nb::str(h.type().attr("__name__"))); }

/// The caller's array as float64 on the CPU, or InputError naming what is wrong with it.
nb::ndarray<nb::ro> float64_array(nb::handle h, const char* where, const char* what) {
  nb::ndarray<nb::ro> a;
  if (!nb::try_cast(h, a, false))
    throw InputError(str(where, ": ", what, " must be a numpy array of float64 or a list of numbers, got ",
                         py_type_name(h)));
  if (a.device_type() != nb::device::cpu::value)
    throw InputError(str(where, ": ", what, " must be an array in CPU memory"));
  if (a.dtype() != nb::dtype<double>())
    throw InputError(str(where, ": ", what, " must be an array of float64, got ", dtype_name(a.dtype())));
  return a;
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

bool is_sequence(nb::handle h) { return PyList_Check(h.ptr()) || PyTuple_Check(h.ptr()); }

}  // namespace

VecIn::VecIn(nb::handle h, const char* where, const char* what) : where_(where), what_(what) {
  if (is_sequence(h)) {
    const nb::sequence s = nb::borrow<nb::sequence>(h);
    owned_.resize(static_cast<Eigen::Index>(nb::len(s)));
    Eigen::Index i = 0;
    for (nb::handle x : s) owned_(i++) = number(x, where, what);
    data_ = owned_.data();
    size_ = owned_.size();
    return;
  }
  const nb::ndarray<nb::ro> a = float64_array(h, where, what);
  if (a.ndim() != 1)
    throw InputError(str(where, ": ", what, " must be a 1-dimensional array, got ", a.ndim(), " dimensions"));
  if (a.shape(0) > 1 && a.stride(0) != 1)
    throw InputError(str(where, ": ", what, " must be contiguous (a strided view: pass a copy)"));
  data_ = static_cast<const double*>(a.data());
  size_ = static_cast<Eigen::Index>(a.shape(0));
}

const VecIn& VecIn::require(Eigen::Index n) const {
  detail::require_size(size_, n, where_, what_);
  return *this;
}

MatIn::MatIn(nb::handle h, const char* where, const char* what) : where_(where), what_(what) {
  if (is_sequence(h)) {
    const nb::sequence s = nb::borrow<nb::sequence>(h);
    const auto r = static_cast<Eigen::Index>(nb::len(s));
    Eigen::Index c = -1, i = 0;
    for (nb::handle row : s) {
      if (!is_sequence(row))
        throw InputError(str(where, ": ", what, " must be a 2-dimensional array or a list of rows"));
      const nb::sequence rs = nb::borrow<nb::sequence>(row);
      const auto ci = static_cast<Eigen::Index>(nb::len(rs));
      if (c < 0) {
        c = ci;
        owned_.resize(r, c);
      } else if (ci != c) {
        throw InputError(str(where, ": ", what, ": rows of different lengths (", c, " and ", ci, ")"));
      }
      Eigen::Index j = 0;
      for (nb::handle x : rs) owned_(i, j++) = number(x, where, what);
      ++i;
    }
    if (c < 0) owned_.resize(0, 0);
    data_ = owned_.data();
    rows_ = owned_.rows();
    cols_ = owned_.cols();
    return;
  }
  const nb::ndarray<nb::ro> a = float64_array(h, where, what);
  if (a.ndim() != 2)
    throw InputError(str(where, ": ", what, " must be a 2-dimensional array, got ", a.ndim(), " dimensions"));
  const auto r = static_cast<int64_t>(a.shape(0)), c = static_cast<int64_t>(a.shape(1));
  if ((c > 1 && a.stride(1) != 1) || (r > 1 && a.stride(0) != c))
    throw InputError(str(where, ": ", what, " must be C-contiguous (row-major; a strided view or a transpose: ",
                         "pass numpy.ascontiguousarray of it)"));
  data_ = static_cast<const double*>(a.data());
  rows_ = r;
  cols_ = c;
}

const MatIn& MatIn::require(Eigen::Index r, Eigen::Index c) const {
  if (rows_ != r || (c >= 0 && cols_ != c))
    throw InputError(str(where_, ": ", what_, " has shape (", rows_, ", ", cols_, "), expected (", r, ", ",
                         c >= 0 ? str(c) : std::string("any"), ")"));
  return *this;
}

Vector3 vec3(nb::handle h, const char* where, const char* what) {
  const VecIn v(h, where, what);
  v.require(3);
  return v.map();
}

Matrix3 mat3(nb::handle h, const char* where, const char* what) {
  const MatIn a(h, where, what);
  a.require(3, 3);
  return a.map();
}

Eigen::VectorXd vecx(nb::handle h, const char* where, const char* what) { return VecIn(h, where, what).map(); }

Quaternion quat_xyzw(nb::handle h, const char* where, const char* what) {
  const VecIn v(h, where, what);
  v.require(4);
  const auto q = v.map();
  detail::require_finite_all(q, where, what);
  return Quaternion(q(3), q(0), q(1), q(2));
}

ArrayOut view(const Eigen::MatrixXd& m, nb::handle owner) {
  const size_t shape[2] = {static_cast<size_t>(m.rows()), static_cast<size_t>(m.cols())};
  const int64_t strides[2] = {1, m.rows()};  // Eigen's column-major storage
  return ArrayOut(m.data(), 2, shape, owner, strides);
}

ArrayOut view(const Eigen::VectorXd& v, nb::handle owner) {
  const size_t shape[1] = {static_cast<size_t>(v.size())};
  return ArrayOut(v.data(), 1, shape, owner);
}

nb::ndarray<nb::numpy, double> copy_out(const Eigen::Ref<const Eigen::MatrixXd>& m, bool as_vector) {
  const auto r = static_cast<size_t>(m.rows()), c = static_cast<size_t>(m.cols());
  auto* buf = new double[r * c];
  for (size_t i = 0; i < r; ++i)
    for (size_t j = 0; j < c; ++j) buf[i * c + j] = m(Eigen::Index(i), Eigen::Index(j));  // C order
  nb::capsule owner(buf, [](void* p) noexcept { delete[] static_cast<double*>(p); });
  const size_t shape[2] = {r, c};
  const size_t vshape[1] = {r * c};
  return as_vector ? nb::ndarray<nb::numpy, double>(buf, 1, vshape, owner)
                   : nb::ndarray<nb::numpy, double>(buf, 2, shape, owner);
}

nb::ndarray<nb::numpy, double> out_quat(const Quaternion& q) {
  return copy_out(q.coeffs(), true);  // x, y, z, w
}

int frame_arg(const Model& model, nb::handle frame, const char* where) {
  if (frame.is_none()) return model.end_effector();
  if (PyLong_Check(frame.ptr())) {
    const long k = PyLong_AsLong(frame.ptr());
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

ContactJoints joints_arg(const Model& model, const std::string& joints, nb::handle armature) {
  ContactJoints cj;
  cj.model = parse_joint_model(joints, "joints");
  std::vector<double> values;
  if (!armature.is_none()) {
    if (PyFloat_Check(armature.ptr()) || PyLong_Check(armature.ptr())) {
      values.push_back(number(armature, "armature", "armature"));
    } else {
      const VecIn v(armature, "armature", "armature");
      values.assign(v.map().data(), v.map().data() + v.size());
    }
  }
  cj.armature = per_joint_values(values, model, "armature");
  return cj;
}

}  // namespace ffsr::python

namespace ffsr::python {
void bind_scenario(nb::module_& m);    // scenario.cpp
void bind_controller(nb::module_& m);  // controller.cpp
void bind_jobs(nb::module_& m);        // jobs.cpp (after bind_scenario: methods of Scenario)
void bind_detumble(nb::module_& m);    // detumble.cpp
}  // namespace ffsr::python

using namespace ffsr::python;

NB_MODULE(_ffsr, m) {
  m.doc() =
      "ffsr: capture-configuration optimization for free-floating space robots (Zhang, Aerospace 2022, 9, 69).\n"
      "Bindings over the C++ library: SI units and radians, 6-vectors linear first, names as in C++.";

  // The library's exceptions, with its hierarchy (InputError is also a ValueError). The classes live
  // as long as the interpreter: plain pointers, never released (no destructor after finalization).
  static PyObject* error = PyErr_NewExceptionWithDoc(
      "ffsr.Error", "Any error of the library (C++ ffsr::Error).", PyExc_RuntimeError, nullptr);
  static PyObject* input_error = PyErr_NewExceptionWithDoc(
      "ffsr.InputError",
      "A caller's argument is wrong: size, non-finite value, range, unknown name, dtype or layout.",
      nb::make_tuple(nb::handle(error), nb::handle(PyExc_ValueError)).ptr(), nullptr);
  static PyObject* joint_rate_limit_error = PyErr_NewExceptionWithDoc(
      "ffsr.JointRateLimitError",
      "A joint-rate limit the motion cannot keep (below what the task alone needs, or invalid): an InputError.",
      input_error, nullptr);
  static PyObject* model_error = PyErr_NewExceptionWithDoc(
      "ffsr.ModelError", "A URDF file or a built tree is malformed or unphysical.", error, nullptr);
  static PyObject* numerical_error = PyErr_NewExceptionWithDoc(
      "ffsr.NumericalError",
      "A computation cannot give an answer: singular matrix, no convergence, a point out of reach.", error,
      nullptr);
  static PyObject* joint_limit_error = PyErr_NewExceptionWithDoc(
      "ffsr.JointLimitError", "A planned motion left a joint's limits (a NumericalError).", numerical_error,
      nullptr);
  static PyObject* integration_error = PyErr_NewExceptionWithDoc(
      "ffsr.IntegrationError", "SUNDIALS CVODE reported a failure (the message names the flag).", error, nullptr);
  if (!error || !input_error || !joint_rate_limit_error || !model_error || !numerical_error || !joint_limit_error || !integration_error)
    throw nb::python_error();
  m.attr("Error") = nb::borrow(error);
  m.attr("InputError") = nb::borrow(input_error);
  m.attr("JointRateLimitError") = nb::borrow(joint_rate_limit_error);
  m.attr("ModelError") = nb::borrow(model_error);
  m.attr("NumericalError") = nb::borrow(numerical_error);
  m.attr("JointLimitError") = nb::borrow(joint_limit_error);
  m.attr("IntegrationError") = nb::borrow(integration_error);
  nb::register_exception_translator([](const std::exception_ptr& p, void*) {
    try {
      std::rethrow_exception(p);
    } catch (const ffsr::JointRateLimitError& e) {
      PyErr_SetString(joint_rate_limit_error, e.what());
    } catch (const ffsr::InputError& e) {
      PyErr_SetString(input_error, e.what());
    } catch (const ffsr::ModelError& e) {
      PyErr_SetString(model_error, e.what());
    } catch (const ffsr::JointLimitError& e) {
      PyErr_SetString(joint_limit_error, e.what());
    } catch (const ffsr::NumericalError& e) {
      PyErr_SetString(numerical_error, e.what());
    } catch (const ffsr::IntegrationError& e) {
      PyErr_SetString(integration_error, e.what());
    } catch (const ffsr::Error& e) {
      PyErr_SetString(error, e.what());
    }
  });

  bind_model(m);
  bind_algorithms(m);
  bind_contact(m);
  bind_batch(m);
  bind_scenario(m);
  bind_jobs(m);
  bind_controller(m);
  bind_detumble(m);
}
