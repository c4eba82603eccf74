// Proves the platform layer's checks fire, on every target: each mode does one forbidden thing and the
// runner (scripts/onboard.sh) expects the matching exit status and message.
//
//   platform_test ok        allocate (malloc, new, std::vector) before the lock only  -> 0
//   platform_test malloc    malloc after ffsr_heap_lock()                           -> 90
//   platform_test new       std::vector growth (operator new) after the lock         -> 90
//   platform_test stdio     first printf on a stream without a buffer, after the lock -> 90 (newlib, glibc
//                           static); 0 where the C library's own calls are not seen (host, shared libc)
//   platform_test throw     std::vector::at out of range (would throw)               -> 92 on the M7;
//                           on Linux libstdc++ throws, and allocating the exception object trips the
//                           heap guard (90; unlocked, it would end in std::terminate)
//   platform_test fault     a faulting instruction                                   -> 91 on the M7; a
//                           signal on Linux
//   platform_test count     a loop of exactly 200000 instructions timed with ffsr_cycles() -> 0; on the
//                           M7 the printed count must be 200000 to within SysTick's 40-instruction tick
//                           (QEMU implements no DWT: its CYCCNT reads 0)
//   platform_test oom       (M7) operator new until the fixed heap is exhausted          -> 93; Linux: 0,
//                           not run (its heap has no fixed bound)
//   platform_test libm FILE writes x, sin x, cos x, atan2(x, 0.7), sqrt|x|, exp(x/8) for 4096 x in
//                           [-8, 8) to FILE (the example's format) -> 0; scripts/onboard-compare.py then
//                           shows which functions of the C libraries (glibc, newlib) round differently
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "ffsr_platform.h"
#include "heap_guard.h"

namespace {

// Opaque to the optimiser, so that allocations and out-of-range indices are not folded away.
volatile std::size_t opaque_size = 64;

int run(const char* mode) {
  std::vector<double> before(opaque_size, 1.0);
  void* block = std::malloc(opaque_size);
  std::printf("mode %s: %lu allocations before the lock\n", mode, ffsr_heap_allocations());
  std::fflush(stdout);
  ffsr_heap_lock();

  if (std::strcmp(mode, "ok") == 0) {
    std::free(block);  // free stays allowed
    return before.size() == opaque_size ? 0 : 1;
  }
  if (std::strcmp(mode, "malloc") == 0) {
    void* late = std::malloc(opaque_size);
    std::printf("not trapped: %p\n", late);
    return 1;
  }
  if (std::strcmp(mode, "new") == 0) {
    before.push_back(2.0);  // the vector is full: it reallocates through operator new
    std::printf("not trapped: %zu\n", before.size());
    return 1;
  }
  if (std::strcmp(mode, "stdio") == 0) {
    // A stream never used before: its buffer is allocated on this first use.
    static const char path[] = "platform_test_stdio.txt";
    std::FILE* file = std::fopen(path, "w");
    if (file == nullptr) return 1;
    std::fprintf(file, "%d\n", 42);
    std::fclose(file);
    std::remove(path);
    std::printf("not trapped (the C library's own allocations are not wrapped here)\n");
    return 0;
  }
  if (std::strcmp(mode, "throw") == 0) {
    const double value = before.at(opaque_size + 1);
    std::printf("not trapped: %g\n", value);
    return 1;
  }
  if (std::strcmp(mode, "count") == 0) {
#if defined(__arm__) && defined(__thumb2__)
    const std::uint64_t start = ffsr_cycles();
    // 100000 iterations of two instructions (movw/movt set 100000 = 0x186a0).
    __asm__ volatile("movw r0, #0x86a0\n movt r0, #1\n 1: subs r0, r0, #1\n bne 1b\n" ::: "r0", "cc");
    const std::uint64_t spent = ffsr_cycles() - start;
    std::printf("200000 instructions counted as %lu %s\n", static_cast<unsigned long>(spent), ffsr_cycles_unit());
#else
    std::printf("count: only meaningful on the Cortex-M7 (here %s)\n", ffsr_cycles_unit());
#endif
    return 0;
  }
  if (std::strcmp(mode, "fault") == 0) {
    __builtin_trap();  // UDF on Arm (UsageFault, escalated to HardFault); SIGILL/SIGTRAP on Linux
  }
  std::fprintf(stderr, "platform_test: unknown mode %s\n", mode);
  return 1;
}

}  // namespace

// The C library's functions on a grid, in the example's file format (onboard_example.c).
int write_libm(const char* path) {
  std::FILE* file = std::fopen(path, "wb");
  if (file == nullptr) return 1;
  constexpr std::uint32_t kPoints = 4096;
  constexpr std::uint32_t kValues = 6;
  const unsigned char header[16] = {'F', 'F', 'S', 'R', 'O', 'N', 'B', '1', kValues, 0, 0, 0,
                                    kPoints & 0xFF, kPoints >> 8, 0, 0};
  bool ok = std::fwrite(header, 1, sizeof header, file) == sizeof header;
  for (std::uint32_t i = 0; i < kPoints && ok; ++i) {
    // Not a multiple of a simple fraction: the arguments are not special cases of the algorithms.
    const double x = -8.0 + 16.0 * (i + 0.318309886) / kPoints;
    const double record[kValues] = {x, std::sin(x), std::cos(x), std::atan2(x, 0.7), std::sqrt(std::fabs(x)),
                                    std::exp(x / 8.0)};
    ok = std::fwrite(record, sizeof record, 1, file) == 1;
  }
  return (std::fclose(file) == 0 && ok) ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "libm") == 0) return write_libm(argv[2]);
  if (argc == 2 && std::strcmp(argv[1], "oom") == 0) {
#if defined(__arm__)
    // 64 KiB blocks, never freed: _sbrk refuses to pass the linker script's heap, malloc returns null,
    // operator new ends the program (no_throw.cpp) instead of throwing.
    for (unsigned long blocks = 1;; ++blocks) {
      volatile char* block = new char[65536];
      block[0] = 1;
      if (blocks % 4 == 0) std::printf("%lu KiB allocated\n", blocks * 64);
    }
#else
    std::printf("oom: only run on the Cortex-M7\n");
    return 0;
#endif
  }
  if (argc < 2) {
    std::fprintf(stderr, "usage: platform_test ok|malloc|new|stdio|throw|fault|count | libm FILE\n");
    return 1;
  }
  return run(argv[1]);
}
