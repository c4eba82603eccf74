// The C++ runtime pieces of the Cortex-M7 image, without exceptions.
//
// Built with -fno-exceptions, the program's own code never throws, but the library code it
// instantiates still reports errors by calling std::__throw_* (std::vector's length_error,
// std::vector::at's out_of_range, std::function's bad_function_call, ...), and libstdc++'s versions of
// those construct exception objects and call __cxa_throw: that pulls in the unwinder (_Unwind_*), the
// personality routine (__gxx_personality_v0), RTTI for the exception types and std::string, tens of
// kilobytes. Defined here, in an object file linked before libstdc++, they win over the archive's
// members, which are then never loaded. Each reports through semihosting and ends the program with
// FFSR_EXIT_CXX_ERROR: on the spacecraft such an error is a defect, not a condition to recover from.
//
// operator new is replaced for the same reason (libsupc++'s throws std::bad_alloc): exhaustion ends the
// program with FFSR_EXIT_OUT_OF_MEMORY; the nothrow forms return nullptr as the standard asks. Also the
// guard functions for function-local statics (libsupc++'s throw on recursive initialisation) and the
// pure/deleted virtual call handlers (libsupc++'s call std::terminate).
#include <bits/functexcept.h>

#include <cstddef>
#include <cstdlib>
#include <new>

#include <malloc.h>

#include "ffsr_platform.h"
#include "semihost.h"

namespace {

[[noreturn]] void cxx_error(const char* what, const char* detail) noexcept {
  ffsr_semihost_write0("ffsr: C++ error: ");
  ffsr_semihost_write0(what);
  if (detail != nullptr) {
    ffsr_semihost_write0(": ");
    ffsr_semihost_write0(detail);
  }
  ffsr_semihost_write0("\n");
  ffsr_semihost_exit(FFSR_EXIT_CXX_ERROR);
}

}  // namespace

namespace std {

void __throw_bad_exception() { cxx_error("bad_exception", nullptr); }
void __throw_bad_alloc() { ffsr_platform_fatal("out of memory (bad_alloc)", FFSR_EXIT_OUT_OF_MEMORY); }
void __throw_bad_array_new_length() { cxx_error("bad_array_new_length", nullptr); }
void __throw_bad_cast() { cxx_error("bad_cast", nullptr); }
void __throw_bad_typeid() { cxx_error("bad_typeid", nullptr); }
void __throw_logic_error(const char* what) { cxx_error("logic_error", what); }
void __throw_domain_error(const char* what) { cxx_error("domain_error", what); }
void __throw_invalid_argument(const char* what) { cxx_error("invalid_argument", what); }
void __throw_length_error(const char* what) { cxx_error("length_error", what); }
void __throw_out_of_range(const char* what) { cxx_error("out_of_range", what); }
// The format's arguments (indices, sizes) are not formatted: that would need snprintf.
void __throw_out_of_range_fmt(const char* format, ...) { cxx_error("out_of_range", format); }
void __throw_runtime_error(const char* what) { cxx_error("runtime_error", what); }
void __throw_range_error(const char* what) { cxx_error("range_error", what); }
void __throw_overflow_error(const char* what) { cxx_error("overflow_error", what); }
void __throw_underflow_error(const char* what) { cxx_error("underflow_error", what); }
void __throw_system_error(int) { cxx_error("system_error", nullptr); }
void __throw_bad_function_call() { cxx_error("bad_function_call", nullptr); }

}  // namespace std

// ---- operator new / delete: malloc and free, no bad_alloc. ----

namespace {

void* allocate_or_die(std::size_t bytes) noexcept {
  void* pointer = std::malloc(bytes == 0 ? 1 : bytes);
  if (pointer == nullptr) ffsr_platform_fatal("out of memory (operator new)", FFSR_EXIT_OUT_OF_MEMORY);
  return pointer;
}

}  // namespace

void* operator new(std::size_t bytes) { return allocate_or_die(bytes); }
void* operator new[](std::size_t bytes) { return allocate_or_die(bytes); }
void* operator new(std::size_t bytes, const std::nothrow_t&) noexcept { return std::malloc(bytes == 0 ? 1 : bytes); }
void* operator new[](std::size_t bytes, const std::nothrow_t&) noexcept { return std::malloc(bytes == 0 ? 1 : bytes); }
void operator delete(void* pointer) noexcept { std::free(pointer); }
void operator delete[](void* pointer) noexcept { std::free(pointer); }
void operator delete(void* pointer, std::size_t) noexcept { std::free(pointer); }
void operator delete[](void* pointer, std::size_t) noexcept { std::free(pointer); }
void operator delete(void* pointer, const std::nothrow_t&) noexcept { std::free(pointer); }
void operator delete[](void* pointer, const std::nothrow_t&) noexcept { std::free(pointer); }

// Over-aligned types (alignas beyond 8) would use the align_val_t forms; Eigen does not (it aligns its
// own blocks), and no onboard code is expected to. They are defined so that a use links against these
// rather than libsupc++'s throwing ones.
namespace {

void* allocate_aligned_or_die(std::size_t bytes, std::align_val_t alignment) noexcept {
  const std::size_t align = static_cast<std::size_t>(alignment);
  // memalign (newlib-nano's aligned_alloc needs posix_memalign, which nano lacks).
  void* pointer = ::memalign(align, bytes == 0 ? 1 : bytes);
  if (pointer == nullptr) ffsr_platform_fatal("out of memory (operator new)", FFSR_EXIT_OUT_OF_MEMORY);
  return pointer;
}

}  // namespace

void* operator new(std::size_t bytes, std::align_val_t alignment) { return allocate_aligned_or_die(bytes, alignment); }
void* operator new[](std::size_t bytes, std::align_val_t alignment) { return allocate_aligned_or_die(bytes, alignment); }
void operator delete(void* pointer, std::align_val_t) noexcept { std::free(pointer); }
void operator delete[](void* pointer, std::align_val_t) noexcept { std::free(pointer); }
void operator delete(void* pointer, std::size_t, std::align_val_t) noexcept { std::free(pointer); }
void operator delete[](void* pointer, std::size_t, std::align_val_t) noexcept { std::free(pointer); }

// ---- The C++ ABI's runtime hooks. ----

extern "C" {

// Function-local statics: one thread, no interrupts touching C++ statics, so the guard is a flag.
// The guard object's first byte is "initialised" (the compiler's inline fast path tests it); its second
// byte marks an initialisation in progress, to catch a recursive one (undefined behaviour).
int __cxa_guard_acquire(unsigned int* guard) {
  unsigned char* const bytes = reinterpret_cast<unsigned char*>(guard);
  if (bytes[0] != 0) return 0;
  if (bytes[1] != 0) cxx_error("recursive initialisation of a static", nullptr);
  bytes[1] = 1;
  return 1;
}

void __cxa_guard_release(unsigned int* guard) {
  unsigned char* const bytes = reinterpret_cast<unsigned char*>(guard);
  bytes[1] = 0;
  bytes[0] = 1;
}

void __cxa_guard_abort(unsigned int* guard) { reinterpret_cast<unsigned char*>(guard)[1] = 0; }

void __cxa_pure_virtual() { cxx_error("pure virtual function called", nullptr); }
void __cxa_deleted_virtual() { cxx_error("deleted virtual function called", nullptr); }

}  // extern "C"
