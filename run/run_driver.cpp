#include "run/run_driver.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/output_file.h"
#include "core/parallel.h"
#include "run/checkpoint.h"
#include "run/folder_lock.h"
#include "run/frame_schedule.h"
#include "run/memory_estimate.h"
#include "run/output_sinks.h"
#include "run/run_clock.h"
#include "run/run_folder.h"
#include "run/run_log.h"
#include "run/scene_hash.h"
#include "run/steady_state.h"
#include "run/stop_signal.h"
#include "run/version.h"
#include "sim/steppers.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

uintmax_t peakMemoryBytes() {
  struct rusage u {};
  getrusage(RUSAGE_SELF, &u);
  return uintmax_t(u.ru_maxrss) * 1024;
}

// One run of one simulation: the loop, its outputs and its records.
template <int D>
class Driver {
 public:
  Driver(Simulation<D>& sim, const Scene& scene, const RunOptions& opt, RunLog* log)
      : sim_(sim), scene_(scene), opt_(opt), log_(*log), out_(opt.out), schedule_(scene.output.every, opt),
        clock_(runTime(scene)), hash_(sceneHash(scene)) {
    if (scene.time.untilSteady > 0) steady_.emplace(scene.time.untilSteady);
  }

  int run() {
    createOutputFolder(out_);
    lock_.emplace(out_);  // before anything in the folder is removed or written
    if (opt_.resume) resume();
    else removeEarlierRun(out_, safeFileStem(scene_.name));
    sinks_ = makeOutputSinks<D>(out_, scene_, [] { return StopSignals::received() != 0; });
    if (checkpoint_) restoreSinks();
    warnOfIdleSources();
    warnOfRaisedTolerances();
    try {
      return loop();
    } catch (const NonFiniteError& e) {
      // Every frame and checkpoint written so far stays: each was checked finite.
      fail("diverged", e.what());
      throw DivergedError({scene_.path, 0, 0}, "", e.what(), e.hint());
    } catch (const std::exception& e) {
      fail("failed", e.what());
      throw;
    }
  }

 private:
  // A tolerance below what the GPU's float solves reach is raised to that floor (run.json's gpu.tolerances).
  void warnOfRaisedTolerances() {
    for (const RaisedTolerance& t : raisedTolerances(scene_, backendNamed(opt_.backend)))
      log_.warn(
          fmt::format("warning: {} = {:g} is below what the gpu's float solves reach: {:g} is used (gpu.precision "
                      "= \"double\" keeps {:g})",
                      t.key, t.asked, t.used, t.asked));
  }

  // A source whose window opens when this run has ended (a short preview
  // of a longer shot) emits nothing here: said, not refused.
  void warnOfIdleSources() {
    const double end = clock_.latestEnd();
    const std::vector<SmokeSource>& sources = scene_.fluid.smoke.sources;
    for (size_t q = 0; q < sources.size(); ++q)
      if (sources[q].start >= end)
        log_.warn(fmt::format("warning: sources.{} starts emitting at t = {:g}, when this run has ended (t = {:g}): "
                              "it emits nothing here",
                              q, sources[q].start, end));
  }

