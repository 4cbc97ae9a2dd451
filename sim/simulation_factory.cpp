#include "sim/simulation_factory.h"

#include <memory>
#include <set>
#include <string>

#include <stdexcept>

#include "sim/coupled_simulation.h"
#include "sim/fluid_simulation.h"
#include "sim/given_flow_simulation.h"
#include "sim/rd_simulation.h"
#include "sim/timeline_simulation.h"

namespace morphoflow {

namespace {

template <int D>
std::unique_ptr<Simulation<D>> makeFixed(const Scene& scene, Backend backend,
                                         const std::function<void(const std::string&)>& say,
                                         const std::function<void(const std::string&)>& warn) {
  if (scene.velocity.enabled) return std::make_unique<GivenFlowSimulation<D>>(scene);
  if (!scene.hasFluid) return std::make_unique<RDSimulation<D>>(scene, backend, say);
  if (scene.rd.enabled) return std::make_unique<CoupledSimulation<D>>(scene, backend, warn);
  return std::make_unique<FluidSimulation<D>>(scene, backend, warn);
}

}  // namespace

template <int D>
std::unique_ptr<TimelineSimulation<D>> makeTimelineSimulation(const Scene& scene, Backend backend,
                                                              const std::function<void(const std::string&)>& say,
                                                              const std::function<void(const std::string&)>& warn) {
  // Built again at each change: what a build says (a warning about the
  // scene) is said once, not at every rebuild.
  auto once = [seen = std::make_shared<std::set<std::string>>()](std::function<void(const std::string&)> f) {
    return [seen, f](const std::string& line) {
      if (seen->insert(line).second && f) f(line);
    };
  };
  return std::make_unique<TimelineSimulation<D>>(scene, [backend, say = once(say), warn = once(warn)](const Scene& at) {
    return makeFixed<D>(at, backend, say, warn);
  });
}

template <int D>
std::unique_ptr<Simulation<D>> makeSimulation(const Scene& scene, Backend backend,
                                              const std::function<void(const std::string&)>& say,
                                              const std::function<void(const std::string&)>& warn) {
  if (!scene.timeline.empty()) return makeTimelineSimulation<D>(scene, backend, say, warn);
  return makeFixed<D>(scene, backend, say, warn);
}

template std::unique_ptr<TimelineSimulation<2>> makeTimelineSimulation<2>(
    const Scene&, Backend, const std::function<void(const std::string&)>&,
    const std::function<void(const std::string&)>&);
template std::unique_ptr<TimelineSimulation<3>> makeTimelineSimulation<3>(
    const Scene&, Backend, const std::function<void(const std::string&)>&,
    const std::function<void(const std::string&)>&);
template std::unique_ptr<Simulation<2>> makeSimulation<2>(const Scene&, Backend,
                                                          const std::function<void(const std::string&)>&,
                                                          const std::function<void(const std::string&)>&);
template std::unique_ptr<Simulation<3>> makeSimulation<3>(const Scene&, Backend,
                                                          const std::function<void(const std::string&)>&,
                                                          const std::function<void(const std::string&)>&);

}  // namespace morphoflow
