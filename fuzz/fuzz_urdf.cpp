// fuzz_urdf: arbitrary bytes as a URDF file (see urdf_check.hpp).
#include "urdf_check.hpp"

#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    ffsr_fuzz::check_urdf_input(data, size);
  } catch (const ffsr_fuzz::Finding& f) {
    std::fprintf(stderr, "fuzz_urdf: FINDING: %s\n", f.what());
    std::abort();
  }
  return 0;
}
