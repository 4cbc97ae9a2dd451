// `morphoflow run`: a scene file to its Simulation (sim/simulation_factory.h),
// through the run driver.
#include <algorithm>
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "core/error.h"
#include "core/parallel.h"
#include "run/folder_lock.h"
#include "run/memory_estimate.h"
#include "run/run_driver.h"
#include "run/run_log.h"
#include "run/run_options.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"

namespace morphoflow {

namespace {

template <int D>
int run(const Scene& scene, const RunOptions& opt, Backend backend) {
  RunLog log(opt.quiet, stderrIsTerminal());
  std::unique_ptr<Simulation<D>> sim = makeSimulation<D>(
      scene, backend, [&log](const std::string& line) { log.say(line); },
      [&log](const std::string& line) { log.warn(line); });
  return driveRun<D>(*sim, scene, opt, &log);
}

// Refuses --frames A:B whose A lies beyond the run's last frame (a run
// whose steps are known: no CFL limit), which would write nothing.
void checkFrames(const Scene& scene, const RunOptions& opt) {
  if (scene.time.cfl > 0 || opt.firstFrame == 0) return;
  const long last = scene.totalSteps() / scene.output.every;
  if (opt.firstFrame > last)
    throw UserError({"--frames", 0, 0}, "",
                    fmt::format("frame {} is beyond the run's last frame, {} ({} steps, a frame every {})",
                                opt.firstFrame, last, scene.totalSteps(), scene.output.every),
                    fmt::format("give --frames A:B with A <= {}", last));
}

// Refuses a scene that reads a file inside the output folder: the run would
// delete it (an earlier run's outputs go first) or write over it.
void checkInputsOutside(const Scene& scene, const std::string& out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path folder = fs::weakly_canonical(fs::absolute(out, ec), ec);
  if (ec) return;
  for (const SceneInput& in : scene.inputs) {
    const fs::path file = fs::weakly_canonical(fs::absolute(in.path, ec), ec);
    if (ec) continue;
    const auto [f, o] = std::mismatch(file.begin(), file.end(), folder.begin(), folder.end());
    if (o == folder.end())
      throw UserError(in.where, in.key,
                      "the scene reads " + in.path + ", which lies inside the output folder " + out +
                          ": the run would delete or overwrite it",
                      "move the file out of the output folder, or give another --out");
  }
}

}  // namespace

int runScene(const RunOptions& opt) {
  stopWithBatchParent();
  const Backend backend = backendNamed(opt.backend);
  Scene scene = loadScene(opt.scene, opt.overrides);
  checkFrames(scene, opt);
  checkInputsOutside(scene, opt.out);
  checkBackend(scene, backend);
  checkRunFits(scene);
  ThreadLimit limit(backend == Backend::Serial ? 1 : opt.threads);
  return scene.dimension == 2 ? run<2>(scene, opt, backend) : run<3>(scene, opt, backend);
}

}  // namespace morphoflow
