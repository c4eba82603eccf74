#!/usr/bin/env bash
# Checks the wheel of scripts/build-wheel.sh on a machine without compilers: in a minimal Debian 12 root
# (debootstrap --variant=minbase, python3 and python3-venv only), offline (a network namespace without
# interfaces, pip --no-index), a venv gets the wheel and numpy from a folder, imports ffsr and runs the
# README's Python example. Needs root (chroot). The root is cached as build-wheel/bookworm-minbase.tar;
# `check-wheel.sh --root-only` only makes that cache (CI makes it in the background while it compiles).
set -euo pipefail
cd "$(dirname "$0")/.."
out=build-wheel
[ "$(id -u)" -eq 0 ] || { echo "check-wheel.sh: needs root (debootstrap, chroot)" >&2; exit 1; }
root_only=0
[ "${1:-}" = "--root-only" ] && root_only=1
mkdir -p "$out"
command -v debootstrap >/dev/null || {
  apt-get update -qq &&
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap; }
start=$SECONDS

# --- the Debian 12 root, from the mirror apt uses here (or FFSR_DEBIAN_MIRROR), cached as a tarball --
mirror=${FFSR_DEBIAN_MIRROR:-$(/usr/bin/python3 - <<'PY'
import glob, re
# the first source of the suite bookworm (one-line .list or deb822 .sources)
for path in sorted(glob.glob("/etc/apt/sources.list") + glob.glob("/etc/apt/sources.list.d/*")):
    text = open(path, encoding="utf-8").read()
    for stanza in re.split(r"\n\s*\n", text):
        uris = re.findall(r"^URIs:\s*(.+)$", stanza, re.M)
        suites = re.findall(r"^Suites:\s*(.+)$", stanza, re.M)
        if uris and suites and "bookworm" in suites[0].split():
            print(uris[0].split()[0]); raise SystemExit
    for line in text.splitlines():
        f = line.split()
        if len(f) >= 3 and f[0] == "deb" and "bookworm" in f[2:3]:
            print(f[1]); raise SystemExit
PY
)}
[ -n "$mirror" ] || { echo "check-wheel.sh: no Debian bookworm mirror in /etc/apt/sources.list*" \
                           "(set FFSR_DEBIAN_MIRROR)" >&2; exit 1; }
cache=$out/bookworm-minbase.tar
key="bookworm minbase python3,python3-venv $mirror"
if [ ! -f "$cache" ] || [ "$(cat "$cache.key" 2>/dev/null)" != "$key" ]; then
  rm -rf "$out/debootstrap" "$cache" "$cache.key"
  t0=$SECONDS
  debootstrap --variant=minbase --include=python3,python3-venv bookworm "$out/debootstrap" "$mirror" \
    > "$out/debootstrap.log" 2>&1 ||
    { tail -20 "$out/debootstrap.log"; echo "check-wheel.sh: debootstrap failed" >&2; exit 1; }
  echo "check-wheel.sh: debootstrap: $((SECONDS - t0)) s, $(du -sh "$out/debootstrap" | cut -f1)"
  tar -C "$out/debootstrap" -cf "$cache" .
  echo "$key" > "$cache.key"
  rm -rf "$out/debootstrap"
