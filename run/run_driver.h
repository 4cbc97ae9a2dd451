// The run driver: the one loop every scene runs through, whatever its
// Simulation (fluid-only, reaction-diffusion-only, coupled; any backend). It
// owns the frame schedule, every output sink, progress, the measurement files
// and run.json.
#pragma once

#include "run/run_options.h"
#include "sim/simulation.h"
#include "scenes/scene.h"

namespace morphoflow {

class RunLog;

// Steps `sim` to the end of the scene, feeding every frame to the scene's
// sinks; returns the process exit status.
template <int D>
int driveRun(Simulation<D>& sim, const Scene& scene, const RunOptions& options, RunLog* log);

}  // namespace morphoflow
