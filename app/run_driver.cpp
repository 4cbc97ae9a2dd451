#include "app/run_driver.h"

#include <chrono>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/frame_schedule.h"
#include "app/output_files.h"
#include "app/output_sinks.h"
#include "app/run_clock.h"
#include "app/run_log.h"
#include "app/version.h"
#include "core/parallel.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

// How the run is clocked: a reaction-diffusion-only scene takes whole steps
// of time.dt (duration / dt of them); a fluid may adapt dt and clip the last.
TimeSettings runTime(const Scene& scene) {
  TimeSettings t = scene.time;
  if (!scene.hasFluid) {
    t.steps = scene.totalSteps();
    t.cfl = 0.0;
  }
  return t;
}

template <int D>
nlohmann::json runReport(const Scene& scene, const RunOptions& opt, const Simulation<D>& sim,
                         const std::vector<std::unique_ptr<OutputSink<D>>>& sinks, double wallSeconds) {
  nlohmann::json j;
  j["version"] = kVersion;
  j["scene_file"] = scene.path;
  j["scene"] = nlohmann::json::parse(scene.resolvedJson);
  j["overrides"] = opt.overrides;
  j["resolved"] = sim.resolved();
  j["backend"] = opt.backend;
  j["threads"] = opt.threads > 0 ? opt.threads : hardwareThreads();
  j["steps"] = sim.steps();
  j["time"] = sim.time();
  j["frames_written"] = 0;
  j["fields_written"] = 0;
  j["wall_seconds"] = wallSeconds;
  for (const auto& s : sinks) s->report(&j);
  sim.report(&j);
  return j;
}

}  // namespace

template <int D>
int driveRun(Simulation<D>& sim, const Scene& scene, const RunOptions& opt, RunLog* log) {
  const fs::path out(opt.out);
  fs::create_directories(out);
  const FrameSchedule schedule(scene.output.every, opt);
  std::vector<std::unique_ptr<OutputSink<D>>> sinks = makeOutputSinks<D>(out, scene);
  const RunClock clock(runTime(scene));
  const long stepsEstimate = scene.hasFluid ? scene.totalSteps() : runTime(scene).steps;
  const double endTime = scene.time.steps > 0 ? 0.0 : scene.time.duration;
  const auto wall0 = std::chrono::steady_clock::now();
  long lastFrame = -1;
  auto frame = [&]() {
    const long f = schedule.frameAt(sim.steps());
    if (f < 0) return;
    sim.checkFinite(fmt::format("at step {}", sim.steps()));
    for (const auto& s : sinks) s->write(f, sim.steps(), sim);
    lastFrame = f;
  };

  frame();
  while (clock.running(sim.steps(), sim.time()) && !schedule.pastLast(sim.steps())) {
    sim.step(clock.dt(sim));
    frame();
    log->progress(lastFrame, sim.steps(), stepsEstimate, sim.time(), endTime);
  }
  sim.checkFinite(fmt::format("at step {}", sim.steps()));
  log->endProgress();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  for (const auto& s : sinks) s->finish();
  nlohmann::json j = runReport<D>(scene, opt, sim, sinks, wall);
  if (j.contains("video") && !j["video"]["written"].get<bool>())
    log->warn("warning: " + j["video"]["warning"].get<std::string>());
  for (const auto& [path, text] : sim.measurementFiles()) {
    fs::create_directories((out / path).parent_path());
    writeTextFile(out / path, text);
  }
  writeTextFile(out / "run.json", j.dump(2) + "\n");
  log->say(fmt::format("done: {} steps, t = {:.5g}, {:.2f} s wall, {} frames -> {}", sim.steps(), sim.time(), wall,
                       j["frames_written"].get<int>(), out.string()));
  writeTextFile(out / "log.txt", log->text());
  return 0;
}

template int driveRun<2>(Simulation<2>&, const Scene&, const RunOptions&, RunLog*);
template int driveRun<3>(Simulation<3>&, const Scene&, const RunOptions&, RunLog*);

}  // namespace morphoflow
