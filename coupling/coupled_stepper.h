// CoupledStepper<D>: what advances a fluid and its advection-reaction-diffusion
// layer together, with one shape for every backend: the CPU's serial or tbb
// schedule (cpu_coupled_stepper.h) and the GPU's (gpu/gpu_coupled_stepper.h). The
// host FluidSolver and RDSolver hold the state that fields and checkpoints
// read; a backend whose state lives elsewhere copies it there when asked.
#pragma once

#include <array>

#include <nlohmann/json.hpp>

#include "core/state_archive.h"
#include "coupling/smoke_layer.h"
#include "fluid/fluid_stepper.h"
#include "rd/rd_solver.h"

namespace morphoflow {

template <int D>
class CoupledStepper {
 public:
  virtual ~CoupledStepper() = default;

  virtual void step(double dt) = 0;
  // The fluid side: the clock, its solvers' results, the CFL step, finiteness.
  virtual const FluidStepper<D>& fluid() const = 0;
  // The layer's Newton and diffusion results of the last step.
  virtual const RDStepStats& layerStats() const = 0;
  // Seconds of the last step: the fluid's, the ARD's, the whole step's.
  virtual std::array<double, 3> seconds() const = 0;
  // Whether the two sides ran concurrently.
  virtual bool overlapped() const = 0;
  // The state into the hosts (nothing where the hosts are what is stepped),
  // and from them (after a checkpoint was read into them).
  virtual void toHost(FluidSolver<D>* fluid, RDSolver<D>* rd) const = 0;
  virtual void fromHost(const FluidSolver<D>& fluid, const RDSolver<D>& rd) = 0;
  // Checkpoints: what the backend keeps besides the hosts' state.
  virtual void save(StateWriter* out) const = 0;
  virtual void load(const StateReader& in) = 0;
  // run.json: the backend's own entries.
  virtual void report(nlohmann::json* run) const = 0;
  // The pattern on the smoke (smoke_layer.h) on the stepped layer: a
  // source's blend (`id` names a cover that stays the same from step to
  // step, -1 one that moves) and the mask.
  virtual void blendLayer(int id, const Grid<float, D>& cover, const std::vector<double>& values) = 0;
  virtual void maskLayer(const SmokeTaps<D>& taps, double threshold, const std::vector<double>& rest) = 0;
};

}  // namespace morphoflow
