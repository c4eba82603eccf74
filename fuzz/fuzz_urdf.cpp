// fuzz_urdf: arbitrary bytes as a URDF file (see urdf_check.hpp).
#include "urdf_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ffsr_fuzz::run_fuzz_input("fuzz_urdf", ffsr_fuzz::check_urdf_input, data, size);
}
