# Cross toolchain: bare-metal Cortex-M7 with a double-precision FPU (Arm's GNU toolchain as packaged by
# Debian, gcc-arm-none-eabi 12.2), newlib-nano, I/O through semihosting. The programs run on QEMU's
# mps2-an500 machine (an MPS2 board with the AN500 FPGA image: a Cortex-M7 with FPv5-D16).
#
#   cmake -S src/onboard -B build-onboard/m7 -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/cortex-m7.cmake
#
# The project (src/onboard/CMakeLists.txt) adds the platform layer for this target: the linker script,
# the startup code and -nostartfiles (it replaces rdimon's crt0 with its own reset handler).
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR cortex-m7)

set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_ASM_COMPILER arm-none-eabi-gcc)

# The compiler cannot link a program without the project's startup code and linker script: CMake's
# compiler checks build a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# fpv5-d16 is the M7's double-precision FPU; hard-float passes doubles in d-registers. These flags also
# select the matching multilib (thumb/v7e-m+dp/hard) of libc, libm, libstdc++ and libgcc.
set(FFSR_M7_ARCH_FLAGS "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb")
set(CMAKE_C_FLAGS_INIT "${FFSR_M7_ARCH_FLAGS}")
set(CMAKE_CXX_FLAGS_INIT "${FFSR_M7_ARCH_FLAGS}")
set(CMAKE_ASM_FLAGS_INIT "${FFSR_M7_ARCH_FLAGS}")
# newlib-nano (small printf, small malloc) and librdimon: newlib's system calls (_write, _open, ...)
# become semihosting requests, so printf/fopen/fwrite reach the host's terminal and files through QEMU.
# nano.specs must come first: rdimon.specs picks the _nano variants only when it sees it.
set(CMAKE_EXE_LINKER_FLAGS_INIT "${FFSR_M7_ARCH_FLAGS} --specs=nano.specs --specs=rdimon.specs")

# The emulator is a small wrapper around
#   qemu-system-arm -M mps2-an500 -nographic -semihosting-config enable=on,target=native,arg=... \
#                   -icount shift=0 -kernel <elf>
# because a program's own arguments cannot follow -kernel <elf>: they go into the semihosting
# configuration (arg=<program>,arg=<first>,...), where the startup code reads them back with
# SYS_GET_CMDLINE. target=native: QEMU serves the requests itself (not a gdb). QEMU's exit status is the
# program's (SYS_EXIT_EXTENDED). -icount shift=0 makes ffsr_cycles() count instructions.
find_program(FFSR_QEMU_SYSTEM_ARM qemu-system-arm REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR
    ${CMAKE_CURRENT_LIST_DIR}/../../src/onboard/platform/cortex_m7/qemu-run.sh)

set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