  int loop() {
    const long stepsEstimate = scene_.hasFluid ? scene_.totalSteps() : runTime(scene_).steps;
    const double endTime = scene_.time.steps > 0 ? 0.0 : scene_.time.duration;
    if (!checkpoint_) frame();
    if (steady_ && !checkpoint_) steady_->reference(sim_);
    while (clock_.running(sim_.steps(), sim_.time()) && !schedule_.pastLast(sim_.steps())) {
      if (StopSignals::received()) return stop();
      lastDt_ = clock_.dt(sim_);
      checkStepsLeft();
      sim_.advance(lastDt_, stepsNow());
      const long f = frame();
      const bool steady = f > 0 && steady_ && steady_->check(sim_);
      if (f > 0 && scene_.output.checkpointEvery > 0 && f % scene_.output.checkpointEvery == 0) saveCheckpoint();
      log_.progress(lastFrame_, sim_.steps(), stepsEstimate, sim_.time(), endTime);
      if (steady) break;
    }
    checkFinite();
    log_.endProgress();
    for (const auto& s : sinks_) s->finish();
    if (StopSignals::received()) return stop();
    for (const auto& [path, text] : sim_.measurementFiles()) {
      createOutputFolder((out_ / path).parent_path());
      writeFileAtomically(out_ / path, text);
      measurementBytes_ += text.size();
    }
    saveCheckpoint();
    const nlohmann::json j = record("completed");
    if (j.contains("video") && !j["video"]["written"].get<bool>())
      log_.warn("warning: " + j["video"]["warning"].get<std::string>());
    if (j.contains("vdb_half_warning")) log_.warn("warning: " + j["vdb_half_warning"].get<std::string>());
    if (j.contains("frames_range") && j["frames_range"]["cells_beyond"].get<uintmax_t>() > 0)
      log_.say(fmt::format(
          "frames: {:.2g}% of the shown cells lay beyond output.range [{:g}, {:g}] and were drawn at its ends",
          100.0 * j["frames_range"]["fraction_beyond"].get<double>(), scene_.output.range[0], scene_.output.range[1]));
    if (steady_) sayHowSteady();
    log_.say(fmt::format("done: {} steps, t = {:.5g}, {:.2f} s wall, {} frames -> {}", sim_.steps(), sim_.time(),
                         wallSeconds(), j["frames_written"].get<int>(), out_.string()));
    for (const auto& s : sinks_)
      for (const std::string& line : s->whereToLook()) log_.say(line);
    writeLog();
    return 0;
  }

  // The steps to take at once: as many as the simulation takes faster
  // together, up to the next step that may write a frame (frames and
  // checkpoints fall on output.every) and the run's last; one where dt may change.
  long stepsNow() const {
    const long together = sim_.stepsTogether(), step = sim_.steps();
    if (together <= 1 || !clock_.fixedDt()) return 1;
    return std::min({together, schedule_.every() - step % schedule_.every(), clock_.stepsLeft(step)});
  }

  // A CFL limit sets dt as the run goes: refused once the duration left
  // would take more steps than any run may (TimeSettings::kMaxSteps).
  void checkStepsLeft() const {
    if (scene_.time.cfl <= 0 || scene_.time.steps > 0) return;
    const double left = (scene_.time.duration - sim_.time()) / lastDt_;
    if (double(sim_.steps()) + left <= double(TimeSettings::kMaxSteps)) return;
    throw UserError(
        {scene_.path, 0, 0}, "time.cfl",
        fmt::format("at step {} (t = {:.5g}) the CFL limit {:g} gives dt = {:.3g}: the {:.3g} time units left "
                    "would take {:.3g} steps, more than {}",
                    sim_.steps(), sim_.time(), scene_.time.cfl, lastDt_, scene_.time.duration - sim_.time(), left,
                    TimeSettings::kMaxSteps),
        "raise time.cfl or shorten time.duration");
  }

  void sayHowSteady() {
    const double tol = steady_->tolerance();
    if (steady_->steady())
      log_.say(fmt::format("steady at t = {:.5g} (step {}): the velocity changes by {:.3g} per unit time, below "
                           "time.until_steady = {:g}", sim_.time(), sim_.steps(), steady_->change(), tol));
    else if (!steady_->checked())
      log_.warn(fmt::format("warning: steadiness not measured: it is measured at each frame, every {} steps "
                            "(output.every), and the run ended at step {} before the first; give output.every <= {} "
                            "to measure it (time.until_steady = {:g})",
                            schedule_.every(), sim_.steps(), std::max(1L, sim_.steps()), tol));
    else
      log_.warn(fmt::format("warning: not steady by t = {:.5g}: the velocity still changes by {:.3g} per unit time "
                            "(time.until_steady = {:g}); give a longer time.duration (or time.steps) to run on",
                            sim_.time(), steady_->change(), tol));
  }

