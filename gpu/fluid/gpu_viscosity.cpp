#include "gpu/fluid/gpu_viscosity.h"

#include <vector>

#include "gpu/compute_program.h"
#include "gpu/gpu_laplace.h"
#include "gpu/gpu_pcg.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

// Component a's implicit viscous system: the host copy (its diagonal
// follows nu dt / h^2) and its boundary terms.
template <int D>
struct GpuViscosity<D>::Component {
  ViscousSystem<D> host;
  GpuBuffer boundaryRhs;
};

template <int D>
GpuViscosity<D>::GpuViscosity(const VelocityConstraints<D>& vc, GpuMacGrid<D>* grid, GpuPrecision real)
    : grid_(*grid), real_(real) {
  std::vector<const LaplaceSystem<D>*> blocks;
  for (int a = 0; a < D; ++a) {
    auto c = std::make_unique<Component>();
    c->host = viscousSystem<D>(vc, a);
    c->host.setRate(1.0);
    const std::vector<float> rhs = c->host.boundaryRhs.expanded();  // (the shader reads reals)
    c->boundaryRhs = realBuffer(std::vector<double>(rhs.begin(), rhs.end()), real_);
    blocks.push_back(&c->host.A);
    components_[size_t(a)] = std::move(c);
  }
  A_ = std::make_unique<GpuLaplace>(blocks);
  A_->setPrecision(real_);
  // (at least the cells: the pressure's solve shares them)
  work_ = std::make_shared<GpuPcgWork>(std::max(A_->size(), grid_.cellCount), real_);
  pcg_ = std::make_unique<GpuPcg>(*A_, work_);
  b_ = realBuffer(A_->size(), real_);
  x_ = realBuffer(A_->size(), real_);
  if (grid_.cut) {  // the viscosity holds the faces inside cut obstacles too
    std::vector<uint32_t> held;
    for (int a = 0; a < D; ++a) held.insert(held.end(), vc.fixed[a].values().begin(), vc.fixed[a].values().end());
    for (int a = 0; a < D; ++a) {
      const ViscousSystem<D>& V = components_[size_t(a)]->host;
      for (size_t i = 0; i < V.insideCut.size(); ++i)
        if (V.insideCut[i]) held[grid_.off[size_t(a)] + vc.fixed[a].index(latticeCoord<D>(V.dims, i))] = 1u;
    }
    held_ = GpuBuffer::of(held);
  }
}

template <int D>
GpuViscosity<D>::~GpuViscosity() = default;

template <int D>
std::shared_ptr<GpuPcgWork> GpuViscosity<D>::work() const {
  return work_;
}

template <int D>
void GpuViscosity<D>::run(FluidOp mode, int a, double s) {
  const Component& C = *components_[size_t(a)];
  std::array<int, 3> udims{1, 1, 1};
  for (int b = 0; b < D; ++b) udims[size_t(b)] = C.host.dims[b];
  const ComputeProgram& p = grid_.stage(mode, real_);
  setUniform(p, "cells", grid_.cells);
  setUniform(p, "axis", a);
  setUniform(p, "n", int(C.host.A.size()));
  setUniform(p, "udims", udims);
  setUniform(p, "velOff", grid_.velocityOffsets());
  setUniform(p, "s", s);
  setUniform(p, "blockOff", int(A_->blockStart(a)));
  grid_.vel.bind(0);
  (held_.bytes() ? held_ : grid_.fixed).bind(1);
  b_.bind(7);
  x_.bind(8);
  C.boundaryRhs.bind(9);
  dispatchFlat(C.host.A.size(), mode == FluidOp::ViscousSetup ? 32.0 : 16.0);
}

template <int D>
SolverResult GpuViscosity<D>::diffuse(double nu, double dt, double tolerance) {
  const double s = nu * dt / (grid_.h * grid_.h);
  for (int a = 0; a < D; ++a) {
    if (s != s_) {
      components_[size_t(a)]->host.setRate(s);
      A_->updateBlock(a, components_[size_t(a)]->host.A);
    }
    run(FluidOp::ViscousSetup, a, s);
  }
  storageBarrier();
  // The components as one block system, to the relative residual of the
  // whole velocity system (the CPU's: sum_a ||r_a||^2 <= tol^2 sum_a ||b_a||^2).
  const SolverResult r = pcg_->solve(&b_, &x_, nullptr, {tolerance, 500}, true);
  for (int a = 0; a < D; ++a) run(FluidOp::ViscousStore, a, s);
  storageBarrier();
  s_ = s;
  grid_.constrain(grid_.vel, real_);
  return r;
}

template <int D>
SolverResult GpuViscosity<D>::tally() {
  return pcg_->tally();
}

template class GpuViscosity<2>;
template class GpuViscosity<3>;

}  // namespace morphoflow
