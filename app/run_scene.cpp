// `morphoflow run`: a scene file to its Simulation, through the run driver.
#include <memory>

#include "app/coupled_simulation.h"
#include "app/fluid_simulation.h"
#include "app/given_flow_simulation.h"
#include "app/gpu_simulation.h"
#include "app/memory_estimate.h"
#include "app/rd_simulation.h"
#include "app/run_driver.h"
#include "app/run_log.h"
#include "app/run_options.h"
#include "core/error.h"
#include "core/parallel.h"
#include "scenes/scene_loader.h"

namespace morphoflow {

namespace {

template <int D>
std::unique_ptr<Simulation<D>> makeSimulation(const Scene& scene, const RunOptions& opt, RunLog* log) {
  auto say = [log](const std::string& line) { log->say(line); };
  auto warn = [log](const std::string& line) { log->warn(line); };
  if (opt.backend == "gpu" && !scene.hasFluid) return std::make_unique<GpuRDSimulation<D>>(scene, say);  // checkGpuRuns said it can
  if (opt.backend == "gpu" && scene.rd.enabled) return std::make_unique<CoupledSimulation<D>>(scene, CouplingBackend::Serial, warn, true);
  if (opt.backend == "gpu") return std::make_unique<FluidSimulation<D>>(scene, warn, true);
  if (scene.velocity.enabled) return std::make_unique<GivenFlowSimulation<D>>(scene);
  if (!scene.hasFluid) return std::make_unique<RDSimulation<D>>(scene, say);
  if (scene.rd.enabled)
    return std::make_unique<CoupledSimulation<D>>(
        scene, opt.backend == "serial" ? CouplingBackend::Serial : CouplingBackend::TBB, warn);
  return std::make_unique<FluidSimulation<D>>(scene, warn);
}

template <int D>
int run(const Scene& scene, const RunOptions& opt) {
  RunLog log(opt.quiet, stderrIsTerminal());
  std::unique_ptr<Simulation<D>> sim = makeSimulation<D>(scene, opt, &log);
  return driveRun<D>(*sim, scene, opt, &log);
}

}  // namespace

int runScene(const RunOptions& opt) {
  Scene scene = loadScene(opt.scene, opt.overrides);
  if (opt.backend == "gpu") checkGpuRuns(scene);
  checkRunFits(scene);
  ThreadLimit limit(opt.backend == "serial" ? 1 : opt.threads);
  return scene.dimension == 2 ? run<2>(scene, opt) : run<3>(scene, opt);
}

}  // namespace morphoflow
