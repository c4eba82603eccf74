#!/usr/bin/env bash
# Regenerates docs/figures/capture_view.png, the README's picture of the 3-D view (ffsr.view): the
# 7-DOF robot capturing in the grasp orientation that needs a reconfiguration, with shapes (the links'
# capsules, the URDF's bus box, the target's 0.5 m cube), the global run at t = 130 s of 157 s (the
# reconfiguration's path in orange; the approach's, in green, lies behind the target from this view). Needs a built ffsr-optimize (default
# build/src/cli/ffsr-optimize; or pass its path), the installed package (scripts/install-python.sh:
# its build brings three.js; or set FFSR_PYTHON) and Debian's chromium (headless, WebGL through SwiftShader).
#   scripts/capture_view_figure.sh [path/to/ffsr-optimize]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cli="${1:-$root/build/src/cli/ffsr-optimize}"
python="${FFSR_PYTHON:-$root/build-python/venv/bin/python}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

"$cli" --config "$root/robots/paper_7dof_grasp.toml" --target-shape box --target-size 0.5,0.5,0.5 \
  --link-radius 0.06 --quiet --json "$tmp/result.json" --csv "$tmp/series.csv"
"$python" -m ffsr.view "$tmp/result.json" \
  --csv "$tmp/series.csv" -o "$tmp/capture.html"
flags=(--headless --use-angle=swiftshader --enable-unsafe-swiftshader --no-first-run --disable-background-networking
       --disable-component-update --disable-sync --hide-scrollbars "--user-data-dir=$tmp/profile")
[ "$(id -u)" -ne 0 ] || flags+=(--no-sandbox --disable-gpu-sandbox)
timeout 300 chromium "${flags[@]}" --virtual-time-budget=8000 --window-size=1280,760 --screenshot="$tmp/capture_view.png" \
  "file://$tmp/capture.html#t=130" 2> /dev/null
cp "$tmp/capture_view.png" "$root/docs/figures/capture_view.png"
ls -l "$root/docs/figures/capture_view.png"
