// The data a scene names beyond its text, read and checked before a run
// starts (the scene reader records the files; it reads no volume data).
#pragma once

#include "scenes/scene.h"

namespace morphoflow {

// Reads a [velocity] sequence's first frame and resamples it onto the
// scene's grid, so that a missing grid or another domain stops `validate`
// or a batch's preparation rather than the run. Throws UserError at
// velocity.vdb, naming the file.
void checkSceneInputs(const Scene& scene);

}  // namespace morphoflow
