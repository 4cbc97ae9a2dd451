#include "studio/studio_session.h"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/parallel.h"
#include "fluid/obstacle_motion.h"
#include "gpu/gl_context.h"
#include "run/memory_estimate.h"
#include "run/run_clock.h"
#include "sim/frame_palette.h"
#include "sim/simulation_factory.h"
#include "studio/frame_encoding.h"

namespace fs = std::filesystem;

namespace morphoflow {

namespace {

const SourceLocation kStudio{"studio", 0, 0};
using Clock = std::chrono::steady_clock;

nlohmann::json region(const ObstacleSpec& r, int D) {
  nlohmann::json j;
  j["shape"] = r.shape == ObstacleShape::Box                                      ? "box"
               : r.shape == ObstacleShape::Image || r.shape == ObstacleShape::Sdf ? "image"
                                                                                  : "circle";
  j["center"] = std::vector<double>(r.center.begin(), r.center.begin() + D);
  j["radius"] = r.radius;
  std::vector<double> size;
  for (int a = 0; a < D; ++a) size.push_back(2.0 * r.halfSize[size_t(a)]);
  j["size"] = size;
  return j;
}

}  // namespace

StudioSession::StudioSession(const std::string& text, const std::string& path, const StudioOptions& options)
    : options_(options), log_(text, path) {
  const Scene& s = log_.scene();
  checkBackend(s, backendNamed(options.backend));
  checkRunFits(s);
  dimension_ = s.dimension;
  // The simulation's thread uses the GPU: the context it took here is let go.
  if (backendNamed(options.backend) == Backend::Gpu) GlContext::instance().release();
  std::promise<void> ready;
  std::future<void> built = ready.get_future();
  thread_ = std::thread([this, &ready] {
    ThreadLimit limit(options_.backend == "serial" ? 1 : options_.threads);
    // The simulation goes on this thread (GPU objects are freed where the
    // context is current), which then lets the GPU's context go.
    auto finish = [this] {
      s2_.reset();
      s3_.reset();
      if (backendNamed(options_.backend) == Backend::Gpu) GlContext::instance().release();
    };
    try {
      build();  // (on this thread: the GPU's context is made current here)
      publish();
      ready.set_value();
    } catch (...) {
      finish();
      ready.set_exception(std::current_exception());
      return;
    }
    loop();
    finish();
  });
  try {
    built.get();
  } catch (...) {
    thread_.join();
    throw;
  }
}

StudioSession::~StudioSession() { close(); }

void StudioSession::close() {
  {
    std::lock_guard<std::mutex> lk(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
    // The GPU's context back on this thread (the process's cached programs are freed on it at exit).
    if (backendNamed(options_.backend) == Backend::Gpu) GlContext::instance();
  }
  if (render_) render_->signal(SIGTERM);
}

template <class F>
auto StudioSession::with(F&& f) const {
  if (s2_) return f(*s2_);
  return f(*s3_);
}

void StudioSession::build() {
  const Backend backend = backendNamed(options_.backend);
  auto quiet = [](const std::string&) {};
  clockScene_ = std::make_unique<Scene>(log_.scene());
  s2_.reset();
  s3_.reset();
  if (dimension_ == 2) s2_ = makeTimelineSimulation<2>(*clockScene_, backend, quiet, quiet);
  else s3_ = makeTimelineSimulation<3>(*clockScene_, backend, quiet, quiet);
  const std::vector<std::string> names = with([](auto& sim) { return sim.fieldNames(); });
  std::lock_guard<std::mutex> lk(mutex_);
  if (std::find(names.begin(), names.end(), field_) == names.end())
    field_ = std::find(names.begin(), names.end(), clockScene_->output.field) != names.end() ? clockScene_->output.field
                                                                                             : names.front();
  time_ = 0.0, steps_ = 0, error_.clear();
}

template <class R>
R StudioSession::onSimThread(std::function<R()> task) {
  std::packaged_task<R()> job(std::move(task));
  std::future<R> result = job.get_future();
  {
    std::lock_guard<std::mutex> lk(mutex_);
    if (stop_) throw UserError(kStudio, "", "this scene was closed", "reload the page");
    tasks_.push_back([&job] { job(); });
  }
  wake_.notify_all();
  return result.get();  // (rethrows the task's UserError)
}

void StudioSession::loop() {
  Clock::time_point rateStart = Clock::now();
  long rateSteps = 0;
  for (;;) {
    std::deque<std::function<void()>> tasks;
    bool go = false;
    {
      std::unique_lock<std::mutex> lk(mutex_);
      wake_.wait_for(lk, std::chrono::milliseconds(200),
                     [&] { return stop_ || !tasks_.empty() || running_ || stepsToDo_ > 0; });
      if (stop_) return;
      tasks.swap(tasks_);
    }
    for (auto& t : tasks) t();
    bool behind = false;  // stopped with a step whose frame was not made (paused between two steps)
    {
      std::lock_guard<std::mutex> lk(mutex_);
      go = running_ || stepsToDo_ > 0;
      if (!running_ && stepsToDo_ > 0) --stepsToDo_;
      behind = !go && sinceFrame_ > 0;
      if (behind) sinceFrame_ = 0, lastFrame_ = Clock::now();
    }
    if (!go) {
      if (behind) publish();
      rateStart = Clock::now(), rateSteps = 0;
      continue;
    }
    stepOnce();
    ++rateSteps;
    const double seconds = std::chrono::duration<double>(Clock::now() - rateStart).count();
    if (seconds >= 0.5) {
      std::lock_guard<std::mutex> lk(mutex_);
      stepsPerSecond_ = rateSteps / seconds;
      rateStart = Clock::now(), rateSteps = 0;
    }
  }
}

// One step of the clock `run` takes (time.dt, the CFL limit, a duration's
// clipped last step); past the scene's end the studio pauses, and runs on
// at the scene's dt when played again.
void StudioSession::stepOnce() {
  try {
    with([&](auto& sim) {
      const TimeSettings t = runTime(*clockScene_);
      const RunClock clock(t);
      double dt = clock.dt(sim);
      if (!clock.running(sim.steps(), sim.time())) {
        std::unique_lock<std::mutex> lk(mutex_);
        if (!pastEnd_) {
          pastEnd_ = true;
          running_ = false, stepsToDo_ = 0;
          error_ =
              fmt::format("the scene's run ends here (t = {:.5g}, step {}): play to run on", sim.time(), sim.steps());
          return;
        }
        dt = t.cfl > 0 ? sim.cflTimeStep(t.cfl, t.dt) : t.dt;
      }
      sim.step(dt);
    });
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lk(mutex_);
    running_ = false, stepsToDo_ = 0;
    error_ = std::string("the step failed: ") + e.what() + " (reset, or undo the last edit)";
  }
  bool due = false;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    with([&](auto& sim) { time_ = sim.time(), steps_ = sim.steps(); });
    const bool paused = !running_ && stepsToDo_ == 0;
    const bool shown = !wanted_ || (wanted_() && Clock::now() - lastFrame_ >= std::chrono::microseconds(16667));
    due = (++sinceFrame_ >= stepsPerFrame_ && shown) || paused;
    if (due) sinceFrame_ = 0, lastFrame_ = Clock::now();
  }
  if (due) publish();
}

void StudioSession::publish() {
  std::string field;
  bool running = false;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    field = field_, running = running_;
  }
  std::string bytes;
  const Clock::time_point start = Clock::now();
  try {
    bytes = with([&](auto& sim) {
      // Every field checked for NaN and infinity when paused and at most 4
      // times a second while running (a frame in between shows them as 0).
      if (!running || Clock::now() - lastCheck_ >= std::chrono::milliseconds(250)) {
        sim.checkFinite(fmt::format("at step {}", sim.steps()));
        lastCheck_ = Clock::now();
      }
      const OutputSettings& out = clockScene_->output;
      const bool autoRange = field != out.field || out.autoRange;
      const nlohmann::json meta = {
          {"field", field}, {"t", sim.time()}, {"step", sim.steps()}, {"dimension", dimension_}};
      return encodeFrame(sim.field(field), frameImageOptions(out, false).palette, autoRange, out.range,
                         sim.symmetric(field), meta);
    });
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lk(mutex_);
    running_ = false, stepsToDo_ = 0;
    error_ = std::string(e.what()) + " (reset, or undo the last edit)";
    return;
  }
  std::function<void()> listener;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    frame_ = std::make_shared<const std::string>(std::move(bytes));
    frameSeconds_ += std::chrono::duration<double>(Clock::now() - start).count();
    listener = listener_;
  }
  ++framesPublished_;
  if (listener) listener();
}

