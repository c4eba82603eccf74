#!/usr/bin/env bash
# Regenerates the figure gallery (docs/results.md), docs/figures/*.png, from the shipped scenarios with a built
# ffsr-optimize (default build/src/cli/ffsr-optimize; or pass its path). Needs a build with plotting.
#   scripts/figures.sh [path/to/ffsr-optimize]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cli="${1:-$root/build/src/cli/ffsr-optimize}"
out="$root/docs/figures"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out" "$tmp/3dof" "$tmp/7dof" "$tmp/contact" "$tmp/xi" "$tmp/map" "$tmp/robust" "$tmp/pareto" "$tmp/detumble"

# Figures 10 and 11: the 3-DOF robot, plain and optimized (Table 4)
"$cli" --config "$root/robots/paper_3dof.toml" --plot "$tmp/3dof" --quiet > /dev/null
# Figures 13 and 15: the 7-DOF robot, plain (pose) and optimized on the position only (Table 7)
"$cli" --config "$root/robots/paper_7dof_position.toml" --plot "$tmp/7dof" --quiet > /dev/null
# Figure 3: M_ie = 1 kg is not a robot's; the paper's loop uses c_r = 0.5 and Gonthier's law. Here
# the 3-DOF robot at [0, 90, -90] deg (M_ie 5.8 kg) with the same law and restitution.
"$cli" contact --urdf "$root/robots/paper_3dof.urdf" --joints-deg=0,90,-90 --model gonthier --restitution 0.5 \
  --plot "$tmp/contact" > /dev/null
# Figures 4-6
"$cli" xi --plot "$tmp/xi" --csv "$tmp/xi/xi.csv"

cp "$tmp/3dof/capture_plain.png" "$out/3dof_capture_plain.png"
cp "$tmp/3dof/capture_optimized.png" "$out/3dof_capture_optimized.png"
cp "$tmp/3dof/capture_global.png" "$out/3dof_capture_global.png"
cp "$tmp/3dof/histories.png" "$out/3dof_histories.png"
cp "$tmp/7dof/capture_plain.png" "$out/7dof_capture_plain.png"
cp "$tmp/7dof/capture_optimized.png" "$out/7dof_capture_optimized.png"
cp "$tmp/7dof/capture_global.png" "$out/7dof_capture_global.png"
cp "$tmp/7dof/histories.png" "$out/7dof_histories.png"
cp "$tmp/contact/contact.png" "$out/contact_gonthier.png"
cp "$tmp/xi/xi_stiffness.png" "$tmp/xi/xi_approach_speed.png" "$tmp/xi/xi_restitution.png" "$out/"
# Figures 8 and 9: M_ie of the 3-DOF robot over the paper's ranges (2 deg grid, 1.3 million points),
# the slices through theta = 0 and the grid in 3-D
"$cli" map --urdf "$root/robots/paper_3dof.urdf" --joints-deg 0,0,0 --vary 1,2,3 \
  --range-deg=-90,90,-120,120,-120,120 --step-deg 2 --csv "$tmp/map/map.csv" --plot "$tmp/map" --quiet > /dev/null
cp "$tmp/map/map_slices.png" "$out/3dof_map_slices.png"
cp "$tmp/map/map_cloud.png" "$out/3dof_map_cloud.png"
# beyond the paper: F_max over the uncertain target of the example (1000 samples, exact model)
"$cli" robust --config "$root/robots/paper_7dof_position_uncertain.toml" --plot "$tmp/robust" --quiet > /dev/null
cp "$tmp/robust/robust.png" "$out/7dof_robust.png"
# beyond the paper: M_ie against the base's angular rate jump at the impact, the three runs marked
"$cli" pareto --config "$root/robots/paper_7dof_position.toml" --plot "$tmp/pareto" > /dev/null
cp "$tmp/pareto/pareto.png" "$out/7dof_pareto.png"
# beyond the paper: the post-capture runs after the three captures (docs/detumble.md), half a second of
# the hold after rest drawn
"$cli" detumble --config "$root/robots/paper_7dof_detumble.toml" --run all --detumble-dwell 0.5 --plot "$tmp/detumble" \
  --quiet > /dev/null
cp "$tmp/detumble/detumble.png" "$out/7dof_detumble.png"
ls -l "$out"
