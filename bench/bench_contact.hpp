// bench/bench_contact.hpp -- benchmarks of the contact hot paths (included by bench_main.cpp):
//   the closed-form F_max (Eq. 24), the exact single-body F_max (bracketed Newton on Eq. 19),
//   and one CVODE run of the single-body model Eq. 16 from first touch to separation.
#pragma once

#include "ffsr/contact/contact_law.hpp"
#include "ffsr/simulate/single_body.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ostream>
#include <vector>

// Each reports the median over several batches of the time per call (std::chrono::steady_clock);
// the results feed a volatile sink and the inputs vary per call so nothing is optimized away.
// Targets: closed form < 1 µs, exact < 20 µs.

namespace ffsr::bench {

/// Median over `batches` of the mean time per call [s] of fn(i), i = 0 .. calls-1 per batch.
template <class Fn>
double median_seconds_per_call(Fn&& fn, int calls, int batches) {
  volatile double sink = 0;
  std::vector<double> per_call;
  per_call.reserve(static_cast<std::size_t>(batches));
  for (int b = 0; b < batches; ++b) {
    const auto t0 = std::chrono::steady_clock::now();
    double acc = 0;
    for (int i = 0; i < calls; ++i) acc += fn(i);
    const auto t1 = std::chrono::steady_clock::now();
    sink = sink + acc;
    per_call.push_back(std::chrono::duration<double>(t1 - t0).count() / calls);
  }
  std::nth_element(per_call.begin(), per_call.begin() + batches / 2, per_call.end());
  return per_call[static_cast<std::size_t>(batches / 2)];
}

}  // namespace ffsr::bench

/// Prints one line per benchmark to `os`.
inline void bench_contact(std::ostream& os) {
  using namespace ffsr;
  // The paper's contact (Table 3): K = 1e9, α = 1.5, c_r = 0.9, Herbert-McWhannell, 0.2052 m/s.
  const AnyContactLaw law = make_contact_law("herbert-mcwhannell", {1e9, 1.5, 0.9}, 0.20524);
  // The law built inside the loop too (what the optimizer pays per evaluation if it rebuilds it).
  const double closed = bench::median_seconds_per_call(
      [&](int i) { return max_force_closed_form(law, 1.5 + 1e-3 * (i % 1000)); }, 200000, 15);
  const double closed_built = bench::median_seconds_per_call(
      [&](int i) {
        const auto l = make_contact_law("herbert-mcwhannell", {1e9, 1.5, 0.9}, 0.2 + 1e-6 * (i % 1000));
        return max_force_closed_form(l, 5.0);
      },
      100000, 15);
  // The exact maximum re-solves s* on every call; vary c_r so s* changes.
  const double exact = bench::median_seconds_per_call(
      [&](int i) {
        const HertzDamped<HerbertMcWhannell> l({1e9, 1.5, 0.5 + 4e-4 * (i % 1000)}, 0.20524);
        return l.max_force_exact(1.5 + 1e-3 * (i % 997));
      },
      50000, 15);
  const double sim = bench::median_seconds_per_call(
      [&](int i) { return simulate_single_body(law, 5.0 + 1e-3 * i).f_max; }, 20, 11);

  auto row = [&os](const char* what, double value, const char* unit) {
    char line[160];
    std::snprintf(line, sizeof line, "contact: %-38s%10.4f %s\n", what, value, unit);
    os << line;
  };
  row("closed-form F_max (Eq. 24)", closed * 1e6, "us/call");
  row("make_contact_law + closed-form F_max", closed_built * 1e6, "us/call");
  row("exact single-body F_max (Eq. 19)", exact * 1e6, "us/call");
  row("single-body CVODE run (Eq. 16)", sim * 1e3, "ms/run");
}
