// python/src/exceptions.cpp -- the library's exceptions in Python, with its hierarchy: ffsr.Error (a
// RuntimeError) > InputError (also a ValueError) > JointRateLimitError; ModelError; NumericalError >
// JointLimitError; IntegrationError. A C++ exception leaves a bound call as the class of the same name.
#include "common.hpp"
#include "bindings.hpp"

#include <Python.h>

#include <string>

namespace ffsr::python {
namespace {

/// The classes live as long as the interpreter: plain pointers, never released (no destructor runs
/// after finalization).
struct Classes {
  PyObject *error, *input, *joint_rate_limit, *model, *numerical, *joint_limit, *integration;
};
Classes classes;

PyObject* new_class(nb::module_& m, const char* name, const char* doc, PyObject* base) {
  PyObject* c = PyErr_NewExceptionWithDoc((std::string("ffsr.") + name).c_str(), doc, base, nullptr);
  if (!c) throw nb::python_error();
  m.attr(name) = nb::borrow(c);
  return c;
}

void translate(const std::exception_ptr& p, void*) {
  try {
    std::rethrow_exception(p);
  } catch (const ffsr::JointRateLimitError& e) {
    PyErr_SetString(classes.joint_rate_limit, e.what());
  } catch (const ffsr::InputError& e) {
    PyErr_SetString(classes.input, e.what());
  } catch (const ffsr::ModelError& e) {
    PyErr_SetString(classes.model, e.what());
  } catch (const ffsr::JointLimitError& e) {
    PyErr_SetString(classes.joint_limit, e.what());
  } catch (const ffsr::NumericalError& e) {
    PyErr_SetString(classes.numerical, e.what());
  } catch (const ffsr::IntegrationError& e) {
    PyErr_SetString(classes.integration, e.what());
  } catch (const ffsr::Error& e) {
    PyErr_SetString(classes.error, e.what());
  }
}

}  // namespace

void bind_exceptions(nb::module_& m) {
  Classes& c = classes;
  c.error = new_class(m, "Error", "Any error of the library (C++ ffsr::Error).", PyExc_RuntimeError);
  const nb::tuple input_bases = nb::make_tuple(nb::handle(c.error), nb::handle(PyExc_ValueError));
  c.input =
      new_class(m, "InputError",
                "A caller's argument is wrong: size, non-finite value, range, unknown name, dtype or layout.",
                input_bases.ptr());
  c.joint_rate_limit =
      new_class(m, "JointRateLimitError",
                "A joint-rate limit the motion cannot keep (below what the task alone needs, or "
                "invalid): an InputError.",
                c.input);
  c.model = new_class(m, "ModelError", "A URDF file or a built tree is malformed or unphysical.", c.error);
  c.numerical =
      new_class(m, "NumericalError",
                "A computation cannot give an answer: singular matrix, no convergence, a point out of "
                "reach.",
                c.error);
  c.joint_limit = new_class(m, "JointLimitError",
                            "A planned motion left a joint's limits (a NumericalError).", c.numerical);
  c.integration = new_class(m, "IntegrationError",
                            "SUNDIALS CVODE reported a failure (the message names the flag).", c.error);
  nb::register_exception_translator(translate);
}

}  // namespace ffsr::python