std::shared_ptr<const std::string> StudioSession::frame() const {
  std::lock_guard<std::mutex> lk(mutex_);
  return frame_;
}

void StudioSession::onFrame(std::function<void()> listener, std::function<bool()> wanted) {
  std::lock_guard<std::mutex> lk(mutex_);
  listener_ = std::move(listener);
  wanted_ = std::move(wanted);
}

nlohmann::json StudioSession::state() const {
  std::lock_guard<std::mutex> lk(mutex_);
  const Scene& s = log_.scene();
  nlohmann::json j = {{"scene", s.name},        {"path", log_.path()},   {"dimension", dimension_},
                      {"t", time_},             {"steps", steps_},       {"running", running_},
                      {"steps_per_second", stepsPerSecond_}, {"field", field_}, {"steps_per_frame", stepsPerFrame_},
                      {"frames", framesPublished_.load()},
                      {"frame_ms", framesPublished_ > 0 ? 1e3 * frameSeconds_ / double(framesPublished_) : 0.0}};
  j["domain"] = s.fluid.size;
  j["fields"] = with([](auto& sim) { return sim.fieldNames(); });
  j["species"] = with([](auto& sim) { return sim.species(); });
  j["rest_values"] = s.rd.initial.values;
  nlohmann::json keys = nlohmann::json::object();
  for (const auto& [key, range] : s.numericKeys) {
    if (!isSteerableKey(key)) continue;
    std::vector<double> value = range.values;
    for (const KeyedValue& k : s.timeline.keyed)
      if (k.key == key) value = k.at(time_);
    keys[key] = {{"value", range.array ? nlohmann::json(value) : nlohmann::json(value[0])},
                 {"min", range.lo}, {"max", range.hi}, {"min_open", range.loOpen}};
  }
  j["keys"] = keys;
  nlohmann::json elements = nlohmann::json::array();
  for (size_t q = 0; q < s.fluid.obstacles.size(); ++q) {
    // (a moving obstacle where it is now)
    nlohmann::json e = region(placedAt(s.fluid.obstacles[q], s.dimension, time_, nullptr), s.dimension);
    e["target"] = fmt::format("obstacles.{}", q);
    e["active"] = q < s.timeline.obstacles.size() ? s.timeline.obstacles[q].contains(time_) : true;
    elements.push_back(e);
  }
  for (size_t q = 0; q < s.fluid.smoke.sources.size(); ++q) {
    const SmokeSource& src = s.fluid.smoke.sources[q];
    nlohmann::json e = region(src.region, s.dimension);
    e["target"] = fmt::format("sources.{}", q);
    e["active"] = src.start <= time_ && time_ < src.end;
    elements.push_back(e);
  }
  j["elements"] = elements;
  j["error"] = error_;
  nlohmann::json render = {{"running", false}};
  if (render_) {
    std::optional<ChildExit> done = const_cast<ChildProcess&>(*render_).poll();
    long frames = 0;
    std::error_code ec;
    for (const auto& f : fs::directory_iterator(fs::path(renderOut_) / "frames", ec))
      frames += f.is_regular_file() ? 1 : 0;
    render = {{"running", !done}, {"out", renderOut_}, {"frames", frames}, {"total_frames", renderFrames_},
              {"progress", renderFrames_ > 0 ? std::min(1.0, double(frames) / double(renderFrames_)) : 0.0}};
    if (done) render["exit_code"] = done->signal ? 128 + done->signal : done->code;
  }
  j["render"] = render;
  return j;
}

