#include "sim/simulation_factory.h"

#include <stdexcept>

#include "sim/coupled_simulation.h"
#include "sim/fluid_simulation.h"
#include "sim/given_flow_simulation.h"
#include "sim/rd_simulation.h"

namespace morphoflow {

template <int D>
std::unique_ptr<Simulation<D>> makeSimulation(const Scene& scene, Backend backend,
                                              const std::function<void(const std::string&)>& say,
                                              const std::function<void(const std::string&)>& warn) {
  if (scene.velocity.enabled) return std::make_unique<GivenFlowSimulation<D>>(scene);
  if (!scene.hasFluid) return std::make_unique<RDSimulation<D>>(scene, backend, say);
  if (scene.rd.enabled) return std::make_unique<CoupledSimulation<D>>(scene, backend, warn);
  return std::make_unique<FluidSimulation<D>>(scene, backend, warn);
}

template std::unique_ptr<Simulation<2>> makeSimulation<2>(const Scene&, Backend, const std::function<void(const std::string&)>&,
                                                          const std::function<void(const std::string&)>&);
template std::unique_ptr<Simulation<3>> makeSimulation<3>(const Scene&, Backend, const std::function<void(const std::string&)>&,
                                                          const std::function<void(const std::string&)>&);

}  // namespace morphoflow
