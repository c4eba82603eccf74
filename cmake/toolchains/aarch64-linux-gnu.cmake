# Cross toolchain: 64-bit Arm Linux (Debian's g++-12-aarch64-linux-gnu), run under qemu-aarch64.
#
#   cmake -S src/onboard -B build-onboard/aarch64 \
#         -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/aarch64-linux-gnu.cmake
#
# Programs are linked statically so that qemu-aarch64 runs them without being told where an aarch64
# dynamic loader and libc live (no -L <sysroot>).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc-12)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++-12)

# Debian's cross compilers search the host's /usr/include after their own headers (multiarch layout),
# so a host header (an x86-64 library's, or a second Eigen) could be picked up silently. With the
# sysroot set to the cross libc's directory that entry becomes /usr/aarch64-linux-gnu/usr/include,
# which does not exist: only the cross compiler's own headers remain on the default path. Eigen is
# header-only and is added explicitly by the project (-isystem /usr/include/eigen3).
set(CMAKE_SYSROOT /usr/aarch64-linux-gnu)

set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")

find_program(FFSR_QEMU_AARCH64 qemu-aarch64 REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR ${FFSR_QEMU_AARCH64})

# Libraries and headers only from the sysroot; programs (the emulator, python) from the host.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
