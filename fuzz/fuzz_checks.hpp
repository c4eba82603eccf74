// fuzz/fuzz_checks.hpp -- what every fuzz target asserts, shared with tests/test_fuzz_regressions.cpp.
#pragma once

#include "ffsr/errors.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <typeinfo>

// The contract under test: for any input the library either returns finite numbers or throws an
// ffsr::Error subclass. A check that fails throws Finding (deliberately not an ffsr::Error); the
// libFuzzer entry points turn it into abort() (a crash libFuzzer records), the Catch2 regression test
// into a failed assertion. Any other exception type escaping the library is a Finding too.

namespace ffsr_fuzz {

/// A broken contract: a crash-worthy result (NaN/inf answer, unexpected exception type, ...).
class Finding : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

[[noreturn]] inline void fail(const std::string& what) { throw Finding(what); }

/// The body of a libFuzzer entry point: check(data, size); a Finding is printed as
/// "<target>: FINDING: ..." and aborts (a crash libFuzzer records). Returns 0.
template <class Check>
int run_fuzz_input(const char* target, Check check, const std::uint8_t* data, std::size_t size) {
  try {
    check(data, size);
  } catch (const Finding& f) {
    std::fprintf(stderr, "%s: FINDING: %s\n", target, f.what());
    std::abort();
  }
  return 0;
}

inline void require_finite(double x, const std::string& what) {
  if (!std::isfinite(x)) fail(what + " is not finite: " + std::to_string(x));
}

template <class Derived>
void require_finite(const Eigen::DenseBase<Derived>& m, const std::string& what) {
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      if (!std::isfinite(m(i, j)))
        fail(what + "(" + std::to_string(i) + "," + std::to_string(j) +
             ") is not finite: " + std::to_string(m(i, j)));
}

/// Runs f; an ffsr::Error is an accepted answer (returns false), any other exception is a Finding.
/// Returns true when f returned normally.
/// With FFSR_FUZZ_TRACE set in the environment, each call prints its outcome on stderr (to see which
/// paths a reproducer or a seed reaches).
template <class F>
bool returns_or_ffsr_error(const char* what, F&& f) {
  static const bool trace = std::getenv("FFSR_FUZZ_TRACE") != nullptr;
  try {
    f();
    if (trace) std::fprintf(stderr, "[fuzz] %s: ok\n", what);
    return true;
  } catch (const Finding&) {
    throw;
  } catch (const ffsr::Error& e) {
    if (trace) std::fprintf(stderr, "[fuzz] %s: %s: %s\n", what, typeid(e).name(), e.what());
    return false;
  } catch (const std::exception& e) {
    fail(std::string(what) + ": unexpected exception " + typeid(e).name() + ": " + e.what());
  } catch (...) {
    fail(std::string(what) + ": unexpected non-standard exception");
  }
}

/// Reads the fuzz input as a stream of bytes and doubles (8 raw bytes each, so NaN, infinities,
/// denormals and huge values all occur). Past the end it returns the fallback, so that short inputs
/// still reach the deep code paths with the paper's values.
class Input {
 public:
  Input(const uint8_t* data, size_t size) : d_(data), n_(size) {}
  uint8_t byte(uint8_t fallback = 0) { return i_ < n_ ? d_[i_++] : fallback; }
  double real(double fallback) {
    if (i_ + sizeof(double) > n_) {
      i_ = n_;
      return fallback;
    }
    double x;
    std::memcpy(&x, d_ + i_, sizeof x);
    i_ += sizeof x;
    return x;
  }
  bool empty() const { return i_ >= n_; }

 private:
  const uint8_t* d_;
  size_t n_;
  size_t i_ = 0;
};

}  // namespace ffsr_fuzz
