#include "coupling/cpu_coupled_stepper.h"

#include <tbb/task_group.h>

#include <atomic>
#include <functional>
#include <numeric>

#include "coupling/solid_on_layer.h"

#if defined(__SANITIZE_THREAD__)
#include <thread>
#endif

namespace morphoflow {

namespace {

// Records stages [first, first + count) that ran back to back from `begin`
// on the calling thread.
template <size_t N>
void recordStages(StageTrace* trace, const char* category, const char* const (&names)[N],
                  const std::array<double, N>& seconds, double begin, size_t first = 0, size_t count = N) {
  if (!trace) return;
  for (size_t k = first; k < first + count; ++k) {
    trace->record(names[k], category, begin, begin + seconds[k]);
    begin += seconds[k];
  }
}

}  // namespace

template <int D>
CpuCoupledStepper<D>::CpuCoupledStepper(FluidSolver<D>* fluid, ARDSolver<D>* ard, Backend backend)
    : fluid_(fluid), fluidStepper_(fluid), ard_(ard), overlap_(D == 2 && backend != Backend::Serial) {
  if (!overlap_) ard_->shareWorkPool(fluid_->workPool());
  fluid_->keepAdvectedVelocity(overlap_);  // (overlapped, the ARD reads it beside the fluid's later stages)
  size_t fluidCells = 1, layerCells = 1;
  for (int a = 0; a < D; ++a) fluidCells *= size_t(fluid_->cells()[a]), layerCells *= size_t(ard_->rd().cells()[a]);
  traceAhead_ = layerCells <= fluidCells;
}

// A moving obstacle: the fluid's solid where this step ends, and the
// chemicals' solid cells with it (coupling/solid_on_layer.h).
template <int D>
void CpuCoupledStepper<D>::moveSolids(double dt) {
  RDSolver<D>& rd = ard_->rd();
  const Grid<uint8_t, D> was = solidOnLayer<D>(fluid_->solid(), fluid_->h(), rd.cells(), rd.h());
  fluid_->placeObstaclesFor(dt);
  Grid<uint8_t, D> now = solidOnLayer<D>(fluid_->solid(), fluid_->h(), rd.cells(), rd.h());
  std::vector<Grid<double, D>*> species;
  for (int s = 0; s < rd.species(); ++s) species.push_back(&rd.field(s));
  followSolid<D>(species, ard_->advector().domain().solidValues, was, now);
  ard_->advector().setSolid(std::move(now.values()));
}

template <int D>
void CpuCoupledStepper<D>::step(double dt) {
  const double t0 = traceClock();
  if (fluid_->movesObstacles()) moveSolids(dt);
  // The ARD's stages, each recorded on the thread that ran it.
  auto ardStage = [&](int k, auto&& run) {
    const double b = traceClock();
    run();
    if (trace_) trace_->record(ARDSolver<D>::kStageNames[k], "ard", b, traceClock());
  };
  auto reactDiffuse = [&] { ardStage(0, [&] { ard_->reactDiffuse(dt); }); };
  // The fluid's step keeps the velocity it advected through until the next step.
  auto advect = [&] { ardStage(1, [&] { ard_->advect(dt, fluid_->advectedVelocity()); }); };
  const auto& fluidStages = FluidStepStats::kStageNames;
  if (!overlap_) {
    // The ARD's step inside the fluid's, once its advection is done: the
    // fluid's stages leave their work vectors in the pool the ARD borrows.
    const double b = traceClock();
    double resumed = b;
    fluid_->step(dt, [&] {
      // Chemicals on a grid no finer than the fluid's: their feet first
      // (counted in their advection's seconds), whose bytes are no more
      // than the velocity's, which then goes back to the pool before the
      // reaction-diffusion solves borrow from it. Finer chemicals keep the
      // velocity instead, and trace after those solves.
      if (traceAhead_) {
        ard_->traceAhead(dt, fluid_->advectedVelocity());
        fluid_->releaseAdvectedVelocity();
        reactDiffuse();
        ardStage(1, [&] { ard_->advect(dt); });
      } else {
        reactDiffuse();
        advect();
      }
      resumed = traceClock();
    });
    const auto& seconds = fluid_->lastStats().seconds;  // (the ARD's time not among them)
    fluidSeconds_ = std::accumulate(seconds.begin(), seconds.end(), 0.0);
    recordStages(trace_, "fluid", fluidStages, seconds, b, 0, 2);
    recordStages(trace_, "fluid", fluidStages, seconds, resumed, 2, 2);
  } else {
    auto fluidStep = [&](const std::function<void()>& afterAdvection) {
      const double b = traceClock();
      fluid_->step(dt, afterAdvection);
      fluidSeconds_ = traceClock() - b;
      recordStages(trace_, "fluid", fluidStages, fluid_->lastStats().seconds, b);
    };
    // The chemicals' advection waits for two things, the reaction-diffusion
    // stage and the fluid's advection: whichever is done second starts it.
    std::atomic<int> done{0};
#if defined(__SANITIZE_THREAD__)
    auto arrive = [&] { if (done.fetch_add(1) == 1) advect(); };
    std::thread fluidThread([&] { fluidStep(arrive); });  // TSan builds: a thread TSan sees (core/parallel.h)
    reactDiffuse();
    arrive();
    fluidThread.join();
#else
    tbb::task_group group;
    auto arrive = [&] { if (done.fetch_add(1) == 1) group.run(advect); };
    group.run([&] { fluidStep(arrive); });
    reactDiffuse();
    arrive();
    group.wait();
#endif
  }
  ardSeconds_ = ard_->stageSeconds()[0] + ard_->stageSeconds()[1];
  stepSeconds_ = traceClock() - t0;
}

template class CpuCoupledStepper<2>;
template class CpuCoupledStepper<3>;

}  // namespace morphoflow
