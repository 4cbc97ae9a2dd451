// The part of DIR/run.json every run writes: version, the scene as written
// and resolved, overrides, backend and threads, and what the run did. Each
// runner adds its own solver statistics.
#pragma once

#include <chrono>

#include <nlohmann/json.hpp>

#include "app/frame_writer.h"
#include "app/run_options.h"
#include "scenes/scene.h"

namespace morphoflow {

// The end of a run, before its report: ends the progress line, encodes the
// video (output.video) and returns the wall seconds since `wall0`.
double finishRun(const Scene& scene, const RunOptions& options, FrameWriter* frames,
                 std::chrono::steady_clock::time_point wall0);

nlohmann::json runReport(const Scene& scene, const RunOptions& options, nlohmann::json resolved, long steps,
                         double time, const FrameWriter& frames, double wallSeconds);

}  // namespace morphoflow
