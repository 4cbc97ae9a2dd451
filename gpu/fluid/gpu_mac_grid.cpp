#include "gpu/fluid/gpu_mac_grid.h"

#include <algorithm>
#include <vector>

#include <fmt/format.h>

#include "gpu/compute_program.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

namespace {
// The constraints' per-face arrays, component after component: the fixed flags, values and open fractions.
template <int D>
void faceArrays(const VelocityConstraints<D>& vc, std::vector<uint32_t>* flags, std::vector<float>* values,
                std::vector<float>* fractions) {
  for (int a = 0; a < D; ++a) {
    flags->insert(flags->end(), vc.fixed[a].values().begin(), vc.fixed[a].values().end());
    const std::vector<float> v = vc.prescribedGrid(a), o = vc.open[a].expanded();
    values->insert(values->end(), v.begin(), v.end());
    fractions->insert(fractions->end(), o.begin(), o.end());
  }
}
}  // namespace

template <int D>
GpuMacGrid<D>::GpuMacGrid(const VelocityConstraints<D>& vc) : h(vc.h), cut(!vc.cut.empty() || vc.bodies.moving()) {
  cellCount = 1;
  for (int a = 0; a < D; ++a) {
    cells[size_t(a)] = vc.cells[a];
    periodic[size_t(a)] = vc.boundaries.periodic(a) ? 1 : 0;
    cellCount *= size_t(vc.cells[a]);
  }
  for (int a = 0; a < D; ++a) {
    off[size_t(a)] = faceCount;
    faceCount += faces(a);
    maxGrid = std::max(maxGrid, faces(a));
  }
  std::vector<uint32_t> flags;
  std::vector<float> values, fractions;
  faceArrays<D>(vc, &flags, &values, &fractions);
  open = cut ? GpuBuffer::of(fractions) : GpuBuffer(sizeof(float));  // (read for cut obstacles only)
  vel = GpuBuffer(faceCount * sizeof(float));
  velScratch = GpuBuffer(faceCount * sizeof(float));
  vel.zero();
  velScratch.zero();
  fixed = GpuBuffer::of(flags);
  value = GpuBuffer::of(values);
  solid = GpuBuffer::of(std::vector<uint32_t>(vc.solid.values().begin(), vc.solid.values().end()));
  if (vc.bodies.moving()) solidFlux = GpuBuffer(cellCount * sizeof(double));
  refresh(vc);
}

template <int D>
void GpuMacGrid<D>::refresh(const VelocityConstraints<D>& vc) {
  std::vector<uint32_t> flags;
  std::vector<float> values, fractions;
  faceArrays<D>(vc, &flags, &values, &fractions);
  fixed.upload(flags);
  value.upload(values);
  if (cut) open.upload(fractions);
  solid.upload(std::vector<uint32_t>(vc.solid.values().begin(), vc.solid.values().end()));
  if (solidFlux.bytes()) {
    if (vc.solidFlux.empty()) solidFlux.zero();
    else solidFlux.upload(vc.solidFlux);
  }
}

template <int D>
size_t GpuMacGrid<D>::faces(int a) const {
  size_t n = 1;
  for (int b = 0; b < D; ++b) n *= size_t(cells[size_t(b)] + (a == b ? 1 : 0));
  return n;
}

template <int D>
std::array<int, 3> GpuMacGrid<D>::velocityOffsets() const {
  return {int(off[0]), int(off[1]), int(off[2])};
}

template <int D>
const ComputeProgram& GpuMacGrid<D>::stage(FluidOp mode, GpuPrecision real, const std::string& more) const {
  return useProgram(shader(mode), fmt::format("#define DIM {}\n#define {}{}", D, define(mode), more), real,
                    kPhiPrecision);
}

template <int D>
void GpuMacGrid<D>::constrain(const GpuBuffer& u, GpuPrecision real) const {
  for (FluidOp mode : {FluidOp::Fixed, FluidOp::Periodic})
    for (int a = 0; a < D; ++a) {
      if (mode == FluidOp::Periodic && !periodic[size_t(a)]) continue;
      const ComputeProgram& p = stage(mode, real);
      setUniform(p, "cells", cells);
      setUniform(p, "axis", a);
      setUniform(p, "n", int(faces(a)));
      setUniform(p, "velOff", velocityOffsets());
      u.bind(0);
      fixed.bind(1);
      value.bind(2);
      dispatchFlat(faces(a), mode == FluidOp::Fixed ? 12.0 : 0.0);  // flag, value, u; (the periodic layer: none)
      storageBarrier();
    }
}

template struct GpuMacGrid<2>;
template struct GpuMacGrid<3>;

}  // namespace morphoflow
