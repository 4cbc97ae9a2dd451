#include "gpu/fluid/gpu_projection.h"

#include <algorithm>

#include "core/multigrid.h"
#include "fluid/pressure_projection.h"
#include "gpu/compute_program.h"
#include "gpu/gpu_laplace.h"
#include "gpu/gpu_multigrid.h"
#include "gpu/gpu_pcg.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

namespace {
// The cells without a pressure: 1, or 2 where they lie inside a solid (a moving one's phi is cleared there).
template <int D>
std::vector<uint32_t> inactiveCells(const LaplaceSystem<D>& P, const VelocityConstraints<D>& vc, size_t rowBegin,
                                    size_t rowEnd) {
  const std::vector<float> diag = P.diag.expandedRows(rowBegin, rowEnd);
  const size_t first = rowBegin * size_t(P.dims[0]);
  std::vector<uint32_t> inactive(diag.size());
  for (size_t i = 0; i < diag.size(); ++i) inactive[i] = diag[i] != 0.0f ? 0u : vc.solid[first + i] ? 2u : 1u;
  return inactive;
}
}  // namespace

template <int D>
GpuProjection<D>::GpuProjection(const VelocityConstraints<D>& vc, GpuMacGrid<D>* grid, GpuPrecision real,
                                std::shared_ptr<GpuPcgWork> work)
    : grid_(*grid), real_(real), P_(pressureSystem<D>(vc)) {
  // The CPU's system and multigrid levels (kept on the host to follow a moving obstacle).
  inactive_ = GpuBuffer::of(inactiveCells<D>(P_, vc, 0, P_.size() / size_t(P_.dims[0])));
  A_ = std::make_unique<GpuLaplace>(P_);
  A_->setPrecision(real_, kPhiPrecision);
  levels_ = std::make_unique<Multigrid<D>>(P_, kPressureCycle);
  multigrid_ = std::make_unique<GpuMultigrid>(*levels_, *A_, kPressureCycle);
  if (!vc.bodies.moving()) levels_.reset(), P_ = LaplaceSystem<D>();  // (at rest: uploaded once)
  pcg_ = std::make_unique<GpuPcg>(*A_, std::move(work));
  rhs_ = realBuffer(grid_.cellCount, real_);
  ratePrev_ = realBuffer(grid_.cellCount, GpuPrecision::Float);
  phi_ = realBuffer(grid_.cellCount, kPhiPrecision);
}

// As PressureProjection::rebuild: the system and its levels again, and no
// pressure in the cells the solid covers.
template <int D>
void GpuProjection<D>::rebuild(const VelocityConstraints<D>& vc, const IVec<D>& lo, const IVec<D>& hi) {
  updatePressureSystem<D>(&P_, vc, lo, hi);
  levels_->refresh(pressureRowsChanged(lo, vc.cells, -1), pressureRowsChanged(hi, vc.cells, 1));
  // The rows whose weights, c or diagonal can have changed (a margin of two cells), uploaded again.
  IVec<D> clo, chi;
  for (int a = 0; a < D; ++a) clo[a] = std::max(lo[a] - 2, 0), chi[a] = std::min(hi[a] + 2, vc.cells[a]);
  const auto [r0, r1] = rowSpan(rowsOf<D>(vc.cells, clo, chi));
  A_->update(P_, r0, r1);
  multigrid_->update(*levels_);
  inactive_.upload(inactiveCells<D>(P_, vc, r0, r1), r0 * size_t(vc.cells[0]) * sizeof(uint32_t));
  run(FluidOp::ClearPhi, 0, grid_.cellCount, 0.0);
}

template <int D>
GpuProjection<D>::~GpuProjection() = default;

template <int D>
void GpuProjection<D>::run(FluidOp mode, int axis, size_t n, double dt) {
  const bool cut = mode == FluidOp::Divergence && grid_.cut;  // (made for cut obstacles only)
  const bool flux = mode == FluidOp::Divergence && grid_.solidFlux.bytes();
  const ComputeProgram& p =
      grid_.stage(mode, real_, std::string(cut ? "\n#define CUT_FACES" : "") + (flux ? "\n#define SOLID_FLUX" : ""));
  setUniform(p, "cells", grid_.cells);
  setUniform(p, "periodic", grid_.periodic);
  setUniform(p, "axis", axis);
  setUniform(p, "n", int(n));
  setUniform(p, "velOff", grid_.velocityOffsets());
  setUniform(p, "invH", 1.0 / grid_.h);
  setUniform(p, "dt", dt);
  setUniform(p, "invLastDt", lastDt_ > 0 ? 1.0 / lastDt_ : 0.0);
  setUniform(p, "extrapolate", solves_ >= 2 ? 1 : 0);
  grid_.vel.bind(0);
  grid_.fixed.bind(1);
  (mode == FluidOp::Divergence ? rhs_ : phi_).bind(7);
  ratePrev_.bind(8);
  inactive_.bind(10);  // (the divergence's "solid": the cells without a pressure)
  grid_.open.bind(12);
  if (flux) grid_.solidFlux.bind(13);
  dispatchFlat(n, mode == FluidOp::Divergence ? 12.0 * D + 12.0 : 32.0);
  storageBarrier();
}

template <int D>
SolverResult GpuProjection<D>::project(double dt, const SolverOptions& options) {
  run(FluidOp::Divergence, 0, grid_.cellCount, dt);
  // Warm start: phi / dt extrapolated from the last two projections.
  if (solves_ >= 1 && lastDt_ > 0) run(FluidOp::WarmStart, 0, grid_.cellCount, dt);
  const SolverResult r = pcg_->solve(&rhs_, &phi_, multigrid_.get(), options, true);
  lastDt_ = dt;
  solves_ = dt > 0 ? std::min(solves_ + 1, 2) : 0;
  for (int a = 0; a < D; ++a) run(FluidOp::Gradient, a, grid_.faces(a), dt);
  grid_.constrain(grid_.vel, real_);
  return r;
}

template <int D>
SolverResult GpuProjection<D>::tally() {
  return pcg_->tally();
}

template <int D>
std::vector<double> GpuProjection<D>::phi() const {
  return readReals(phi_, grid_.cellCount, kPhiPrecision);
}

template <int D>
void GpuProjection<D>::save(StateWriter* out) const {
  out->putVector("gpu.fluid.phi", phi());
  out->putVector("gpu.fluid.rate_prev", readReals(ratePrev_, grid_.cellCount, GpuPrecision::Float));
  out->put("gpu.fluid.last_dt", lastDt_);
  out->put("gpu.fluid.solves", solves_);
}

template <int D>
void GpuProjection<D>::load(const StateReader& in) {
  std::vector<double> v(grid_.cellCount);
  in.getVector("gpu.fluid.phi", &v);
  uploadReals(&phi_, v, kPhiPrecision);
  in.getVector("gpu.fluid.rate_prev", &v);
  uploadReals(&ratePrev_, v, GpuPrecision::Float);
  in.get("gpu.fluid.last_dt", &lastDt_);
  in.get("gpu.fluid.solves", &solves_);
}

template class GpuProjection<2>;
template class GpuProjection<3>;

}  // namespace morphoflow
