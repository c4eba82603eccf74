#!/usr/bin/env bash
# Builds the onboard project (src/onboard) for the host, aarch64 Linux and the Cortex-M7, runs each
# target's example and platform tests in its emulator, checks them, and compares the outputs.
#
#   scripts/onboard.sh [host] [aarch64] [m7]        (default: all three)
#
# Per target, in build-onboard/<target>/: the build, onboard_output.bin (the example's output),
# onboard_example.log, libm.bin and platform_test.log. Exit status 0 only if every step passed:
# configure, build, the example's exit status, the platform test's expected failures (the heap guard,
# and on the M7 the C++ error and fault handlers), the include-path and image checks, the comparison.
#
# Environment:
#   FFSR_ONBOARD_JOBS      parallel build jobs (default 2; builds run under nice -n 10)
#   FFSR_ONBOARD_COMPARE   the comparison command; it is given NAME=FILE arguments, the host's first,
#                          and fails with a non-zero status (default: compare_outputs below)
#   FFSR_ONBOARD_EXPORT    ffsr-onboard-export (default: build-ci's, then build's) that writes the
#                          example's four blobs from the scenario files into build-onboard/blobs/
#   FFSR_QEMU_TIMEOUT      seconds before an emulator run counts as hung (default 600)
set -uo pipefail
# No compiler cache here (.ci/run sets ccache for its other stages): on a hit ccache restores the object
# and the .su file but not GCC's call-graph file (.ci), which the stack analysis reads.
unset CMAKE_C_COMPILER_LAUNCHER CMAKE_CXX_COMPILER_LAUNCHER

root=$(cd "$(dirname "$0")/.." && pwd)
build_root=$root/build-onboard
jobs=${FFSR_ONBOARD_JOBS:-2}
timeout_s=${FFSR_QEMU_TIMEOUT:-600}
stack_entries=(--entry ffsr_capture_step --entry ffsr_detumble_step)
m7_runner=$root/src/onboard/platform/cortex_m7/qemu-run.sh

if [ $# -gt 0 ]; then targets=("$@"); else targets=(host aarch64 m7); fi

failures=()
fail() {
  echo "FAIL: $*" >&2
  failures+=("$*")
}

toolchain_of() {
  case $1 in
    host) echo "" ;;
    aarch64) echo "$root/cmake/toolchains/aarch64-linux-gnu.cmake" ;;
    m7) echo "$root/cmake/toolchains/cortex-m7.cmake" ;;
    *) echo "unknown target $1" >&2; return 1 ;;
  esac
}

program_of() {  # the file name of a program on a target
  case $1 in m7) echo "$2.elf" ;; *) echo "$2" ;; esac
}

# Runs a program of a target in its emulator, in build-onboard/<target>/ (where its files land).
run_on() {
  local target=$1 program=$2
  shift 2
  local image
  image=$(program_of "$target" "$program")
  (
    cd "$build_root/$target" || exit 2
    case $target in
      host) exec timeout "$timeout_s" "./$image" "$@" ;;
      aarch64) exec timeout "$timeout_s" qemu-aarch64 "./$image" "$@" ;;
      m7) FFSR_QEMU_TIMEOUT=$timeout_s exec "$m7_runner" "$image" "$@" ;;
    esac
  )
}

