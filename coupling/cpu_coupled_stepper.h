// CpuCoupledStepper<D>: advances a fluid and its ARD layer together.
//
//   nested:     the ARD step n inside the fluid's step n + 1, once the
//               fluid's advection is done: reaction-diffusion, then the
//               chemicals advected through the velocity the fluid's step
//               advected through (velocity n with step n + 1's forces, which
//               the fluid keeps until its next step: no copy of it is made).
//               The ARD borrows its work vectors from the fluid's pool, which
//               its stages have then given back: one set for both steps.
//   overlapped: the same two steps run concurrently (seed 001 sec. 7): the
//               ARD's reaction-diffusion beside the fluid's step from its
//               start, its advection once the fluid's advection is done too,
//               and both steps split into TBB tasks, so RD work fills the
//               cores while the pressure solve waits on memory; each step
//               keeps its own work vectors.
//
// The serial backend nests, and so does tbb in 3D, whose stages are bound by
// memory on both sides, so that overlapping them gains nothing measurable
// while the second set of work vectors costs 20 bytes a cell
// (docs/performance.md); tbb in 2D overlaps.
//
// Both orders compute exactly the same numbers: neither step reads what the
// other writes, and every parallel loop has a fixed decomposition, so the
// output does not depend on the backend or the thread count.
#pragma once

#include "core/backend.h"
#include "core/stage_trace.h"
#include "coupling/ard_solver.h"
#include "coupling/coupled_stepper.h"
#include "fluid/fluid_solver.h"

namespace morphoflow {

template <int D>
class CpuCoupledStepper final : public CoupledStepper<D> {
 public:
  // backend: Serial (nested, one thread) or TBB (nested in 3D, else overlapped).
  CpuCoupledStepper(FluidSolver<D>* fluid, ARDSolver<D>* ard, Backend backend);

  void step(double dt) override;
  const FluidStepper<D>& fluid() const override { return fluidStepper_; }
  const RDStepStats& layerStats() const override { return ard_->rd().lastStats(); }
  std::array<double, 3> seconds() const override { return {fluidSeconds_, ardSeconds_, stepSeconds_}; }
  bool overlapped() const override { return overlap_; }
  // (the hosts are the solvers stepped)
  void toHost(FluidSolver<D>*, RDSolver<D>*) const override {}
  void fromHost(const FluidSolver<D>&, const RDSolver<D>&) override {}
  void save(StateWriter*) const override {}
  void load(const StateReader&) override {}
  void report(nlohmann::json*) const override {}
  void blendLayer(int, const Grid<float, D>& cover, const std::vector<double>& values) override {
    morphoflow::blendLayer<D>(&ard_->rd(), cover, values);
  }
  void maskLayer(const SmokeTaps<D>& taps, double threshold, const std::vector<double>& rest) override {
    morphoflow::maskLayer<D>(&ard_->rd(), fluid_->dye(), taps, threshold, rest);
  }

  // Wall seconds of the last step: the fluid's, the ARD's, and the whole step.
  double fluidSeconds() const { return fluidSeconds_; }
  double ardSeconds() const { return ardSeconds_; }

  // Records every later step's stages (the fluid's four, the ARD's two) on
  // the thread that ran each, into `trace` (null: stop).
  void setTrace(StageTrace* trace) { trace_ = trace; }

 private:
  void moveSolids(double dt);
  FluidSolver<D>* fluid_;
  CpuFluidStepper<D> fluidStepper_;
  ARDSolver<D>* ard_;
  bool overlap_;
  bool traceAhead_;  // nested: the chemicals' feet before the velocity goes back to the pool
  double fluidSeconds_ = 0, ardSeconds_ = 0, stepSeconds_ = 0;
  StageTrace* trace_ = nullptr;
};

}  // namespace morphoflow
