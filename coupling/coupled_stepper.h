// CoupledStepper<D>: advances a fluid and its ARD layer together.
//
//   serial: fluid step n + 1, then the ARD step n reading velocity n.
//   tbb:    the same two steps run concurrently (seed 001 sec. 7): velocity n
//           is copied into a second buffer before the fluid overwrites it, the
//           ARD step reads only that copy, and both steps split into TBB tasks,
//           so RD work fills the cores while the pressure solve waits on memory.
//
// Both orders compute exactly the same numbers: neither step reads what the
// other writes, and every parallel loop has a fixed decomposition, so the
// output does not depend on the backend or the thread count.
#pragma once

#include "core/stage_trace.h"
#include "coupling/ard_solver.h"
#include "fluid/fluid_solver.h"

namespace morphoflow {

enum class CouplingBackend { Serial, TBB };

template <int D>
class CoupledStepper {
 public:
  CoupledStepper(FluidSolver<D>* fluid, ARDSolver<D>* ard, CouplingBackend backend);

  void step(double dt);

  // Wall seconds of the last step: the fluid's, the ARD's, and the whole step.
  double fluidSeconds() const { return fluidSeconds_; }
  double ardSeconds() const { return ardSeconds_; }
  double stepSeconds() const { return stepSeconds_; }

  // Records every later step's stages (the velocity copy, the fluid's four,
  // the ARD's two) on the thread that ran each, into `trace` (null: stop).
  void setTrace(StageTrace* trace) { trace_ = trace; }

 private:
  FluidSolver<D>* fluid_;
  ARDSolver<D>* ard_;
  CouplingBackend backend_;
  MacVelocity<D> velocityN_;  // the second velocity buffer: what the ARD step reads
  double fluidSeconds_ = 0, ardSeconds_ = 0, stepSeconds_ = 0;
  StageTrace* trace_ = nullptr;
};

}  // namespace morphoflow
