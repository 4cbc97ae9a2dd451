// FluidStepper<D>: what advances a scene's fluid, with one shape for every
// backend. The host FluidSolver (fluid_solver.h) holds the state that fields,
// probes and checkpoints read: the CPU stepper steps it in place
// (CpuFluidStepper), the GPU's keeps the fields on the device
// (gpu/gpu_fluid.h) and copies them into it when asked.
#pragma once

#include <cmath>

#include <nlohmann/json.hpp>

#include "core/state_archive.h"
#include "fluid/fluid_solver.h"

namespace morphoflow {

template <int D>
class FluidStepper {
 public:
  virtual ~FluidStepper() = default;

  virtual void step(double dt) = 0;
  virtual double time() const = 0;
  virtual long steps() const = 0;
  // The solvers' results and the stages' seconds of the last step.
  virtual const FluidStepStats& lastStats() const = 0;
  virtual double cflTimeStep(double cfl, double dtMax) const = 0;
  // Whether the last step left a finite velocity.
  virtual bool finite() const = 0;
  // The state into `host` (nothing where the host is what is stepped), and
  // from it (after a checkpoint was read into it).
  virtual void toHost(FluidSolver<D>* host) const = 0;
  virtual void fromHost(const FluidSolver<D>& host) = 0;
  // Checkpoints: what the stepper keeps besides the host's state.
  virtual void save(StateWriter* out) const = 0;
  virtual void load(const StateReader& in) = 0;
  // run.json: the backend's own entries (the GL context, its solvers).
  virtual void report(nlohmann::json* run) const = 0;
};

template <int D>
class CpuFluidStepper final : public FluidStepper<D> {
 public:
  explicit CpuFluidStepper(FluidSolver<D>* fluid) : fluid_(fluid) {}

  void step(double dt) override { fluid_->step(dt); }
  double time() const override { return fluid_->time(); }
  long steps() const override { return fluid_->steps(); }
  const FluidStepStats& lastStats() const override { return fluid_->lastStats(); }
  double cflTimeStep(double cfl, double dtMax) const override { return fluid_->cflTimeStep(cfl, dtMax); }
  bool finite() const override { return std::isfinite(fluid_->maxSpeed()); }
  void toHost(FluidSolver<D>*) const override {}
  void fromHost(const FluidSolver<D>&) override {}
  void save(StateWriter*) const override {}
  void load(const StateReader&) override {}
  void report(nlohmann::json*) const override {}

 private:
  FluidSolver<D>* fluid_;
};

}  // namespace morphoflow
