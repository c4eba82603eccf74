#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang and runs each for a bounded time.
#
#   bash scripts/fuzz.sh [BUILD_DIR [SECONDS_PER_TARGET]]     (defaults: /tmp/ffsr-fuzz, 60)
#
# Fails (non-zero exit) on any crash, sanitizer report (ASan, UBSan: no recovery), timeout of one input
# (-timeout=10), memory above 2 GB, leak, or NaN/inf in an output (the targets abort on it). Installs
# clang-14 and libclang-rt-14-dev with apt-get when they are missing (as root, or with sudo -n); if
# clang cannot be had, it says so on one line and exits 0. The corpus libFuzzer grows stays in
# BUILD_DIR/corpus/<target> (the seeds in fuzz/corpus/<target> are only read); a failing input is
# saved as BUILD_DIR/artifacts/<target>/crash-* (or timeout-*, oom-*, leak-*).
# The targets run one after the other (one core each); set FFSR_FUZZ_TARGETS to run only some of them.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
build=${1:-/tmp/ffsr-fuzz}
seconds=${2:-60}
targets=${FFSR_FUZZ_TARGETS:-"fuzz_urdf fuzz_scenario fuzz_numeric"}

have_clang() {
  command -v clang++-14 >/dev/null 2>&1 &&
    compgen -G "/usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a" >/dev/null
}
if ! have_clang; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo -n"
  echo "fuzz.sh: installing clang-14 and libclang-rt-14-dev"
  if ! { $SUDO apt-get update -qq &&
         DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends clang-14 libclang-rt-14-dev; } ||
     ! have_clang; then
    echo "fuzz.sh: SKIPPED: clang-14 with libFuzzer (libclang-rt-14-dev) is not available and could not be installed; no fuzz target was run"
    exit 0
  fi
fi
bash scripts/install-deps.sh  # Eigen, urdfdom, SUNDIALS, CLI11, nlohmann/json, CMake, Ninja

cmake -S fuzz -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 >/dev/null
cmake --build "$build" --parallel 2

failed=()
summary=()
for t in $targets; do
  mkdir -p "$build/corpus/$t" "$build/artifacts/$t"
  args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
        -artifact_prefix="$build/artifacts/$t/")
  [ -f "fuzz/$t.dict" ] && args+=(-dict="fuzz/$t.dict")
  log="$build/$t.log"
  echo "fuzz.sh: $t for ${seconds} s (log: $log)"
  rc=0
  "$build/$t" "${args[@]}" "$build/corpus/$t" "$src/fuzz/corpus/$t" >"$log" 2>&1 || rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
  summary+=("$t: ${execs:-?} executions, ${cov:-cov: ?}, exit $rc")
  if [ "$rc" -ne 0 ]; then
    failed+=("$t")
    echo "fuzz.sh: $t FAILED (exit $rc); the end of its log:"
    grep -v '^#[0-9]' "$log" | tail -40
    ls "$build/artifacts/$t"
  fi
done
printf 'fuzz.sh: %s\n' "${summary[@]}"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: FAILED: ${failed[*]} (reproduce with: $build/<target> <artifact>)"
  exit 1
fi
echo "fuzz.sh: all fuzz targets ran ${seconds} s each without a finding"
