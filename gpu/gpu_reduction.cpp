#include "gpu/gpu_reduction.h"

#include <algorithm>

#include <epoxy/gl.h>

#include "gpu/gpu_counts.h"
#include <fmt/format.h>

#include "gpu/compute_program.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

namespace {
constexpr size_t kGroups = 256;  // partial sums: a fixed count, so the sum's order is fixed
}

unsigned GpuReduction::groups(size_t n) { return unsigned(std::clamp<size_t>((n + 255) / 256, 1, kGroups)); }

GpuReduction::GpuReduction(GpuPrecision real)
    : real_(real), partial_(kSlots * kGroups * sizeof(double)), scalars_(kSlots * sizeof(double)) {
  partial_.zero();
  scalars_.zero();
}

void GpuReduction::run(const char* term, const GpuBuffer& x, const GpuBuffer& y, const GpuBuffer& diag, size_t n,
                       int slot, bool partialOnly) {
  const unsigned groups = GpuReduction::groups(n);
  const ComputeProgram& p = useProgram("reduce.comp", fmt::format("#define MODE_PARTIAL\n#define {}", term), real_);
  setUniform(p, "n", int(n));
  setUniform(p, "slot", slot);
  x.bind(0);
  y.bind(1);
  diag.bind(2);
  partial_.bind(3);
  scalars_.bind(4);
  x.bind(5);
  dispatchGroups(groups, 1);
  const std::string t = term;
  const double r = double(realBytes(real_));
  countGpuTraffic(double(n) * (t == "TERM_DOT" ? 2 * r : t == "TERM_ACTIVE_SUM" ? r + 4.0 : 4.0));
  storageBarrier();
  if (partialOnly) return;
  const ComputeProgram& f = useProgram("reduce.comp", std::string("#define MODE_FINAL\n#define ") + term, real_);
  setUniform(f, "n", int(groups));
  setUniform(f, "slot", slot);
  partial_.bind(3);
  scalars_.bind(4);
  dispatchGroups(1, 1);
  storageBarrier();
}

void GpuReduction::dot(const GpuBuffer& x, const GpuBuffer& y, size_t n, int slot) {
  run("TERM_DOT", x, y, x, n, slot);
}

void GpuReduction::activeSum(const GpuBuffer& x, const GpuBuffer& diag, size_t n, int slot, bool partialOnly) {
  run("TERM_ACTIVE_SUM", x, x, diag, n, slot, partialOnly);
}

void GpuReduction::activeCount(const GpuBuffer& diag, size_t n, int slot) {
  run("TERM_ACTIVE_COUNT", diag, diag, diag, n, slot);
}

void GpuReduction::maxAbs(const GpuBuffer& f, size_t n, int slot) { run("TERM_MAX_ABS", f, f, f, n, slot); }

std::vector<double> GpuReduction::read() const { return scalars_.read<double>(kSlots); }

}  // namespace morphoflow