# The tools a target needs (Debian 12: cmake ninja-build python3 qemu-user qemu-system-arm
# g++-12-aarch64-linux-gnu gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib libnewlib-arm-none-eabi
# libeigen3-dev).
check_tools() {
  local tools=(cmake ninja python3 timeout) missing=()
  case $1 in
    host) tools+=(gcc g++) ;;
    aarch64) tools+=(aarch64-linux-gnu-gcc-12 aarch64-linux-gnu-g++-12 qemu-aarch64) ;;
    m7) tools+=(arm-none-eabi-gcc arm-none-eabi-g++ arm-none-eabi-nm arm-none-eabi-size qemu-system-arm) ;;
  esac
  for tool in "${tools[@]}"; do command -v "$tool" >/dev/null || missing+=("$tool"); done
  if [ ${#missing[@]} -ne 0 ]; then
    fail "$1: missing ${missing[*]}"
    return 1
  fi
}

build() {
  local target=$1 toolchain dir=$build_root/$1
  toolchain=$(toolchain_of "$target") || return 1
  local args=(-G Ninja -S "$root/src/onboard" -B "$dir")
  [ -n "$toolchain" ] && args+=("-DCMAKE_TOOLCHAIN_FILE=$toolchain")
  args+=("-DFFSR_ONBOARD_BLOB_DIR=$build_root/blobs")
  echo "== $target: configure and build"
  if ! nice -n 10 cmake "${args[@]}" >"$dir.configure.log" 2>&1; then
    cat "$dir.configure.log" >&2
    fail "$target: configure"
    return 1
  fi
  if ! nice -n 10 cmake --build "$dir" -j "$jobs" >"$dir/build.log" 2>&1; then
    cat "$dir/build.log" >&2
    fail "$target: build"
    return 1
  fi
}

# The cross builds must not read the host's headers: every header a cross object depends on must be
# the cross toolchain's, Eigen's, or the project's (ninja records the compiler's dependency lists).
check_include_paths() {
  local target=$1
  [ "$target" = host ] && return 0
  local strays
  strays=$(ninja -C "$build_root/$target" -t deps | grep -E '^ +/usr/include/' |
    grep -vE '^ +/usr/include/(eigen3|newlib)/' | sort -u)
  if [ -n "$strays" ]; then
    echo "$strays" | head -20 >&2
    fail "$target: host headers on the cross include path"
  else
    echo "   include paths: no host header (only the cross toolchain's, Eigen's, the project's)"
  fi
}

run_example() {
  local target=$1 dir=$build_root/$1 start end status
  rm -f "$dir/onboard_output.bin"
  start=$(date +%s.%N)
  run_on "$target" onboard_example onboard_output.bin >"$dir/onboard_example.log" 2>&1
  status=$?
  end=$(date +%s.%N)
  sed 's/^/   /' "$dir/onboard_example.log"
  awk -v t="$target" -v s="$start" -v e="$end" 'BEGIN { printf "   run time (%s, 10^4 steps, wall): %.2f s\n", t, e - s }'
  if [ $status -ne 0 ]; then
    fail "$target: onboard_example exited with $status"
  elif [ ! -s "$dir/onboard_output.bin" ]; then
    fail "$target: onboard_example wrote no output file"
  fi
}

# expect <target> <mode> <status|nonzero> [message]: platform_test <mode> must end that way.
expect() {
  local target=$1 mode=$2 want=$3 message=${4:-} out status
  out=$(run_on "$target" platform_test "$mode" 2>&1)
  status=$?
  printf '%s\n' "== platform_test $mode -> $status" "$out" >>"$build_root/$target/platform_test.log"
  local ok=1
  if [ "$want" = nonzero ]; then [ $status -ne 0 ] || ok=0; else [ $status -eq "$want" ] || ok=0; fi
  if [ -n "$message" ] && ! grep -q "$message" <<<"$out"; then ok=0; fi
  if [ $ok -eq 1 ]; then
    echo "   platform_test $mode: exit $status as expected${message:+ (\"$message\")}"
  else
    fail "$target: platform_test $mode exited with $status, expected $want${message:+ and \"$message\"}"
    echo "$out" | sed 's/^/     /' >&2
  fi
}

run_platform_tests() {
  local target=$1
  : >"$build_root/$target/platform_test.log"
  expect "$target" ok 0
  expect "$target" malloc 90 "heap allocation after initialisation"
  expect "$target" new 90 "heap allocation after initialisation"
  expect "$target" stdio 90 "heap allocation after initialisation"
  if [ "$target" = m7 ]; then
    expect "$target" throw 92 "C++ error: out_of_range"
    expect "$target" fault 91 "ffsr: fault"
    expect "$target" oom 93 "out of memory"
  else
    expect "$target" throw nonzero
    expect "$target" fault nonzero
  fi
  expect "$target" count 0
  grep -h "instructions counted" "$build_root/$target/platform_test.log" | sed 's/^/   /'
  rm -f "$build_root/$target/libm.bin"
  run_on "$target" platform_test libm libm.bin >/dev/null 2>&1 || fail "$target: platform_test libm"
}

# The M7 image must not contain libstdc++'s exception machinery (no_throw.cpp replaces its entry points).
check_m7_image() {
  local dir=$build_root/m7 elf symbols
  for elf in "$dir/onboard_example.elf" "$dir/platform_test.elf"; do
    symbols=$(arm-none-eabi-nm "$elf" | grep -E ' (__cxa_throw|__cxa_begin_catch|__gxx_personality_v0|_Unwind_[A-Za-z_]*|__cxa_allocate_exception)$')
    if [ -n "$symbols" ]; then
      echo "$symbols" >&2
      fail "m7: exception machinery in $(basename "$elf")"
    fi
  done
  echo "   no __cxa_throw, __gxx_personality_v0, _Unwind_* in the images"
  arm-none-eabi-size "$dir/onboard_example.elf" | sed 's/^/   /'
  echo "   (bss includes the fixed stack and heap regions: arm-none-eabi-size -A for sections)"
}

report_stack() {
  local target=$1 dir=$build_root/$1
  echo "   static stack analysis (scripts/stack-usage.py):"
  python3 "$root/scripts/stack-usage.py" "$dir/CMakeFiles/ffsr_onboard.dir" "${stack_entries[@]}" |
    sed 's/^/     /' || fail "$target: stack analysis"
}

# The core's objects must hold no exception or RTTI machinery: no throw (__cxa_throw, the allocation of
# an exception), no handler (__cxa_begin_catch, the personality routine), no typeid or dynamic_cast, no
# type_info objects (_ZTI*, _ZTS*). nm lists the defined and the undefined symbols of every object.
check_core_symbols() {
  local target=$1 nm=nm
  case $target in aarch64) nm=aarch64-linux-gnu-nm ;; m7) nm=arm-none-eabi-nm ;; esac
  local symbols
  symbols=$($nm "$build_root/$target/libffsr_onboard.a" |
    grep -E ' (__cxa_throw|__cxa_allocate_exception|__cxa_begin_catch|__cxa_rethrow|__gxx_personality_v0|__cxa_bad_typeid|__cxa_bad_cast|__dynamic_cast|_ZTI[A-Za-z0-9_]*|_ZTS[A-Za-z0-9_]*)$')
  if [ -n "$symbols" ]; then
    echo "$symbols" | sort -u | head -20 >&2
    fail "$target: exception or RTTI symbols in the core's objects"
  else
    echo "   core objects: no __cxa_throw, personality, typeid, dynamic_cast or type_info symbol"
  fi
}

