// How much memory a run will need, from the grids its scene creates, before
// any is allocated: a run that would not fit is refused (exit 2) with the
// estimate and what the machine has available; `validate` prints it.
#pragma once

#include <cstdint>
#include <string>

#include "core/system_memory.h"
#include "scenes/scene.h"

namespace morphoflow {

// Peak resident bytes of a run of `scene`.
uintmax_t estimateRunBytes(const Scene& scene);
// Throws UserError (the scene file, the estimate, what is available) when
// the run would not fit.
void checkRunFits(const Scene& scene);

}  // namespace morphoflow
