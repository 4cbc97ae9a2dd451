// Deterministic sums on the GPU (shaders/reduce.comp): a fixed number of
// work groups each sum a fixed share, then one group sums their partials, so
// a sum does not depend on scheduling. Results land in a small buffer of
// double scalars that other kernels read in place (no round trip) and the
// host reads when it must decide (convergence). A kernel that makes the
// terms of a sum can do its partial pass itself (shaders/fused_sum.glsl:
// dispatched over groups(n) groups, writing partials() at the slot), and the
// kernels that use the scalar can do the final pass (finalSum), bitwise as
// dot() would have.
#pragma once

#include <vector>

#include "core/backend.h"
#include "gpu/gpu_buffer.h"

namespace morphoflow {

// Where a kernel that does a sum's partial pass itself writes it: the
// reduction's partials() at `slot` (shaders/fused_sum.glsl).
struct FusedDot {
  const GpuBuffer* partials = nullptr;
  int slot = 0;
};

class GpuReduction {
 public:
  static constexpr int kSlots = 16;
  // Over vectors of `real`s (dot, activeSum).
  explicit GpuReduction(GpuPrecision real = GpuPrecision::Double);
  // The work groups a sum of n terms is split into (a fixed count for n, at most 256).
  static unsigned groups(size_t n);

  void dot(const GpuBuffer& x, const GpuBuffer& y, size_t n, int slot);  // x . y
  // The sum of x where diag > 0; partialOnly: its partials only (a kernel after makes the final pass).
  void activeSum(const GpuBuffer& x, const GpuBuffer& diag, size_t n, int slot, bool partialOnly = false);
  void activeCount(const GpuBuffer& diag, size_t n, int slot);
  void maxAbs(const GpuBuffer& f, size_t n, int slot);  // max |f_i| of a float vector
  std::vector<double> read() const;  // every slot (waits for the queued work)
  const GpuBuffer& scalars() const { return scalars_; }
  const GpuBuffer& partials() const { return partial_; }  // 256 a slot
  FusedDot fused(int slot) const { return {&partial_, slot}; }

 private:
  void run(const char* term, const GpuBuffer& x, const GpuBuffer& y, const GpuBuffer& diag, size_t n, int slot,
           bool partialOnly = false);
  GpuPrecision real_;
  GpuBuffer partial_, scalars_;
};

}  // namespace morphoflow
