#include "gpu/fluid/gpu_fill.h"

#include "gpu/compute_program.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

GpuFill::GpuFill(const FillPlan& plan)
    : stride_(plan.stride), covered_(plan.covered.size()), entries_(plan.entries.size()), layerEnds_(plan.layerEnds) {
  if (plan.empty()) return;
  std::vector<uint32_t> all = plan.entries;
  all.insert(all.end(), plan.covered.begin(), plan.covered.end());
  plan_ = GpuBuffer::of(all);
}

void GpuFill::apply(const GpuBuffer& field, size_t offset, GpuPrecision type, std::optional<double> covered) const {
  if (empty()) return;
  const double bytes = double(realBytes(type));
  auto run = [&](const char* mode, int first, size_t n, double perElement) {
    if (n == 0) return;
    const ComputeProgram& p = useProgram("fill.comp", std::string("#define ") + mode, type);
    setUniform(p, "n", int(n));
    setUniform(p, "first", first);
    setUniform(p, "off", int(offset));
    setUniform(p, "stride", stride_);
    setUniform(p, "coveredValue", covered ? *covered : 0.0);
    field.bind(0);
    plan_.bind(1);
    dispatchFlat(n, perElement);
    storageBarrier();
  };
  if (covered) run("MODE_COVER", int(entries_), covered_, 4.0 + bytes);
  size_t begin = 0;
  for (size_t end : layerEnds_) {
    run("MODE_FILL", int(begin), end - begin, 4.0 * stride_ + bytes * (stride_ - 1));
    begin = end;
  }
}

}  // namespace morphoflow