nlohmann::json StudioSession::where() const {
  return with([](auto& sim) { return nlohmann::json{{"t", sim.time()}, {"step", sim.steps()}}; });
}

nlohmann::json StudioSession::control(const nlohmann::json& body) {
  const std::string action = body.is_object() ? body.value("action", "") : "";
  if (action == "play" || action == "pause") {
    std::lock_guard<std::mutex> lk(mutex_);
    running_ = action == "play";
    stepsToDo_ = 0;
    if (running_) error_.clear();
  } else if (action == "step") {
    const nlohmann::json n = body.value("count", nlohmann::json(1));
    if (!n.is_number_integer() || n.get<long>() < 1 || n.get<long>() > 100000)
      throw UserError(kStudio, "count", "expected an integer in [1, 100000], found " + n.dump());
    std::lock_guard<std::mutex> lk(mutex_);
    running_ = false;
    stepsToDo_ += n.get<long>();
  } else if (action == "reset") {
    return onSimThread<nlohmann::json>([this] {
      EditLog collapsed = log_;
      collapsed.collapse();
      {
        std::lock_guard<std::mutex> lk(mutex_);
        log_ = std::move(collapsed);
        running_ = false, stepsToDo_ = 0, pastEnd_ = false;
      }
      build();
      publish();
      return where();
    });
  } else {
    throw UserError(kStudio, "action",
                    "expected \"play\", \"pause\", \"step\" or \"reset\", found " +
                        (body.is_object() && body.contains("action") ? body["action"].dump() : std::string("nothing")));
  }
  wake_.notify_all();
  return {{"ok", true}};
}

