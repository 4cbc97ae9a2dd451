#!/usr/bin/env bash
# Opt-in (ctest -L blender): a patterned 3D plume's VDB frame rendered by
# Debian's Blender with a Principled Volume at its defaults but for the
# Color Attribute ("color"), Cycles on the CPU. The picture must be an
# element: mostly the world background, and the plume's pixels in the run's
# palette, varying with the pattern (not one flat colour).
# usage: blender_smoke_test.sh MORPHOFLOW_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
BIN=$1 SRC=$2 WORK=$3
command -v blender >/dev/null || { echo "blender_smoke_test: blender is not installed (apt install blender)"; exit 1; }
rm -rf "$WORK"; mkdir -p "$WORK"
"$BIN" run "$SRC/scenes/vfx/plume_gray_scott_3d.toml" --set 'grid.resolution=[36,60,36]' \
  --set 'rd.resolution=[72,120,72]' --set time.duration=1.5 --set output.every=150 \
  --set output.images=false --quiet --out "$WORK/run"
blender -b --factory-startup -P "$SRC/tests/blender_render.py" -- \
  "$WORK/run/vdb/plume_gray_scott_3d.000000.vdb" 2 2 "$WORK/render.png" 240 16 element > "$WORK/blender.log" 2>&1 ||
  { cat "$WORK/blender.log"; exit 1; }
/usr/bin/python3 - "$WORK/render.png" <<'PY'
import colorsys
import sys
import numpy as np
import OpenImageIO as oiio
img = oiio.ImageInput.open(sys.argv[1])
px = img.read_image("float")[:, :, :3]
img.close()
background = px[0, 0]  # a corner: the world colour
plume = np.abs(px - background).sum(axis=2) > 0.05
share = plume.mean()
rgb = px[plume]
hsv = np.array([colorsys.rgb_to_hsv(*c) for c in np.clip(rgb, 0, 1)])
saturated = hsv[:, 1] > 0.25
hues = np.histogram(hsv[saturated, 0], bins=12, range=(0, 1))[0] if saturated.any() else np.zeros(12)
spread = rgb.std(axis=0).mean() if len(rgb) else 0.0
print(f"blender_smoke_test: plume {share:.1%} of the frame, {saturated.mean() if len(rgb) else 0:.0%} of it coloured, "
      f"colour spread {spread:.3f}, hue bins used {int((hues > 0.02 * max(1, hues.sum())).sum())}")
ok = 0.01 < share < 0.5 and saturated.mean() > 0.3 and spread > 0.02
sys.exit(0 if ok else 1)
PY