  // run.json's until_steady: the tolerance, whether and when the run became
  // steady, the last change measured.
  nlohmann::json steadyRecord() const {
    nlohmann::json s = {{"tolerance", steady_->tolerance()}, {"steady", steady_->steady()}};
    s["relative_change_per_time"] = steady_->checked() ? nlohmann::json(steady_->change()) : nlohmann::json(nullptr);
    if (!steady_->checked())
      s["not_measured_because"] =
          fmt::format("output.every ({} steps) is longer than the run ({} steps)", schedule_.every(), sim_.steps());
    s["stopped_because"] = steady_->steady()                  ? "steady"
                           : schedule_.pastLast(sim_.steps()) ? "--frames"
                           : scene_.time.steps > 0            ? "time.steps"
                                                              : "time.duration";
    if (steady_->steady()) s["steady_at"] = {{"step", sim_.steps()}, {"time", sim_.time()}};
    return s;
  }

  void fail(const std::string& exitState, const std::string& error) {
    log_.endProgress();
    log_.keep(exitState + ": " + error);
    record(exitState, error);
    try {
      writeLog();
    } catch (const std::exception&) {  // the first error is the one to report
    }
  }

  // The finiteness check at the current step, naming the last step found finite.
  void checkFinite() {
    sim_.checkFinite(checkedStep_ < 0 ? fmt::format("at step {}", sim_.steps())
                                      : fmt::format("by step {} (finite at step {})", sim_.steps(), checkedStep_));
    checkedStep_ = sim_.steps();
  }

  // Writes the frame of the current step, if it has one; returns its number or -1.
  long frame() {
    const long f = schedule_.frameAt(sim_.steps());
    if (f < 0) return -1;
    checkFinite();
    for (const auto& s : sinks_) s->write(FrameInfo{f, sim_.steps(), lastDt_ > 0 ? lastDt_ : scene_.time.dt}, sim_);
    lastFrame_ = f;
    return f;
  }

  // SIGINT or SIGTERM: the step is done; checkpoint, say where, 128 + signal.
  int stop() {
    const int sig = StopSignals::received();
    log_.endProgress();
    const fs::path file = saveCheckpoint();
    log_.warn(fmt::format("interrupted by {} at step {} (t = {:.5g}); checkpoint {}; continue with --resume",
                          sig == SIGINT ? "SIGINT" : "SIGTERM", sim_.steps(), sim_.time(), file.string()));
    record("interrupted");
    writeLog();
    return 128 + sig;
  }

  fs::path saveCheckpoint() {
    CheckpointHeader header;
    header.sceneHash = hash_;
    header.scene = scene_.resolvedJson;
    header.step = sim_.steps();
    header.time = sim_.time();
    header.lastFrame = lastFrame_;
    for (const auto& s : sinks_) header.sinks.push_back(s->state());
    header.log = log_.text();
    header.checkpointBytes = checkpointBytes_;
    const fs::path file = writeCheckpoint(out_, sim_.steps(), header, [this](StateWriter* w) {
      sim_.save(w);
      if (steady_) steady_->save(w);
    });
    checkpointBytes_ += fileBytes(file);
    return file;
  }

  void resume() {
    Checkpoint c = latestCheckpoint(out_, [this](const std::string& line) { log_.warn(line); });
    const CheckpointHeader& h = c.header;
    // Another version's checkpoint is read section by section, each checked
    // by name and size: one that does not fit is refused; the log says so.
    if (h.version != kVersion)
      log_.warn(fmt::format("warning: {} was written by morphoflow {}, this is {}: its state is used only if every "
                            "section fits",
                            c.file.string(), h.version, kVersion));
    if (h.sceneHash != hash_ && !opt_.force) {
      std::vector<std::string> keys = changedKeys(h.scene, scene_.resolvedJson);
      throw UserError(
          {c.file.string(), 0, 0}, "--resume",
          "the scene differs from the one this checkpoint was written by" +
              (keys.empty() ? std::string() : " (changed: " + fmt::format("{}", fmt::join(keys, ", ")) + ")"),
          "resume with the scene as it was, add --force to continue anyway, or run without --resume");
    }
    try {
      const StateReader state(std::move(c.state));
      sim_.load(state);
      if (steady_) steady_->load(state, sim_);
    } catch (const StateError& e) {
      throw UserError({c.file.string(), 0, 0}, "--resume",
                      std::string("the checkpoint does not fit this scene: ") + e.what(),
                      "run the scene without --resume to start it afresh");
    }
    lastFrame_ = h.lastFrame;
    checkpointBytes_ = h.checkpointBytes;
    log_.restore(h.log);
    log_.say(fmt::format("resumed from {} (step {}, t = {:.5g})", c.file.string(), sim_.steps(), sim_.time()));
    resumedFrom_ = c.file.string();
    checkpoint_ = std::move(c);
  }

