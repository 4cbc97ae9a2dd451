#!/usr/bin/env bash
# Opt-in (ctest -L blender): the shipped 3D patterned plume at half its size,
# its last frame rendered by Debian's Blender through `morphoflow blender`,
# reads as a patterned element (docs/vfx.md, "Legibility"): median plume
# luminance at least 0.25, band-passed contrast at least 0.12 and twice that
# of the same scene with the reaction off (coupling.mode = "passive").
# usage: blender_legibility_test.sh MORPHOFLOW_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
BIN=$1 SRC=$2 WORK=$3
command -v blender >/dev/null || { echo "blender_legibility_test: blender is not installed (apt install blender)"; exit 1; }
rm -rf "$WORK"; mkdir -p "$WORK"
measure() {  # mode -> "median band" of its last frame's render
  "$BIN" run "$SRC/scenes/vfx/plume_gray_scott_3d.toml" --set 'grid.resolution=[48,80,48]' \
    --set 'rd.resolution=[96,160,96]' --set output.every=140 --set output.images=false \
    --set "coupling.mode=\"$1\"" --quiet --out "$WORK/$1"
  "$BIN" blender "$WORK/$1" > /dev/null
  blender -b --factory-startup --python "$WORK/$1/blender_scene.py" -- --render --frame last --resolution 512 \
    --samples 16 --output "$WORK/$1/render_" > "$WORK/$1/blender.log" 2>&1 || { cat "$WORK/$1/blender.log"; exit 1; }
  "$BIN" analyze --legibility "$WORK/$1/render_0003.png" | tee "$WORK/$1/legibility.txt" >&2
  awk '/median_luminance/ {m = $2} /band_contrast/ {b = $2} END {print m, b}' "$WORK/$1/legibility.txt"
}
read -r median band < <(measure ard)
read -r _ passive < <(measure passive)
echo "blender_legibility_test: median luminance $median, band contrast $band, passive $passive"
awk -v m="$median" -v b="$band" -v p="$passive" 'BEGIN {exit !(m >= 0.25 && b >= 0.12 && b >= 2 * p)}'
