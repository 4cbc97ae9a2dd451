// The one place that chooses a scene's Simulation: from the scene and the
// backend, and (for the GPU) whether the scene can run there at all.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "core/simulation.h"
#include "scenes/scene.h"

namespace morphoflow {

// --backend: TBB tasks, one thread (the coupled step's serial schedule), or
// OpenGL compute.
enum class Backend { TBB, Serial, Gpu };
// "tbb", "serial" or "gpu"; std::invalid_argument for any other name.
Backend backendNamed(const std::string& name);

// Throws UserError when the scene cannot run on the backend (the GPU: a
// stage it has no program for, named; no OpenGL 4.3 context; too little
// device memory). Nothing is allocated before this says yes.
void checkBackend(const Scene& scene, Backend backend);

// The scene's simulation on the backend (checkBackend said it can): say
// takes the simulations' messages, warn their warnings.
template <int D>
std::unique_ptr<Simulation<D>> makeSimulation(const Scene& scene, Backend backend,
                                              const std::function<void(const std::string&)>& say,
                                              const std::function<void(const std::string&)>& warn);

}  // namespace morphoflow
