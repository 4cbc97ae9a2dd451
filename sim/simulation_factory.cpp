#include "sim/simulation_factory.h"

#include <stdexcept>

#include "sim/coupled_simulation.h"
#include "sim/fluid_simulation.h"
#include "sim/given_flow_simulation.h"
#include "sim/gpu_simulation.h"
#include "sim/rd_simulation.h"

namespace morphoflow {

Backend backendNamed(const std::string& name) {
  if (name == "tbb") return Backend::TBB;
  if (name == "serial") return Backend::Serial;
  if (name == "gpu") return Backend::Gpu;
  throw std::invalid_argument("no backend '" + name + "'");
}

void checkBackend(const Scene& scene, Backend backend) {
  if (backend == Backend::Gpu) checkGpuRuns(scene);
}

template <int D>
std::unique_ptr<Simulation<D>> makeSimulation(const Scene& scene, Backend backend,
                                              const std::function<void(const std::string&)>& say,
                                              const std::function<void(const std::string&)>& warn) {
  if (backend == Backend::Gpu) {
    if (!scene.hasFluid) return std::make_unique<GpuRDSimulation<D>>(scene, say);
    if (scene.rd.enabled) return std::make_unique<CoupledSimulation<D>>(scene, CouplingBackend::Serial, warn, true);
    return std::make_unique<FluidSimulation<D>>(scene, warn, true);
  }
  if (scene.velocity.enabled) return std::make_unique<GivenFlowSimulation<D>>(scene);
  if (!scene.hasFluid) return std::make_unique<RDSimulation<D>>(scene, say);
  if (scene.rd.enabled)
    return std::make_unique<CoupledSimulation<D>>(scene, backend == Backend::Serial ? CouplingBackend::Serial : CouplingBackend::TBB,
                                                  warn);
  return std::make_unique<FluidSimulation<D>>(scene, warn);
}

template std::unique_ptr<Simulation<2>> makeSimulation<2>(const Scene&, Backend, const std::function<void(const std::string&)>&,
                                                          const std::function<void(const std::string&)>&);
template std::unique_ptr<Simulation<3>> makeSimulation<3>(const Scene&, Backend, const std::function<void(const std::string&)>&,
                                                          const std::function<void(const std::string&)>&);

}  // namespace morphoflow
