// Deterministic sums on the GPU (shaders/reduce.comp): a fixed number of
// work groups each sum a fixed share, then one group sums their partials, so
// a sum does not depend on scheduling. Results land in a small buffer of
// double scalars that other kernels read in place (no round trip) and the
// host reads when it must decide (convergence).
#pragma once

#include <vector>

#include "gpu/gpu_buffer.h"

namespace morphoflow {

class GpuReduction {
 public:
  static constexpr int kSlots = 16;
  GpuReduction();

  void dot(const GpuBuffer& x, const GpuBuffer& y, size_t n, int slot);       // x . y (double vectors)
  void activeSum(const GpuBuffer& x, const GpuBuffer& diag, size_t n, int slot);  // sum of x where diag > 0
  void activeCount(const GpuBuffer& diag, size_t n, int slot);
  void maxAbs(const GpuBuffer& f, size_t n, int slot);  // max |f_i| of a float vector
  std::vector<double> read() const;  // every slot (waits for the queued work)
  const GpuBuffer& scalars() const { return scalars_; }

 private:
  void run(const char* term, const GpuBuffer& x, const GpuBuffer& y, const GpuBuffer& diag, size_t n, int slot);
  GpuBuffer partial_, scalars_;
};

}  // namespace morphoflow