// An edit on the simulation's thread, between two steps: recorded at the
// time the next step starts from (before the first step, the scene itself
// changes and the simulation is built again).
nlohmann::json StudioSession::set(const nlohmann::json& body) {
  if (!body.is_object() || body.empty()) throw UserError(kStudio, "", "expected {\"key\": value, ...}");
  return onSimThread<nlohmann::json>([&] {
    EditLog trial = log_;
    const double t = with([](auto& sim) { return sim.time(); });
    for (const auto& [key, value] : body.items()) trial.set(key, value, t);
    return adopt(std::move(trial));
  });
}

nlohmann::json StudioSession::paint(const nlohmann::json& edit) {
  return onSimThread<nlohmann::json>([&] {
    EditLog trial = log_;
    trial.paint(edit, with([](auto& sim) { return sim.time(); }));
    return adopt(std::move(trial));
  });
}

nlohmann::json StudioSession::adopt(EditLog&& edited) {
  const bool fresh = with([](auto& sim) { return sim.steps() == 0; });
  {
    std::lock_guard<std::mutex> lk(mutex_);
    log_ = std::move(edited);
  }
  if (fresh) {
    build();
    publish();
  } else {
    // Shown now, as the next step would start from it (a paused run shows a deposit at once).
    with([&](auto& sim) {
      sim.retarget(log_.scene());
      sim.prepare(RunClock(runTime(*clockScene_)).dt(sim));
    });
    publish();
  }
  nlohmann::json j = where();
  j["ok"] = true;
  return j;
}

nlohmann::json StudioSession::view(const nlohmann::json& body) {
  if (!body.is_object()) throw UserError(kStudio, "", "expected {\"field\": name} or {\"steps_per_frame\": n}");
  for (const auto& [key, v] : body.items())
    if (key != "field" && key != "steps_per_frame")
      throw UserError(kStudio, key, "unknown key", "expected field or steps_per_frame");
  if (body.contains("steps_per_frame")) {
    const nlohmann::json& n = body["steps_per_frame"];
    if (!n.is_number_integer() || n.get<long>() < 1 || n.get<long>() > 10000)
      throw UserError(kStudio, "steps_per_frame", "expected an integer in [1, 10000], found " + n.dump());
    std::lock_guard<std::mutex> lk(mutex_);
    stepsPerFrame_ = n.get<long>();
  }
  if (body.contains("field")) {
    const nlohmann::json& f = body["field"];
    return onSimThread<nlohmann::json>([&] {
      const std::vector<std::string> names = with([](auto& sim) { return sim.fieldNames(); });
      if (!f.is_string() || std::find(names.begin(), names.end(), f.get<std::string>()) == names.end())
        throw UserError(kStudio, "field", "no field " + f.dump(),
                        "the fields: " + fmt::format("{}", fmt::join(names, ", ")));
      {
        std::lock_guard<std::mutex> lk(mutex_);
        field_ = f.get<std::string>();
      }
      publish();
      return nlohmann::json{{"ok", true}};
    });
  }
  return {{"ok", true}};
}

std::string StudioSession::sceneText() const {
  std::lock_guard<std::mutex> lk(mutex_);
  return log_.text();
}

std::string StudioSession::fieldNpy(const std::string& name) {
  return onSimThread<std::string>([&] {
    return with([&](auto& sim) {
      const std::vector<std::string> names = sim.fieldNames();
      if (std::find(names.begin(), names.end(), name) == names.end())
        throw UserError(kStudio, "name", "no field '" + name + "'",
                        "the fields: " + fmt::format("{}", fmt::join(names, ", ")));
      return npyFile(sim.field(name));
    });
  });
}

nlohmann::json StudioSession::render() {
  std::lock_guard<std::mutex> lk(mutex_);
  if (render_ && !render_->poll())
    throw UserError(kStudio, "render", "a render is running (" + renderOut_ + ")", "wait for it to end");
  const Scene& s = log_.scene();
  const fs::path out = fs::absolute(options_.out);
  fs::create_directories(out);
  const fs::path file = out / (s.name + "_studio.toml");
  {
    std::ofstream f(file);
    f << log_.text();
    if (!f) throw UserError({file.string(), 0, 0}, "", "cannot write the saved scene", "check --out");
  }
  renderOut_ = (out / (s.name + "_render")).string();
  renderFrames_ = s.time.cfl > 0 ? 0 : s.totalSteps() / s.output.every + 1;
  render_.reset();
  render_.emplace(options_.executable,
                  std::vector<std::string>{"run", file.string(), "--out", renderOut_, "--backend", options_.backend},
                  out / (s.name + "_render.log"));
  return {{"ok", true}, {"scene", file.string()}, {"out", renderOut_}};
}

}  // namespace morphoflow
