// The one place that chooses a scene's Simulation, from the scene; the
// backend's steppers, and whether the scene runs there at all
// (checkBackend), are sim/steppers.h's.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "core/simulation.h"
#include "scenes/scene.h"
#include "sim/backend.h"
#include "sim/steppers.h"

namespace morphoflow {

// The scene's simulation on the backend (checkBackend said it can): say
// takes the simulations' messages, warn their warnings.
template <int D>
std::unique_ptr<Simulation<D>> makeSimulation(const Scene& scene, Backend backend,
                                              const std::function<void(const std::string&)>& say,
                                              const std::function<void(const std::string&)>& warn);

}  // namespace morphoflow
