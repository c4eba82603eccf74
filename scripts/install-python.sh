#!/usr/bin/env bash
# Installs the Python package ffsr (python/) into a virtual environment, build-python/venv (or the
# folder given as $1), made with Debian 12's python3: first the Debian packages it needs (python3-dev,
# python3-venv, npm and those of the C++ build, scripts/install-deps.sh), then every PyPI package pinned in
# python/pyproject.toml (build requirements, numpy, and the test extra: pytest and Pinocchio's `pin`,
# the reference of the tests and the bench; dask, nbclient and matplotlib for the studies and the
# notebooks), then the package itself, built by scikit-build-core in
# build-python/cmake-* (kept between runs: a rebuild compiles only what changed).
# Nothing is downloaded at test time: this script is the only step that reaches PyPI.
# FFSR_PYTHON_CXX_FLAGS, when set, replaces the build's optimization flags (python/pyproject.toml:
# -O2 -DNDEBUG). FFSR_PYTHON_WHEEL, when set to a wheel file (scripts/build-wheel.sh's), installs that
# wheel instead of building the package: .ci/run compiles the package once, as the wheel its users get,
# and tests that.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${1:-build-python/venv}
bash scripts/install-deps.sh
missing=()
for p in python3-dev python3-venv; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm: the package's build fetches the 3-D view's three.js from the npm registry (python/three.sha256)
command -v npm >/dev/null || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
  echo "ffsr: installing missing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
[ -x "$venv/bin/python" ] || /usr/bin/python3 -m venv "$venv"
py="$venv/bin/python"
# the pins, from the one place they are written
"$py" - python/pyproject.toml > "$venv/ffsr-requirements.txt" <<'PY'
import sys, tomllib
with open(sys.argv[1], "rb") as f:
    d = tomllib.load(f)
pins = d["build-system"]["requires"] + d["project"]["dependencies"] + d["project"]["optional-dependencies"]["test"]
bad = [p for p in pins if "==" not in p]
if bad:
    sys.exit(f"python/pyproject.toml: not pinned with ==: {bad}")
print("\n".join(dict.fromkeys(pins)))
PY
"$py" -m pip install --quiet --disable-pip-version-check -r "$venv/ffsr-requirements.txt"
# the build requirements are the pinned ones just installed (no isolated build environment)
settings=()
if [ -n "${FFSR_PYTHON_CXX_FLAGS:-}" ]; then
  settings+=("--config-settings=cmake.define.CMAKE_CXX_FLAGS_RELEASE=$FFSR_PYTHON_CXX_FLAGS")
fi
if [ -n "${FFSR_PYTHON_WHEEL:-}" ]; then  # a wheel built already (scripts/build-wheel.sh): no compile here
  "$py" -m pip install --quiet --disable-pip-version-check --no-deps --force-reinstall "$FFSR_PYTHON_WHEEL"
else
  "$py" -m pip install --quiet --disable-pip-version-check --no-build-isolation --no-deps "${settings[@]}" ./python
fi
"$py" -c 'import ffsr; print("ffsr: installed the Python package", ffsr.__version__, "in", __import__("sys").prefix)'
