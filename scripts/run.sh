#!/usr/bin/env bash
# Builds ffsr-optimize and runs the main job on the built-in default scenario (the paper's 3-DOF
# robot, Section 5.1). Extra arguments go to ffsr-optimize, e.g. --config robots/paper_7dof_pose.toml
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# Its own build folder with every option set, so it never changes what .ci/run builds and tests.
cmake -S . -B build-run -G Ninja -DCMAKE_BUILD_TYPE=Release -DFFSR_SANITIZE=OFF \
      -DFFSR_BUILD_TESTS=OFF -DFFSR_BUILD_CLI=ON -DFFSR_BUILD_BENCH=OFF >/dev/null
cmake --build build-run --target ffsr-optimize --parallel 2
./build-run/src/cli/ffsr-optimize "$@"
