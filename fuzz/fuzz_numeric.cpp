// fuzz_numeric: arbitrary doubles into the numeric entry points (see numeric_check.hpp).
#include "numeric_check.hpp"

#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    ffsr_fuzz::check_numeric_input(data, size);
  } catch (const ffsr_fuzz::Finding& f) {
    std::fprintf(stderr, "fuzz_numeric: FINDING: %s\n", f.what());
    std::abort();
  }
  return 0;
}
