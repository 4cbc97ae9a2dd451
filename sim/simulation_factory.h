// The one place that chooses a scene's Simulation, from the scene; the
// backend's steppers, and whether the scene runs there at all
// (checkBackend), are sim/steppers.h's.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "sim/simulation.h"
#include "scenes/scene.h"
#include "core/backend.h"
#include "sim/steppers.h"
#include "sim/timeline_simulation.h"

namespace morphoflow {

// The scene's simulation on the backend (checkBackend said it can): say
// takes the simulations' messages, warn their warnings. A scene with a
// timeline (scenes/timeline.h) runs in a TimelineSimulation.
template <int D>
std::unique_ptr<Simulation<D>> makeSimulation(const Scene& scene, Backend backend,
                                              const std::function<void(const std::string&)>& say,
                                              const std::function<void(const std::string&)>& warn);

// Always a TimelineSimulation (the studio extends its timeline as it runs).
template <int D>
std::unique_ptr<TimelineSimulation<D>> makeTimelineSimulation(const Scene& scene, Backend backend,
                                                              const std::function<void(const std::string&)>& say,
                                                              const std::function<void(const std::string&)>& warn);

}  // namespace morphoflow
