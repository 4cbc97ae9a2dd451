#!/usr/bin/env bash
# Opt-in (ctest -L blender): a small 3D coupled scene's VDB sequence set up
# by `morphoflow blender` and rendered by Debian's Blender (background mode,
# Cycles, CPU) through the script's own options: one frame (--frame), at a
# width (--resolution), to Blender's output path (--output PREFIX####.png);
# the picture must show the volume, not an empty background.
# usage: blender_test.sh MORPHOFLOW_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
BIN=$1 SRC=$2 WORK=$3
command -v blender >/dev/null || { echo "blender_test: blender is not installed (apt install blender)"; exit 1; }
rm -rf "$WORK"; mkdir -p "$WORK"
"$BIN" run "$SRC/scenes/coupled/cavity_gray_scott_3d.toml" --set 'grid.resolution=[24,24,24]' \
  --set 'rd.resolution=[48,48,48]' --set time.steps=60 --set output.every=20 --set output.video=false \
  --set output.images=false --quiet --out "$WORK/run"
"$BIN" blender "$WORK/run"
blender -b --factory-startup --python "$WORK/run/blender_scene.py" -- --render --frame 3 --resolution 160 \
  --samples 8 --output "$WORK/picture_" > "$WORK/blender.log" 2>&1 || { cat "$WORK/blender.log"; exit 1; }
test -f "$WORK/picture_0003.png" || { echo "blender_test: no $WORK/picture_0003.png"; cat "$WORK/blender.log"; exit 1; }
/usr/bin/python3 - "$WORK/picture_0003.png" <<'PY'
import sys
import numpy as np
import OpenImageIO as oiio
img = oiio.ImageInput.open(sys.argv[1])
px = img.read_image("float")[:, :, :3]
width = img.spec().width
img.close()
background = px[0, 0]  # a corner: the backdrop
lit = np.abs(px - background).sum(axis=2) > 0.1
print(f"blender_test: {width} pixels wide, {lit.mean():.1%} of the pixels show the volume, std {px.std():.3f}")
sys.exit(0 if width == 160 and lit.mean() > 0.05 and px.std() > 0.03 else 1)
PY
