#include "gpu/fluid/gpu_mac_grid.h"

#include <algorithm>
#include <vector>

#include <fmt/format.h>

#include "gpu/compute_program.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

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
  open = GpuBuffer((cut ? faceCount : 1) * sizeof(float));  // (read for cut obstacles only)
  vel = GpuBuffer(faceCount * sizeof(float));
  velScratch = GpuBuffer(faceCount * sizeof(float));
  vel.zero();
  velScratch.zero();
  fixed = GpuBuffer(faceCount * sizeof(uint32_t));
  value = GpuBuffer(faceCount * sizeof(float));
  solid = GpuBuffer(cellCount * sizeof(uint32_t));
  if (vc.bodies.moving()) solidFlux = GpuBuffer(cellCount * sizeof(double));
  refresh(vc);
}

template <int D>
void GpuMacGrid<D>::refresh(const VelocityConstraints<D>& vc) {
  refresh(vc, IVec<D>(0), vc.cells);
}

// The rows that hold the faces of the cells [lo, hi), and those cells, uploaded again.
template <int D>
void GpuMacGrid<D>::refresh(const VelocityConstraints<D>& vc, const IVec<D>& lo, const IVec<D>& hi) {
  for (int a = 0; a < D; ++a) {
    const IVec<D>& fd = vc.fixed[a].dims();
    const auto [r0, r1] = rowSpan(rowsOf<D>(fd, lo, hi + unitVector<D>(a)));
    const size_t b = r0 * size_t(fd[0]), e = r1 * size_t(fd[0]), at = (off[size_t(a)] + b) * sizeof(float);
    const std::vector<uint8_t>& flags = vc.fixed[a].values();
    fixed.upload(std::vector<uint32_t>(flags.begin() + ptrdiff_t(b), flags.begin() + ptrdiff_t(e)), at);
    std::vector<float> v(e - b, 0.0f);  // the prescribed values (0 elsewhere)
    const std::vector<size_t>& held = vc.fixedFaces[size_t(a)];
    for (auto it = std::lower_bound(held.begin(), held.end(), b); it != held.end() && *it < e; ++it)
      v[*it - b] = vc.fixedValues[size_t(a)][size_t(it - held.begin())];
    value.upload(v, at);
    if (cut) open.upload(vc.open[a].expandedRows(r0, r1), at);
  }
  const auto [r0, r1] = rowSpan(rowsOf<D>(vc.cells, lo, hi));
  const size_t b = r0 * size_t(vc.cells[0]), e = r1 * size_t(vc.cells[0]);
  const std::vector<uint8_t>& s = vc.solid.values();
  solid.upload(std::vector<uint32_t>(s.begin() + ptrdiff_t(b), s.begin() + ptrdiff_t(e)), b * sizeof(uint32_t));
  if (solidFlux.bytes()) {
    if (vc.solidFlux.empty()) solidFlux.zero();
    else solidFlux.upload(vc.solidFlux.data() + b, (e - b) * sizeof(double), b * sizeof(double));
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
