#include "gpu/gpu_counts.h"

namespace morphoflow {

namespace {
GpuCounts counts;  // (the GL context is the process's one thread's)
}  // namespace

GpuCounts gpuCounts() { return counts; }
void countDispatch() { ++counts.dispatches; }
void countHostWait() { ++counts.hostWaits; }

nlohmann::json perStep(const GpuCounts& c, long steps) {
  const double n = steps > 0 ? double(steps) : 1.0;
  return {{"dispatches_per_step", double(c.dispatches) / n}, {"host_waits_per_step", double(c.hostWaits) / n}};
}

}  // namespace morphoflow
