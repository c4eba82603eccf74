// ffsr/errors.hpp -- the exception hierarchy of the library.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

// The library never prints and never exits: every failure is thrown as one of these types.
//   InputError       -- a caller's argument is wrong (size, non-finite value, range, unknown name)
//   ModelError       -- a URDF file or a programmatically built tree is malformed or unphysical
//   NumericalError   -- a computation cannot give an answer (singular matrix, no convergence)
//   IntegrationError -- SUNDIALS CVODE reported a failure (the message names the flag)
// Messages name the function and the offending argument, what was expected and what came.
//
// The onboard core (the controllers and the headers they include: algorithm/, model/, spatial/,
// contact/, the capture rate law of optimize/, control/'s controllers) also compiles without exceptions
// (-fno-exceptions, flight software's rule). It throws through FFSR_THROW and catches through FFSR_TRY /
// FFSR_CATCH; without exceptions a throw becomes a call of the failure handler (set_failure_handler: the
// platform's fault reporting, e.g. a flight framework's FDIR hook) followed by std::abort(), and a
// handler is never entered. Onboard, the checks that throw are the contract of direct C++ callers at
// initialisation: the controllers' steps check their inputs first and report a bad one as a status, so
// they never reach a throw; the C interface (onboard/ffsr_onboard.h) checks its inputs before it builds
// anything. The rest of the library (parsers, scenarios, jobs, CVODE, the planner) needs exceptions.
#if defined(__cpp_exceptions) || defined(__EXCEPTIONS)
#define FFSR_THROW(...) throw __VA_ARGS__
#define FFSR_RETHROW throw
#define FFSR_TRY try
#define FFSR_CATCH(...) catch (__VA_ARGS__)
#else
// the argument is not evaluated (an operand of sizeof: no code, and the names in the message count as
// used): a message is built only where it can be thrown
#define FFSR_THROW(...) ::ffsr::detail::failed_check(__FILE__, __LINE__, sizeof(__VA_ARGS__))
#define FFSR_RETHROW ::ffsr::detail::failed_check(__FILE__, __LINE__)
#define FFSR_TRY if (true)
#define FFSR_CATCH(...) else if (false)
#endif

namespace ffsr {

/// pi, for the headers that must compile in strict ISO C++ (M_PI is POSIX, not in newlib's strict mode).
inline constexpr double kPi = 3.14159265358979323846;

/// What the library calls, without exceptions, where it would throw: the source file and line of the
/// check that failed. It may not return (std::abort() follows when it does).
using FailureHandler = void (*)(const char* file, int line);

namespace detail {
inline FailureHandler failure_handler = nullptr;

[[noreturn]] inline void failed_check(const char* file, int line, std::size_t /*exception's size*/ = 0) noexcept {
  if (failure_handler != nullptr) failure_handler(file, line);
  std::abort();
}
}  // namespace detail

/// Sets the handler of a failed check in a build without exceptions (nullptr: std::abort() alone);
/// returns the previous one. With exceptions the library throws and never calls it.
inline FailureHandler set_failure_handler(FailureHandler h) noexcept {
  const FailureHandler old = detail::failure_handler;
  detail::failure_handler = h;
  return old;
}

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

/// x with `digits` significant digits (1..17): positional from 1e-5 to below 1e16 (200, 0.05,
/// 1000000000), else with an exponent (1e-07, 2.5e+20); no trailing zeros. Non-finite: inf, -inf, nan.
inline std::string number_with_digits(double x, int digits) {
  if (!std::isfinite(x)) return std::isnan(x) ? "nan" : x > 0 ? "inf" : "-inf";
  char e_form[40], out[400];
  (void)std::snprintf(e_form, sizeof e_form, "%.*e", digits - 1, x);
  const int exponent = static_cast<int>(std::strtol(std::strchr(e_form, 'e') + 1, nullptr, 10));  // of x rounded
  if (exponent < -5 || exponent >= 16) {
    std::string t(e_form);  // drop the mantissa's trailing zeros: 1.50000e-07 -> 1.5e-07
    const size_t e = t.find('e'), dot = t.find('.');
    if (dot == std::string::npos) return t;
    size_t end = e;
    while (end > dot + 1 && t[end - 1] == '0') --end;
    if (end == dot + 1) --end;
    return t.substr(0, end) + t.substr(e);
  }
  (void)std::snprintf(out, sizeof out, "%.*f", std::max(digits - 1 - exponent, 0), x);
  std::string t(out);
  if (t.find('.') != std::string::npos) {
    while (t.back() == '0') t.pop_back();
    if (t.back() == '.') t.pop_back();
  }
  return t;
}

/// The fewest significant digits (1..17) that read back as x exactly.
inline int shortest_digits(double x) {
  if (!std::isfinite(x) || x == 0) return 1;
  char buf[40];
  for (int p = 1; p < 17; ++p) {
    (void)std::snprintf(buf, sizeof buf, "%.*e", p - 1, x);
    if (std::strtod(buf, nullptr) == x) return p;
  }
  return 17;
}

/// The shortest text that reads back as x exactly (0.05, not 0.050000000000000003).
inline std::string shortest_number(double x) { return number_with_digits(x, shortest_digits(x)); }

/// A number as a message shows it: as a person writes it when that reads back as x exactly with at
/// most 9 significant digits (a value a user gave: 0.05, 120, 1e-07), else 6 significant digits (a
/// computed value: 3.4641, not 3.4641016151377544).
inline std::string message_number(double x) {
  const int p = shortest_digits(x);
  return number_with_digits(x, p <= 9 ? p : 6);
}

/// One argument of str: floating-point numbers as message_number, everything else with operator<<.
template <class T>
void put_message_part(std::ostream& os, const T& x) {
  if constexpr (std::is_floating_point_v<T>)
    os << message_number(static_cast<double>(x));
  else
    os << x;
}

/// Joins the arguments into one string (numbers as message_number; Eigen matrices with 6 digits).
template <class... Args>
std::string str(const Args&... args) {
  std::ostringstream os;
  (put_message_part(os, args), ...);
  return os.str();
}

/// Throws InputError("<where>: <what> must be finite, got <value>") for NaN or infinity.
inline void require_finite(double value, const char* where, const char* what) {
  if (!std::isfinite(value)) FFSR_THROW(InputError(str(where, ": ", what, " must be finite, got ", value)));
}

/// The error of require_finite_all, out of line: names the first entry of x[0..size) not finite.
[[noreturn]] inline void throw_not_finite(const double* x, Eigen::Index size, const char* where,
                                          const char* what) {
  Eigen::Index i = 0;
  while (i + 1 < size && std::isfinite(x[i])) ++i;
  FFSR_THROW(InputError(str(where, ": ", what, " must be finite, entry ", i, " is ", x[i])));
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
    FFSR_THROW(InputError(str(where, ": ", what, " has ", got, " entries, expected ", expected)));
}

}  // namespace detail
}  // namespace ffsr
