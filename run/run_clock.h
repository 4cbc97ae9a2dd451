// How long a run lasts and how large each step is: a fixed step count, or a
// duration whose last step is clipped to end on it; dt shrinks to the CFL
// limit when time.cfl > 0.
#pragma once

#include <algorithm>
#include <limits>

#include "sim/simulation.h"
#include "scenes/scene.h"

namespace morphoflow {

// How a scene's run is clocked: a reaction-diffusion-only scene takes whole
// steps of time.dt (duration / dt of them); a fluid may adapt dt and clip the last.
inline TimeSettings runTime(const Scene& scene) {
  TimeSettings t = scene.time;
  if (!scene.hasFluid) {
    t.steps = scene.totalSteps();
    t.cfl = 0.0;
  }
  return t;
}

class RunClock {
 public:
  explicit RunClock(const TimeSettings& t)
      : time_(t),
        steps_(t.steps > 0 ? t.steps : std::numeric_limits<long>::max()),
        endTime_(t.steps > 0 ? 1e300 : t.duration) {}

  // Whether step `step` (0-based) still runs at simulated time `time`.
  bool running(long step, double time) const { return step < steps_ && time < endTime_ - TimeSettings::kEndTolerance; }

  // The steps still to run from step `step` on (by the step count alone).
  long stepsLeft(long step) const { return steps_ - step; }
  // When the run ends at the latest: its duration, or its steps of time.dt
  // (a CFL limit shortens them).
  double latestEnd() const { return time_.steps > 0 ? double(time_.steps) * time_.dt : endTime_; }
  // Whether every step takes time.dt (a step count, no CFL limit).
  bool fixedDt() const { return time_.steps > 0 && time_.cfl <= 0; }

  template <int D>
  double dt(const Simulation<D>& sim) const {
    double dt = time_.dt;
    if (time_.cfl > 0) dt = sim.cflTimeStep(time_.cfl, time_.dt);
    if (time_.steps == 0) dt = std::min(dt, endTime_ - sim.time());
    return dt;
  }

 private:
  TimeSettings time_;
  long steps_;
  double endTime_;
};

}  // namespace morphoflow