# clang-tidy (src/onboard/.clang-tidy: bugprone, cert, performance, a subset of the C++ Core Guidelines)
# and cppcheck on the core: src/onboard/ffsr_onboard.cpp and every ffsr header it includes, with the
# host build's flags (its compile_commands.json); any finding fails.
lint_core() {
  local dir=$build_root/host
  echo "== lint: clang-tidy and cppcheck on the onboard core"
  if ! command -v clang-tidy-14 >/dev/null || ! command -v cppcheck >/dev/null; then
    fail "lint: clang-tidy-14 or cppcheck missing (Debian: clang-tidy-14 cppcheck)"
    return 1
  fi
  # the core's flags (src/onboard/CMakeLists.txt) but GCC's stack-usage options, which clang does not know
  if nice -n 10 clang-tidy-14 --quiet "$root/src/onboard/ffsr_onboard.cpp" "$root/src/onboard/core_check.cpp" \
       -- -std=c++17 -fno-exceptions \
       -fno-rtti "-I$root/include" -isystem /usr/include/eigen3 -DEIGEN_DONT_VECTORIZE -DEIGEN_NO_DEBUG \
       -DEIGEN_ALLOCA=__builtin_alloca -DEIGEN_STACK_ALLOCATION_LIMIT=4096 >"$dir/clang-tidy.log" 2>&1; then
    echo "   clang-tidy: no finding"
  else
    grep -E "(warning|error):" "$dir/clang-tidy.log" | head -30 >&2
    fail "lint: clang-tidy findings ($dir/clang-tidy.log)"
  fi
  if nice -n 10 cppcheck --quiet --enable=warning,performance,portability --std=c++17 --inline-suppr \
       --error-exitcode=1 -I "$root/include" --language=c++ "$root/src/onboard/ffsr_onboard.cpp" \
       "$root/src/onboard/core_check.cpp" \
       >"$dir/cppcheck.log" 2>&1 &&
     nice -n 10 cppcheck --quiet --enable=warning,performance,portability --std=c99 --inline-suppr \
       --error-exitcode=1 -I "$root/include" -I "$root/src/onboard/platform" --language=c \
       "$root/examples/onboard/onboard_example.c" >>"$dir/cppcheck.log" 2>&1; then
    echo "   cppcheck: no finding"
  else
    head -30 "$dir/cppcheck.log" >&2
    fail "lint: cppcheck findings ($dir/cppcheck.log)"
  fi
}

