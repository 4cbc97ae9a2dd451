// The GPU's dispatches and host waits a step of the shipped coupled cavity
// (scenes/coupled/cavity_gray_scott.toml: fluid 128^2, chemicals 256^2, 20
// steps, no frame after the first), against their budget: a change that adds
// a dispatch or a wait to the step shows here. `bench coupling --backend gpu`
// reports it after its cases.
#pragma once

#include <string>

namespace morphoflow {

// At most this many a step (measured 226.5 and 1.75 on Mesa's llvmpipe and on
// NVIDIA: the counts do not depend on the driver).
inline constexpr double kDispatchBudget = 230.0, kHostWaitBudget = 1.8;

// Runs the scene on the GPU, prints the counts against the budget, and adds
// them to the suite's JSON array in `json` (if given) as the case
// "dispatch budget". Returns the run's exit status.
int reportDispatchBudget(const std::string& sceneDir, const std::string& json);

}  // namespace morphoflow