  void restoreSinks() {
    const nlohmann::json& states = checkpoint_->header.sinks;
    if (states.size() != sinks_.size())
      throw UserError({checkpoint_->file.string(), 0, 0}, "--resume", "the checkpoint was written with other outputs",
                      "resume with the outputs as they were, or run without --resume");
    // A checksum-valid header whose outputs' state lacks a key or holds a
    // wrong type or a negative count is refused as damaged, naming it.
    for (size_t i = 0; i < sinks_.size(); ++i) {
      try {
        sinks_[i]->restore(states[i]);
      } catch (const std::exception& e) {  // json's errors and stateCount's
        throw UserError({checkpoint_->file.string(), 0, 0}, "--resume",
                        fmt::format("the checkpoint's state of output {} is damaged ({})", i + 1, e.what()),
                        "run the scene without --resume to start it afresh");
      }
    }
  }

  // run.json, with how the run ended.
  nlohmann::json record(const std::string& exitState, const std::string& error = {}) {
    nlohmann::json j;
    j["version"] = kVersion;
    j["scene_file"] = scene_.path;
    j["scene"] = nlohmann::json::parse(scene_.resolvedJson);
    j["settings_hash"] = hash_;
    j["overrides"] = opt_.overrides;
    j["resolved"] = sim_.resolved();
    j["backend"] = opt_.backend;
    j["threads"] = opt_.threads > 0 ? opt_.threads : hardwareThreads();
    j["steps"] = sim_.steps();
    j["time"] = sim_.time();
    j["frames_written"] = 0;
    j["fields_written"] = 0;
    j["wall_seconds"] = wallSeconds();
    j["exit_state"] = exitState;
    if (!error.empty()) j["error"] = error;
    if (!resumedFrom_.empty()) j["resumed_from"] = resumedFrom_;
    j["peak_memory_bytes"] = peakMemoryBytes();
    j["memory_estimate_bytes"] = estimateRunBytes(scene_);
    j["bytes_written"] = nlohmann::json::object();
    for (const auto& s : sinks_) s->report(&j);
    addBytes(&j, "checkpoints", checkpointBytes_);
    addBytes(&j, "measurements", measurementBytes_);
    sim_.report(&j);
    if (steady_) j["until_steady"] = steadyRecord();
    try {
      writeFileAtomically(out_ / "run.json", j.dump(2) + "\n");
    } catch (const std::exception&) {
      if (exitState == "completed") throw;  // a failed run keeps its first error
    }
    return j;
  }

  void writeLog() { writeFileAtomically(out_ / "log.txt", log_.text()); }

  double wallSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
  }

  Simulation<D>& sim_;
  const Scene& scene_;
  const RunOptions& opt_;
  RunLog& log_;
  const fs::path out_;
  const FrameSchedule schedule_;
  const RunClock clock_;
  const std::string hash_;
  std::vector<std::unique_ptr<OutputSink<D>>> sinks_;
  std::optional<Checkpoint> checkpoint_;
  std::string resumedFrom_;
  long lastFrame_ = -1;
  std::optional<FolderLock> lock_;
  std::optional<SteadyState<D>> steady_;
  long checkedStep_ = -1;
  double lastDt_ = 0.0;
  uintmax_t checkpointBytes_ = 0, measurementBytes_ = 0;
  const std::chrono::steady_clock::time_point wall0_ = std::chrono::steady_clock::now();
};

}  // namespace

template <int D>
int driveRun(Simulation<D>& sim, const Scene& scene, const RunOptions& opt, RunLog* log) {
  StopSignals signals;
  return Driver<D>(sim, scene, opt, log).run();
}

template int driveRun<2>(Simulation<2>&, const Scene&, const RunOptions&, RunLog*);
template int driveRun<3>(Simulation<3>&, const Scene&, const RunOptions&, RunLog*);

}  // namespace morphoflow