fi
[ "$root_only" -eq 0 ] || exit 0
wheels=("$out"/wheelhouse/ffsr-*.whl)
[ ${#wheels[@]} -eq 1 ] && [ -f "${wheels[0]}" ] ||
  { echo "check-wheel.sh: not one wheel in $out/wheelhouse: run scripts/build-wheel.sh first" >&2; exit 1; }
wheel=${wheels[0]}
py="$out/venv/bin/python"   # build-wheel.sh's venv (the host side: pip download)
root=$out/root
cleanup() {
  mountpoint -q "$root/proc" && umount "$root/proc"
  rm -rf "$root"
}
trap cleanup EXIT
cleanup
mkdir -p "$root"
tar -C "$root" -xf "$cache"

# nothing to compile with, no headers
if chroot "$root" /bin/sh -c 'for c in cc c++ gcc g++ clang; do command -v $c; done' | grep .; then
  echo "check-wheel.sh: the root has a compiler" >&2; exit 1
fi
dev=$(chroot "$root" dpkg-query -W -f '${Package}\n' | grep -E -- '-dev(:|$)' || true)
[ -z "$dev" ] || { echo "check-wheel.sh: the root has -dev packages: $dev" >&2; exit 1; }

# --- what goes in: the wheels (downloaded here, on the host), the README's example, the robots --------
work=$root/opt/ffsr-check
mkdir -p "$work/wheels"
cp "$wheel" "$work/wheels/"
numpy=$("$py" -c 'import sys, tomllib
print(*tomllib.load(open(sys.argv[1], "rb"))["project"]["dependencies"])' python/pyproject.toml)
"$py" -m pip download --quiet --disable-pip-version-check --only-binary=:all: --no-deps \
  -d "$work/wheels" $numpy
cp -r robots "$work/robots"
# the README's example (the first python block of its section "Python") and the numbers the README
# gives for it (the parenthesis after the block)
"$py" - README.md "$work/example.py" "$work/expected.txt" <<'PY'
import re, sys
text = open(sys.argv[1], encoding="utf-8").read()
section = text.split("\n## Python\n", 1)[1].split("\n## ", 1)[0]
m = re.search(r"```python\n(.*?)```\n(.*?)(?:\n\n|\Z)", section, re.S)
if not m:
    sys.exit("README.md: no python block in the section Python")
numbers = re.findall(r"\d+\.\d+ (?:kg|kN|%)", m.group(2))
if len(numbers) != 6:
    sys.exit(f"README.md: expected six numbers after the example, found {numbers}")
open(sys.argv[2], "w").write(m.group(1))
open(sys.argv[3], "w").write("\n".join(numbers) + "\n")
PY

# --- inside: a venv, the wheels from the folder only, no network namespace --------------------------
mount -t proc proc "$root/proc"
t0=$SECONDS
unshare --net chroot "$root" /usr/bin/env -i PATH=/usr/bin:/bin HOME=/root LANG=C.UTF-8 /bin/sh -ec '
  cd /opt/ffsr-check
  python3 -m venv venv
  venv/bin/pip install --quiet --disable-pip-version-check --no-index --find-links wheels ffsr
  venv/bin/python -c "
import ffsr, ffsr._ffsr, ffsr.view as v
print(\"import ffsr:\", ffsr.__version__, ffsr._ffsr.__file__)
print(\"three.js in the package:\", sum(len(v._asset(\"three/\" + f)) for f in v.THREE_FILES), \"bytes\")
import glob, os, sys
site = os.path.dirname(os.path.dirname(ffsr.__file__))
libs = sorted(os.path.basename(p) for p in glob.glob(os.path.join(site, \"ffsr.libs\", \"*.so*\")))
lic = glob.glob(os.path.join(site, \"ffsr-*.dist-info\", \"licenses\"))
index = open(os.path.join(lic[0], \"bundled-libraries.txt\")).read() if lic else \"\"
named = [l.split(\": \")[0][len(\"ffsr.libs/\"):] for l in index.splitlines() if l.startswith(\"ffsr.libs/\")]
texts = [l.rsplit(\", \", 1)[1] for l in index.splitlines() if l.startswith(\"ffsr.libs/\")]
if not libs or sorted(named) != libs or not os.path.isfile(os.path.join(lic[0], \"LICENSE\")) or not all(
        os.path.getsize(os.path.join(os.path.dirname(lic[0]), t)) > 0 for t in texts):
    sys.exit(\"the licence texts: bundled-libraries.txt names %s, ffsr.libs holds %s\" % (named, libs))
print(\"licence texts:\", len(libs), \"bundled libraries,\", len(set(texts)), \"copyright files and ffsr LICENSE\")"
  venv/bin/python example.py > example.out
  cat example.out
' || { echo "check-wheel.sh: the wheel failed in the Debian 12 root" >&2; exit 1; }
printed=$(grep -oE '[0-9]+\.[0-9]+ (kg|kN|%)' "$work/example.out" || true)
missing=$(grep -vxF -f <(echo "$printed") "$work/expected.txt" || true)
[ -z "$missing" ] || { echo "check-wheel.sh: the example did not print the README's" $missing >&2; exit 1; }
echo "check-wheel.sh: $(basename "$wheel") ($(du -k "$wheel" | cut -f1) KiB) installed and ran the README's" \
     "example in a Debian 12 root without compilers, offline: $((SECONDS - t0)) s inside," \
     "$((SECONDS - start)) s in all"
