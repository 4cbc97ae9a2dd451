#include "app/run_report.h"

#include <iostream>

#include "app/version.h"
#include "core/parallel.h"

namespace morphoflow {

double finishRun(const Scene& scene, const RunOptions& opt, FrameWriter* frames,
                 std::chrono::steady_clock::time_point wall0) {
  if (!opt.quiet) std::cerr << "\n";
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  frames->finishVideo(scene.name);
  return wall;
}

nlohmann::json runReport(const Scene& scene, const RunOptions& opt, nlohmann::json resolved, long steps, double time,
                         const FrameWriter& frames, double wallSeconds) {
  nlohmann::json j;
  j["version"] = kVersion;
  j["scene_file"] = scene.path;
  j["scene"] = nlohmann::json::parse(scene.resolvedJson);
  j["overrides"] = opt.overrides;
  j["resolved"] = std::move(resolved);
  j["backend"] = opt.backend;
  j["threads"] = opt.threads > 0 ? opt.threads : hardwareThreads();
  j["steps"] = steps;
  j["time"] = time;
  j["frames_written"] = frames.written();
  j["fields_written"] = frames.fieldsWritten();
  j["wall_seconds"] = wallSeconds;
  if (const VideoResult* v = frames.video())
    j["video"] = {{"file", frames.videoFile().string()},
                  {"written", v->written},
                  {"warning", v->warning},
                  {"ffmpeg_log", v->log.string()}};
  return j;
}

}  // namespace morphoflow
