// How long a fluid run lasts and how large each step is: a fixed step count,
// or a duration whose last step is clipped to end on it; dt shrinks to the
// CFL limit when time.cfl > 0. Shared by the fluid and the coupled runners.
#pragma once

#include <algorithm>
#include <limits>

#include "fluid/fluid_solver.h"
#include "scenes/scene.h"

namespace morphoflow {

class RunClock {
 public:
  explicit RunClock(const TimeSettings& t)
      : time_(t),
        steps_(t.steps > 0 ? t.steps : std::numeric_limits<long>::max()),
        endTime_(t.steps > 0 ? 1e300 : t.duration) {}

  // Whether step `step` (0-based) still runs at fluid time `time`.
  bool running(long step, double time) const { return step < steps_ && time < endTime_ - 1e-12; }

  template <int D>
  double dt(const FluidSolver<D>& fluid) const {
    double dt = time_.dt;
    if (time_.cfl > 0) dt = fluid.cflTimeStep(time_.cfl, time_.dt);
    if (time_.steps == 0) dt = std::min(dt, endTime_ - fluid.time());
    return dt;
  }

 private:
  TimeSettings time_;
  long steps_;
  double endTime_;
};

}  // namespace morphoflow
