#include "coupling/coupled_stepper.h"

#include <chrono>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <tbb/task_group.h>

namespace morphoflow {

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::mutex traceMutex;

int threadId() {
  static std::map<std::thread::id, int> ids;
  std::lock_guard<std::mutex> lock(traceMutex);
  auto [it, fresh] = ids.emplace(std::this_thread::get_id(), int(ids.size()));
  return it->second;
}

}  // namespace

template <int D>
CoupledStepper<D>::CoupledStepper(FluidSolver<D>* fluid, ARDSolver<D>* ard, CouplingBackend backend)
    : fluid_(fluid), ard_(ard), backend_(backend), velocityN_(fluid->velocity()), origin_(now()) {}

template <int D>
void CoupledStepper<D>::step(double dt) {
  const double t0 = now();
  // Velocity n for the ARD step, copied before the fluid writes velocity n + 1.
  for (int a = 0; a < D; ++a) velocityN_[a].values() = fluid_->velocity()[a].values();
  auto timed = [&](const char* name, double* seconds, auto&& fn) {
    const double b = now();
    const int tid = tracing_ ? threadId() : 0;
    fn();
    const double e = now();
    *seconds = e - b;
    if (tracing_) {
      std::lock_guard<std::mutex> lock(traceMutex);
      trace_.push_back({name, tid, b - origin_, e - origin_});
    }
  };
  auto fluidStep = [&] { timed("fluid", &fluidSeconds_, [&] { fluid_->step(dt); }); };
  auto ardStep = [&] { timed("ard", &ardSeconds_, [&] { ard_->step(dt, velocityN_); }); };
  if (backend_ == CouplingBackend::Serial) {
    fluidStep();
    ardStep();
  } else {
    tbb::task_group group;
    group.run(fluidStep);
    ardStep();
    group.wait();
  }
  stepSeconds_ = now() - t0;
}

std::string traceJson(const std::vector<TraceEvent>& events) {
  std::string s = "{\"traceEvents\": [\n";
  for (size_t i = 0; i < events.size(); ++i) {
    const TraceEvent& e = events[i];
    s += fmt::format("  {{\"name\": \"{}\", \"ph\": \"X\", \"pid\": 1, \"tid\": {}, \"ts\": {:.3f}, \"dur\": {:.3f}}}{}\n",
                     e.name, e.thread, 1e6 * e.begin, 1e6 * (e.end - e.begin), i + 1 < events.size() ? "," : "");
  }
  return s + "], \"displayTimeUnit\": \"ms\"}\n";
}

template class CoupledStepper<2>;
template class CoupledStepper<3>;

}  // namespace morphoflow
