#include "gpu/fluid/gpu_smoke.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "fluid/smoke.h"
#include "gpu/compute_program.h"
#include "gpu/gpu_programs.h"

namespace morphoflow {

template <int D>
GpuSmoke<D>::GpuSmoke(const FluidSettings& settings, const VelocityConstraints<D>& vc, const GpuMacGrid<D>* grid,
                      GpuPrecision real)
    : settings_(settings), grid_(*grid), real_(real), solid_(vc.solid) {
  const size_t n = grid_.cellCount;
  temp_ = GpuBuffer::of(std::vector<float>(n, float(smoke().ambient)));
  tempScratch_ = GpuBuffer(n * sizeof(float));
  force_ = GpuBuffer(D * n * sizeof(float));
  centre_ = GpuBuffer(D * n * sizeof(float));
  omega_ = GpuBuffer((D == 2 ? 2 : 4) * n * sizeof(float));
  for (const Grid<float, D>& c : sourceCoverage<D>(smoke().sources, vc.cells, vc.h, vc.solid))
    cover_.push_back(GpuBuffer::of(c.values()));
}

template <int D>
void GpuSmoke<D>::run(SmokeOp mode, size_t n, int axis, const GpuBuffer& dye,
                      const std::function<void(const ComputeProgram&)>& uniforms) {
  const ComputeProgram& p = useProgram("smoke.comp", fmt::format("#define DIM {}\n#define {}", D, define(mode)), real_);
  setUniform(p, "cells", grid_.cells);
  setUniform(p, "periodic", grid_.periodic);
  setUniform(p, "velOff", grid_.velocityOffsets());
  setUniform(p, "axis", axis);
  setUniform(p, "n", int(n));
  uniforms(p);
  grid_.vel.bind(0);
  dye.bind(1);
  temp_.bind(2);
  force_.bind(4);
  centre_.bind(5);
  omega_.bind(6);
  dispatchFlat(n, 16.0);
  storageBarrier();
}

// (a moving source's cover computed on the host and uploaded)
template <int D>
void GpuSmoke<D>::emit(double time, double dt, GpuBuffer* dye) {
  const SmokeSettings& sm = smoke();
  for (size_t q = 0; q < sm.sources.size(); ++q) {
    const SmokeSource& src = sm.sources[q];
    const double on = std::min(time + dt, src.end) - std::max(time, src.start);
    if (!(on > 0.0)) continue;
    if (!src.motion.empty()) {
      IVec<D> cells;
      for (int a = 0; a < D; ++a) cells[a] = grid_.cells[size_t(a)];
      cover_[q].upload(sourceCover<D>(src, time + 0.5 * dt, cells, grid_.h, solid_).values());
    }
    cover_[q].bind(3);
    run(SmokeOp::Emit, grid_.cellCount, 0, *dye, [&](const ComputeProgram& p) {
      setUniform(p, "dRho", src.density * on);
      setUniform(p, "dT", src.temperature * on);
    });
    if (!src.inject) continue;
    for (int a = 0; a < D; ++a)
      run(SmokeOp::Inject, grid_.faces(a), a, *dye,
          [&](const ComputeProgram& p) { setUniform(p, "value", src.velocity[size_t(a)]); });
  }
}

// Buoyancy and confinement as cell-centred forces, then onto the faces.
template <int D>
void GpuSmoke<D>::forces(double dt, const GpuBuffer& dye) {
  const SmokeSettings& sm = smoke();
  const bool buoyant = sm.weight != 0.0 || sm.heat != 0.0;
  if (!buoyant && sm.vorticity == 0.0) return;
  force_.zero();
  if (buoyant)
    run(SmokeOp::Buoyancy, grid_.cellCount, 0, dye, [&](const ComputeProgram& p) {
      setUniform(p, "alpha", sm.weight);
      setUniform(p, "beta", sm.heat);
      setUniform(p, "ambient", sm.ambient);
      setUniformDoubles(p, "up", settings_.buoyancyDirection.data(), 1, 3);
    });
  if (sm.vorticity != 0.0) {
    auto hs = [&](const ComputeProgram& p) {
      setUniform(p, "h", grid_.h);
      setUniform(p, "s", sm.vorticity * grid_.h);
    };
    run(SmokeOp::Centre, grid_.cellCount, 0, dye, hs);
    run(SmokeOp::Vorticity, grid_.cellCount, 0, dye, hs);
    run(SmokeOp::Confine, grid_.cellCount, 0, dye, hs);
  }
  for (int a = 0; a < D; ++a)
    run(SmokeOp::AddFaces, grid_.faces(a), a, dye, [&](const ComputeProgram& p) { setUniform(p, "dt", dt); });
}

template <int D>
void GpuSmoke<D>::decay(double dt, GpuBuffer* dye) {
  const SmokeSettings& sm = smoke();
  if (sm.dissipation <= 0.0 && sm.cooling <= 0.0) return;
  run(SmokeOp::Decay, grid_.cellCount, 0, *dye, [&](const ComputeProgram& p) {
    setUniform(p, "keepRho", sm.dissipation > 0.0 ? std::exp(-sm.dissipation * dt) : 1.0);
    setUniform(p, "keepT", sm.cooling > 0.0 ? std::exp(-sm.cooling * dt) : 1.0);
    setUniform(p, "ambient", sm.ambient);
  });
}

template class GpuSmoke<2>;
template class GpuSmoke<3>;

}  // namespace morphoflow
