// `morphoflow run` for reaction-diffusion-only scenes (no [fluid]).
#pragma once

#include "app/run_options.h"
#include "scenes/scene.h"

namespace morphoflow {

int runReactionDiffusion(const Scene& scene, const RunOptions& options);

}  // namespace morphoflow
