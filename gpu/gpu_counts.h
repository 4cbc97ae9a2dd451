// What the GPU backend asks of the driver, counted since the process
// started: compute dispatches (glDispatchCompute) and host waits, the calls
// that make the host wait for the GPU's queued work (a buffer read back,
// glFinish). Timer queries are not waits: they are read a step late
// (gpu_stage_timer.h). run.json and the GPU benchmarks report them per step,
// and per stage where a GpuStageTimer marks the stages.
#pragma once

#include <nlohmann/json.hpp>

namespace morphoflow {

struct GpuCounts {
  long dispatches = 0, hostWaits = 0;
  GpuCounts operator-(const GpuCounts& o) const { return {dispatches - o.dispatches, hostWaits - o.hostWaits}; }
  GpuCounts& operator+=(const GpuCounts& o) {
    dispatches += o.dispatches, hostWaits += o.hostWaits;
    return *this;
  }
};

GpuCounts gpuCounts();
void countDispatch();
void countHostWait();

// {"dispatches_per_step", "host_waits_per_step"} of `c` over `steps` steps.
nlohmann::json perStep(const GpuCounts& c, long steps);

// The counts of a backend's steps (and of the work between them that
// belongs to the step), not of its set-up or its frames' read-backs.
struct StepCounts {
  GpuCounts total;
  long steps = 0;
  template <class F>
  void add(F&& work) {
    const GpuCounts before = gpuCounts();
    work();
    total += gpuCounts() - before;
  }
  nlohmann::json perStep() const { return morphoflow::perStep(total, steps); }
};

}  // namespace morphoflow
