#!/usr/bin/env bash
# Installs the Debian 12 packages ffsr needs, only when some are missing (needs root, as on CI).
set -euo pipefail
packages=(cmake ninja-build g++ pkg-config libeigen3-dev liburdfdom-dev libtinyxml-dev libsundials-dev
          catch2 libcli11-dev nlohmann-json3-dev
          libtomlplusplus-dev
          libplplot-dev plplot-driver-cairo zlib1g-dev)  # figures (--plot; optional) and their test
packages+=(libnlopt-cxx-dev)  # NLopt: the global capture search (optimize/global.hpp)
packages+=(coinor-libipopt-dev)  # IPOPT: the time-optimal post-capture planner (control/detumble_planner.hpp; optional)
packages+=(libfcl-dev)  # FCL: distances between the robot, the bus and the target (geometry/distance.hpp; optional)
packages+=(chromium)  # the 3-D view's tests (python/tests/test_view.py): headless, WebGL through SwiftShader
packages+=(ccache)  # .ci/run: compiles cached between runs on one machine
packages+=(debootstrap)  # the wheel's check in a minimal Debian 12 root (scripts/check-wheel.sh)
# the onboard core on the flight targets (scripts/onboard.sh, docs/onboard.md): the cross compilers, their
# emulators, and the core's static analysis
packages+=(g++-12-aarch64-linux-gnu qemu-user gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib
           libnewlib-arm-none-eabi qemu-system-arm clang-tidy-14 cppcheck)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "ffsr: installing missing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
