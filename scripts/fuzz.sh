#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang and runs them. Two modes:
#
#   bash scripts/fuzz.sh ci [BUILD_DIR]
#       What .ci/run does: a verdict that depends only on the commit. Each target first replays every
#       input of its seed corpus (fuzz/corpus/<target>) and of its regression folder
#       (tests/data/fuzz_regressions/<target>), then mutates from them with a FIXED seed for a FIXED
#       number of runs (the table below), starting from an empty scratch corpus each time. libFuzzer is
#       deterministic for a given seed, corpus and run count, so two runs of one commit agree.
#
#   bash scripts/fuzz.sh explore [BUILD_DIR [SECONDS_PER_TARGET [SEED]]]
#       Exploratory fuzzing for people: a random seed (printed; pass SEED to repeat a run) and a time
#       budget (default 600 s per target); the corpus grows in BUILD_DIR/corpus/<target> across runs.
#       Whatever it finds goes, once fixed, into tests/data/fuzz_regressions/<target>/ (replayed by ctest
#       and by the ci mode).
#
#   (the old form `scripts/fuzz.sh BUILD_DIR SECONDS` is the explore mode)
#
# Fails (non-zero exit) on any crash, sanitizer report (ASan, UBSan: no recovery), an input running
# longer than the timeout, memory above 2 GB, leak, or NaN/inf in an output (the targets abort on it).
# Installs clang-14 and libclang-rt-14-dev with apt-get when they are missing (as root, or with sudo -n);
# if clang cannot be had, it says so on one line and exits 0. A failing input is saved as
# BUILD_DIR/artifacts/<target>/crash-* (or timeout-*, oom-*, leak-*); replay it with BUILD_DIR/<target> FILE.
# The targets run side by side (one core each; FFSR_FUZZ_JOBS at a time, default all); set
# FFSR_FUZZ_TARGETS to run only some of them.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)

mode=explore
case "${1:-}" in
  ci|explore) mode=$1; shift ;;
esac
build=${1:-/tmp/ffsr-fuzz}
seconds=${2:-600}
seed_arg=${3:-}
targets=${FFSR_FUZZ_TARGETS:-"fuzz_urdf fuzz_scenario fuzz_numeric"}

# The ci budget: fixed seed and run count per target (about a minute each on one core of the 2-core
# CI machine; fuzz_numeric's inputs run CVODE and the planner, a few to 100 per second).
declare -A ci_seed=([fuzz_urdf]=1 [fuzz_scenario]=2 [fuzz_numeric]=3)
declare -A ci_runs=([fuzz_urdf]=150000 [fuzz_scenario]=3000 [fuzz_numeric]=2000)

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

# Determinism: libFuzzer follows its seed, but coverage also depends on addresses (pointer
# comparisons, hashes), so the ci mode turns off address-space randomization for the fuzz process
# (setarch -R) and corpus reloading (-reload=0). Measured on fuzz_urdf: without them two runs of one
# seed grew different corpora; with them three runs grew the same one, file for file.
norandom=()
if [ "$mode" = ci ]; then
  if setarch "$(uname -m)" -R true 2>/dev/null; then
    norandom=(setarch "$(uname -m)" -R)
  else
    echo "fuzz.sh: warning: setarch -R is not permitted here; the fuzz runs may differ between two runs of one commit"
  fi
fi

# One target: replay and fixed-seed mutation (ci) or a timed run (explore). Its messages go to
# stdout; its summary line to BUILD_DIR/<target>.summary, and BUILD_DIR/<target>.failed when it failed.
fuzz_one() {
  local t=$1
  mkdir -p "$build/artifacts/$t"
  common=(-timeout=60 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/artifacts/$t/")
  [ -f "fuzz/$t.dict" ] && common+=(-dict="fuzz/$t.dict")
  log="$build/$t.log"
  rc=0
  dirs=()  # the seed and regression folders that exist (libFuzzer refuses a missing one)
  for d in "$src/fuzz/corpus/$t" "$src/tests/data/fuzz_regressions/$t"; do if [ -d "$d" ]; then dirs+=("$d"); fi; done
  if [ "$mode" = ci ]; then
    # 1. every seed and regression input, once each
    inputs=()
    for d in "${dirs[@]}"; do
      while IFS= read -r f; do inputs+=("$f"); done < <(find "$d" -type f | sort)
    done
    echo "fuzz.sh: $t: replaying ${#inputs[@]} seed and regression inputs"
    "$build/$t" "${common[@]}" "${inputs[@]}" >"$log.replay" 2>&1 || rc=$?
    if [ "$rc" -ne 0 ]; then
      echo "$t (replay)" >"$build/$t.failed"
      echo "fuzz.sh: $t FAILED on a seed or regression input (exit $rc); the end of its log:"
      grep -v '^#[0-9]' "$log.replay" | tail -40
      echo "$t: replay failed" >"$build/$t.summary"
      return 0
    fi
    # 2. fixed-seed mutation from an empty scratch corpus plus the seeds and regressions
    scratch="$build/ci-corpus/$t"
    rm -rf "$scratch" && mkdir -p "$scratch"
    echo "fuzz.sh: $t: -seed=${ci_seed[$t]} -runs=${ci_runs[$t]} (log: $log)"
    "${norandom[@]}" "$build/$t" "${common[@]}" -reload=0 -seed="${ci_seed[$t]}" -runs="${ci_runs[$t]}" \
      "$scratch" "${dirs[@]}" >"$log" 2>&1 || rc=$?
  else
    seed=${seed_arg:-$(od -An -N4 -tu4 /dev/urandom | tr -d ' ')}
    mkdir -p "$build/corpus/$t"
    echo "fuzz.sh: $t for ${seconds} s, -seed=$seed (log: $log)"
    "$build/$t" "${common[@]}" -seed="$seed" -max_total_time="$seconds" \
      "$build/corpus/$t" "${dirs[@]}" >"$log" 2>&1 || rc=$?
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
  echo "$t: ${execs:-?} executions, ${cov:-cov: ?}, exit $rc" >"$build/$t.summary"
  if [ "$rc" -ne 0 ]; then
    echo "$t" >"$build/$t.failed"
    echo "fuzz.sh: $t FAILED (exit $rc); the end of its log:"
    grep -v '^#[0-9]' "$log" | tail -40
    ls "$build/artifacts/$t"
  fi
}

# The targets run side by side (each is one process on one core; libFuzzer's result for a fixed seed and
# run count does not depend on what else runs), FFSR_FUZZ_JOBS at a time (default: all of them); their
# messages are printed target by target once all have finished.
max_jobs=${FFSR_FUZZ_JOBS:-$(wc -w <<<"$targets")}
for t in $targets; do
  rm -f "$build/$t.summary" "$build/$t.failed"
  while [ "$(jobs -rp | wc -l)" -ge "$max_jobs" ]; do wait -n || true; done
  fuzz_one "$t" >"$build/$t.out" 2>&1 &
done
wait
failed=()
summary=()
for t in $targets; do
  cat "$build/$t.out"
  summary+=("$(cat "$build/$t.summary" 2>/dev/null || echo "$t: no summary (the script stopped early)")")
  if [ -f "$build/$t.failed" ] || [ ! -f "$build/$t.summary" ]; then failed+=("$(cat "$build/$t.failed" 2>/dev/null || echo "$t")"); fi
done
printf 'fuzz.sh: %s\n' "${summary[@]}"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: FAILED: ${failed[*]} (reproduce with: $build/<target> <artifact>)"
  exit 1
fi
echo "fuzz.sh: every fuzz target passed ($mode mode)"
