// ffsr/errors.hpp -- the exception hierarchy of the library.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

// The library never prints and never exits: every failure is thrown as one of these types.
//   InputError       -- a caller's argument is wrong (size, non-finite value, range, unknown name)
//   ModelError       -- a URDF file or a programmatically built tree is malformed or unphysical
//   NumericalError   -- a computation cannot give an answer (singular matrix, no convergence)
//   IntegrationError -- SUNDIALS CVODE reported a failure (the message names the flag)
// Messages name the function and the offending argument, what was expected and what came.

namespace ffsr {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
class InputError : public Error {
 public:
  using Error::Error;
};
/// A joint-rate limit the motion cannot keep (the caller's limit is below what the task alone needs,
/// or the limit itself is invalid): an InputError, so that a caller who set the limit can name it.
class JointRateLimitError : public InputError {
 public:
  using InputError::InputError;
};
class ModelError : public Error {
 public:
  using Error::Error;
};
class NumericalError : public Error {
 public:
  using Error::Error;
};
/// A planned motion left a joint's URDF limits (a NumericalError: callers that catch those see it).
class JointLimitError : public NumericalError {
 public:
  using NumericalError::NumericalError;
};
class IntegrationError : public Error {
 public:
  using Error::Error;
};

namespace detail {

/// Joins the arguments into one string with operator<<.
template <class... Args>
std::string str(const Args&... args) {
  std::ostringstream os;
  os.precision(17);
  (os << ... << args);
  return os.str();
}

/// Throws InputError("<where>: <what> must be finite, got <value>") for NaN or infinity.
inline void require_finite(double value, const char* where, const char* what) {
  if (!std::isfinite(value)) throw InputError(str(where, ": ", what, " must be finite, got ", value));
}

/// The error of require_finite_all, out of line: names the first entry of x[0..size) not finite.
[[noreturn]] inline void throw_not_finite(const double* x, Eigen::Index size, const char* where,
                                          const char* what) {
  Eigen::Index i = 0;
  while (i + 1 < size && std::isfinite(x[i])) ++i;
  throw InputError(str(where, ": ", what, " must be finite, entry ", i, " is ", x[i]));
}

/// Throws InputError unless every coefficient of an Eigen expression is finite (the test inline and
/// without a branch per entry; the error is built out of line).
template <class Derived>
void require_finite_all(const Derived& m, const char* where, const char* what) {
  bool finite = true;
  for (Eigen::Index i = 0; i < m.size(); ++i) finite &= std::isfinite(m.data()[i]);
  if (!finite) throw_not_finite(m.data(), m.size(), where, what);
}

/// Throws InputError("<where>: <what> has <got> entries, expected <expected>").
inline void require_size(long got, long expected, const char* where, const char* what) {
  if (got != expected)
    throw InputError(str(where, ": ", what, " has ", got, " entries, expected ", expected));
}

}  // namespace detail
}  // namespace ffsr
