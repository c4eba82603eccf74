// fuzz_numeric: arbitrary doubles into the numeric entry points (see numeric_check.hpp).
#include "numeric_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ffsr_fuzz::run_fuzz_input("fuzz_numeric", ffsr_fuzz::check_numeric_input, data, size);
}
