#include "coupling/coupled_stepper.h"

#include <chrono>

#include <tbb/task_group.h>

namespace morphoflow {

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

template <int D>
CoupledStepper<D>::CoupledStepper(FluidSolver<D>* fluid, ARDSolver<D>* ard, CouplingBackend backend)
    : fluid_(fluid), ard_(ard), backend_(backend), velocityN_(fluid->velocity()) {}

template <int D>
void CoupledStepper<D>::step(double dt) {
  const double t0 = now();
  // Velocity n for the ARD step, copied before the fluid writes velocity n + 1.
  for (int a = 0; a < D; ++a) velocityN_[a].values() = fluid_->velocity()[a].values();
  auto timed = [&](double* seconds, auto&& fn) {
    const double b = now();
    fn();
    *seconds = now() - b;
  };
  auto fluidStep = [&] { timed(&fluidSeconds_, [&] { fluid_->step(dt); }); };
  auto ardStep = [&] { timed(&ardSeconds_, [&] { ard_->step(dt, velocityN_); }); };
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

template class CoupledStepper<2>;
template class CoupledStepper<3>;

}  // namespace morphoflow