# The example's four blobs, written once from the scenario files by the host's ffsr-onboard-export.
make_blobs() {
  local export=${FFSR_ONBOARD_EXPORT:-}
  if [ -z "$export" ]; then
    for candidate in "$root/build-ci/ffsr-onboard-export" "$root/build/ffsr-onboard-export"; do
      [ -x "$candidate" ] && { export=$candidate; break; }
    done
  fi
  if [ -z "$export" ] || [ ! -x "$export" ]; then
    fail "ffsr-onboard-export not found: build the project (scripts/run.sh or .ci/run) or set FFSR_ONBOARD_EXPORT"
    return 1
  fi
  mkdir -p "$build_root/blobs"
  local out=$build_root/blobs
  echo "== blobs ($export)"
  "$export" "$root/robots/paper_3dof.toml" capture ffsr_blob_capture_3dof "$out/capture_3dof.c" &&
    "$export" "$root/robots/paper_7dof_position.toml" capture ffsr_blob_capture_7dof "$out/capture_7dof.c" &&
    "$export" "$root/examples/onboard/paper_3dof_detumble.toml" detumble ffsr_blob_detumble_3dof \
      "$out/detumble_3dof.c" &&
    "$export" "$root/robots/paper_7dof_detumble.toml" detumble ffsr_blob_detumble_7dof "$out/detumble_7dof.c" ||
    { fail "the example's blobs"; return 1; }
}

# The comparison across targets: every command of every tick against the host's. Values relative to the
# largest value of their own command (a torque component near zero is compared at its vector's scale):
# 1e-12. The compilers contract no multiply-add (-ffp-contract=off) and Eigen does not vectorize, so the
# arithmetic is the same operations in the same order on every target; what differs is the C library's
# sin, cos and atan2 (glibc and newlib round a few arguments differently in the last place; platform_test
# libm shows which).
compare_outputs() {
  python3 "$root/scripts/onboard-compare.py" --record-rel 1e-12 --skip 2 "$@"
}

mkdir -p "$build_root"
make_blobs || { printf '  %s\n' "${failures[@]}" >&2; exit 1; }
for target in "${targets[@]}"; do
  if ! check_tools "$target" || ! build "$target"; then continue; fi
  check_include_paths "$target"
  check_core_symbols "$target"
  run_example "$target"
  run_platform_tests "$target"
  [ "$target" = m7 ] && check_m7_image
  [ "$target" = host ] && lint_core
  report_stack "$target"
done

# Compare every target's output with the host's (or the first target's).
files=()
for target in "${targets[@]}"; do
  [ -s "$build_root/$target/onboard_output.bin" ] && files+=("$target=$build_root/$target/onboard_output.bin")
done
if [ ${#files[@]} -ge 2 ]; then
  echo "== comparison of the outputs"
  if [ -n "${FFSR_ONBOARD_COMPARE:-}" ]; then
    $FFSR_ONBOARD_COMPARE "${files[@]}" || fail "comparison of the outputs"
  else
    compare_outputs "${files[@]}" || fail "comparison of the outputs"
  fi
  libm=()
  for target in "${targets[@]}"; do
    [ -s "$build_root/$target/libm.bin" ] && libm+=("$target=$build_root/$target/libm.bin")
  done
  echo "== the C libraries' sin, cos, atan2, sqrt, exp (values 1-5 of a record) compared (information)"
  python3 "$root/scripts/onboard-compare.py" "${libm[@]}" | sed 's/ -> FAIL.*//'
fi

if [ ${#failures[@]} -ne 0 ]; then
  echo "onboard: ${#failures[@]} failure(s):" >&2
  printf '  %s\n' "${failures[@]}" >&2
  exit 1
fi
echo "onboard: all targets passed (${targets[*]})"
