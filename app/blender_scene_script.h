// The Python body of the Blender set-up that `morphoflow blender OUT_DIR`
// writes (OUT_DIR/blender_scene.py): after a header of the run's facts
// (RUN = {...}) it imports the VDB sequence, shades it with a Principled
// Volume on density, color and temperature, lights it as the lit preview is
// lit (render/lit_volume.h), frames it with the preview's camera and sets
// the frame range; with `-- --render` it renders.
#pragma once

namespace morphoflow {

extern const char* const kBlenderSceneBody;

}  // namespace morphoflow
