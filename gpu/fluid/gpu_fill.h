// A moving solid's fill (fluid/extrapolation.h) on the GPU: the plan the
// host made from the solid's flags, uploaded once, carried out on any field
// of its grid by shaders/fill.comp, a dispatch a layer.
#pragma once

#include <optional>
#include <vector>

#include "core/backend.h"
#include "fluid/extrapolation.h"
#include "gpu/gpu_buffer.h"

namespace morphoflow {

class GpuFill {
 public:
  explicit GpuFill(const FillPlan& plan);
  bool empty() const { return covered_ == 0 && layerEnds_.empty(); }
  // The elements of `field` from `offset` on (of precision `type`) filled;
  // the covered ones take `covered` when given.
  void apply(const GpuBuffer& field, size_t offset, GpuPrecision type, std::optional<double> covered = {}) const;

 private:
  int stride_ = 0;
  size_t covered_ = 0, entries_ = 0;  // the covered elements; the uncovered ones (in uints)
  std::vector<size_t> layerEnds_;
  GpuBuffer plan_;  // the entries, then the covered elements
};

}  // namespace morphoflow
