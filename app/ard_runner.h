// `morphoflow run` for coupled scenes ([fluid] and [rd]): the stable fluid
// carrying an advection-reaction-diffusion layer (seed 001 sec. 5, 7).
#pragma once

#include "app/run_options.h"
#include "scenes/scene.h"

namespace morphoflow {

int runCoupled(const Scene& scene, const RunOptions& options);

}  // namespace morphoflow
