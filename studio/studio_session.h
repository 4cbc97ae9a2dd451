// The studio's running simulation: a scene's TimelineSimulation stepped on
// a thread of its own, steered by edits that the EditLog records at the
// time of the step they take effect at, and published as frames
// (studio/frame_encoding.h) for however many pages watch. Every call is
// safe from any thread; an edit waits for the step in flight (at most one).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "run/child_process.h"
#include "sim/timeline_simulation.h"
#include "studio/edit_log.h"

namespace morphoflow {

struct StudioOptions {
  std::string backend = "tbb";
  int threads = 0;
  std::string out = "studio";       // where Render writes the saved scene and its run
  std::string executable;           // the morphoflow executable Render starts
};

class StudioSession {
 public:
  // Throws UserError when the scene does not read or cannot run on the backend.
  StudioSession(const std::string& text, const std::string& path, const StudioOptions& options);
  ~StudioSession();
  // Stops the simulation and frees it (the GPU's context let go) now, though
  // a frame in flight may still hold the session.
  void close();
  StudioSession(const StudioSession&) = delete;
  StudioSession& operator=(const StudioSession&) = delete;

  // t, steps, running, steps/s, the field shown, the fields, steps per
  // frame, the steerable keys (value and range), the scene's obstacles and
  // sources, the render's progress, the last error.
  nlohmann::json state() const;
  // {"action": "play" | "pause" | "step" | "reset"} (step: "count", default 1).
  nlohmann::json control(const nlohmann::json& body);
  // {"key": value, ...}: all or nothing, each through the scene reader.
  nlohmann::json set(const nlohmann::json& body);
  // A paint edit (studio/edit_log.h).
  nlohmann::json paint(const nlohmann::json& edit);
  // {"field": name} and/or {"steps_per_frame": n}.
  nlohmann::json view(const nlohmann::json& body);
  // The scene file with every edit.
  std::string sceneText() const;
  // The field's values now, as a .npy file (UserError for an unknown name).
  std::string fieldNpy(const std::string& name);
  // Starts `morphoflow run` of the saved scene in the background.
  nlohmann::json render();

  // The newest frame (null before the first).
  std::shared_ptr<const std::string> frame() const;
  // Called on the simulation's thread after each new frame.
  // `wanted` says whether any client waits for a frame: while running, a
  // frame is made only then (at most 60 a second), so that watching costs
  // the simulation no more than what is shown.
  void onFrame(std::function<void()> listener, std::function<bool()> wanted = {});
  long framesPublished() const { return framesPublished_; }
  int dimension() const { return dimension_; }

 private:
  template <class R>
  R onSimThread(std::function<R()> task);
  void loop();
  void stepOnce();
  void publish();
  void build();
  template <class F>
  auto with(F&& f) const;
  nlohmann::json where() const;
  nlohmann::json adopt(EditLog&& edited);

  StudioOptions options_;
  EditLog log_;                       // on the simulation's thread (and under mutex_ when read elsewhere)
  int dimension_ = 2;
  std::unique_ptr<TimelineSimulation<2>> s2_;
  std::unique_ptr<TimelineSimulation<3>> s3_;
  std::unique_ptr<Scene> clockScene_;  // the scene the clock and palette come from

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> tasks_;
  bool running_ = false, stop_ = false, pastEnd_ = false;
  long stepsToDo_ = 0, stepsPerFrame_ = 1, sinceFrame_ = 0;
  std::string field_, error_;
  double time_ = 0.0, stepsPerSecond_ = 0.0;
  long steps_ = 0;
  std::shared_ptr<const std::string> frame_;
  std::function<void()> listener_;
  std::function<bool()> wanted_;
  std::chrono::steady_clock::time_point lastFrame_{}, lastCheck_{};
  std::atomic<long> framesPublished_{0};
  double frameSeconds_ = 0.0;  // the simulation thread's time making frames (under mutex_)
  std::optional<ChildProcess> render_;
  std::string renderOut_;
  long renderFrames_ = 0;
  std::thread thread_;
};

}  // namespace morphoflow
