#include "coupling/coupled_stepper.h"

#include <tbb/task_group.h>

#if defined(__SANITIZE_THREAD__)
#include <thread>
#endif

namespace morphoflow {

namespace {

// Records stages that ran back to back from `begin` on the calling thread.
template <size_t N>
void recordStages(StageTrace* trace, const char* category, const char* const (&names)[N],
                  const std::array<double, N>& seconds, double begin) {
  if (!trace) return;
  for (size_t k = 0; k < N; ++k) {
    trace->record(names[k], category, begin, begin + seconds[k]);
    begin += seconds[k];
  }
}

}  // namespace

template <int D>
CoupledStepper<D>::CoupledStepper(FluidSolver<D>* fluid, ARDSolver<D>* ard, CouplingBackend backend)
    : fluid_(fluid), ard_(ard), backend_(backend), velocityN_(fluid->velocity()) {}

template <int D>
void CoupledStepper<D>::step(double dt) {
  const double t0 = traceClock();
  // Velocity n for the ARD step, copied before the fluid writes velocity n + 1.
  for (int a = 0; a < D; ++a) velocityN_[a].values() = fluid_->velocity()[a].values();
  if (trace_) trace_->record("copy velocity", "coupling", t0, traceClock());
  auto fluidStep = [&] {
    const double b = traceClock();
    fluid_->step(dt);
    fluidSeconds_ = traceClock() - b;
    recordStages(trace_, "fluid", FluidStepStats::kStageNames, fluid_->lastStats().seconds, b);
  };
  auto ardStep = [&] {
    const double b = traceClock();
    ard_->step(dt, velocityN_);
    ardSeconds_ = traceClock() - b;
    recordStages(trace_, "ard", ARDSolver<D>::kStageNames, ard_->stageSeconds(), b);
  };
  if (backend_ == CouplingBackend::Serial) {
    fluidStep();
    ardStep();
  } else {
#if defined(__SANITIZE_THREAD__)
    std::thread fluidThread(fluidStep);  // TSan builds: a thread TSan sees (core/parallel.h)
    ardStep();
    fluidThread.join();
#else
    tbb::task_group group;
    group.run(fluidStep);
    ardStep();
    group.wait();
#endif
  }
  stepSeconds_ = traceClock() - t0;
}

template class CoupledStepper<2>;
template class CoupledStepper<3>;

}  // namespace morphoflow
