#include "gpu/fluid/gpu_viscosity.h"

#include <algorithm>
#include <vector>

#include "gpu/compute_program.h"
#include "gpu/gpu_laplace.h"
#include "gpu/gpu_pcg.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

// Component a's implicit viscous system: the host copy (its diagonal
// follows nu dt / h^2), its boundary terms, the system on the device and its solve.
template <int D>
struct GpuViscosity<D>::Component {
  ViscousSystem<D> host;
  GpuBuffer boundaryRhs;
  std::unique_ptr<GpuLaplace> A;
  std::unique_ptr<GpuPcg> pcg;
};

template <int D>
GpuViscosity<D>::GpuViscosity(const VelocityConstraints<D>& vc, GpuMacGrid<D>* grid, GpuPrecision real)
    : grid_(*grid), real_(real) {
  size_t most = grid_.cellCount;  // (at least the cells: the pressure's solve shares the work vectors)
  for (int a = 0; a < D; ++a) {
    auto c = std::make_unique<Component>();
    c->host = viscousSystem<D>(vc, a);
    c->host.setRate(1.0);
    const std::vector<float> rhs = c->host.boundaryRhs.expanded();  // (the shader reads reals)
    c->boundaryRhs = realBuffer(std::vector<double>(rhs.begin(), rhs.end()), real_);
    c->A = std::make_unique<GpuLaplace>(c->host.A);
    c->A->setPrecision(real_);
    most = std::max(most, c->A->size());
    components_[size_t(a)] = std::move(c);
  }
  work_ = std::make_shared<GpuPcgWork>(most, real_);
  for (auto& c : components_) c->pcg = std::make_unique<GpuPcg>(*c->A, work_);
  b_ = realBuffer(most, real_);
  x_ = realBuffer(most, real_);
  if (grid_.cut) {  // the viscosity holds the faces inside cut obstacles too
    held_ = GpuBuffer(grid_.faceCount * sizeof(uint32_t));
    for (int a = 0; a < D; ++a) uploadHeld(vc, a, 0, vc.fixed[a].size() / size_t(vc.fixed[a].dims()[0]));
  }
}

// The faces of grid a's rows [rowBegin, rowEnd) that the viscous solves
// hold (the prescribed ones and those inside a cut obstacle), uploaded.
template <int D>
void GpuViscosity<D>::uploadHeld(const VelocityConstraints<D>& vc, int a, size_t rowBegin, size_t rowEnd) {
  const Grid<uint8_t, D>& fixed = vc.fixed[a];
  const ViscousSystem<D>& V = components_[size_t(a)]->host;
  const size_t nx = size_t(fixed.dims()[0]), first = rowBegin * nx;
  std::vector<uint32_t> held(fixed.values().begin() + ptrdiff_t(first),
                             fixed.values().begin() + ptrdiff_t(rowEnd * nx));
  if (!V.insideCut.empty())
    for (size_t j = 0; j < held.size(); ++j) {
      const IVec<D> k = fixed.coord(first + j);
      bool unknown = true;  // (not the duplicate layer a periodic axis drops)
      for (int b = 0; b < D; ++b) unknown = unknown && k[b] < V.dims[b];
      if (unknown && V.insideCut[V.A.c.index(k)]) held[j] = 1u;
    }
  held_.upload(held, (grid_.off[size_t(a)] + first) * sizeof(uint32_t));
}

// As ViscositySolver::rebuild: the rows of the faces of the cells [lo, hi)
// and of one more layer, and the held faces and boundary terms again; the
// rows that changed are uploaded, at the systems' rate (or whole at the
// next solve when there is none yet).
template <int D>
void GpuViscosity<D>::rebuild(const VelocityConstraints<D>& vc, const IVec<D>& lo, const IVec<D>& hi) {
  for (int a = 0; a < D; ++a) {
    Component& c = *components_[size_t(a)];
    IVec<D> ulo, uhi;
    updateViscousSystem<D>(&c.host, vc, a, lo, hi, &ulo, &uhi);
    // The unknowns' rows that changed, and one more layer (the diagonal reads the faces below).
    IVec<D> plo, phi;
    for (int b = 0; b < D; ++b) plo[b] = std::max(ulo[b] - 1, 0), phi[b] = std::min(uhi[b] + 1, c.host.dims[b]);
    const auto [r0, r1] = rowSpan(rowsOf<D>(c.host.dims, plo, phi));
    const std::vector<float> rhs = c.host.boundaryRhs.expandedRows(r0, r1);  // (the shader reads reals)
    uploadReals(&c.boundaryRhs, std::vector<double>(rhs.begin(), rhs.end()), real_, r0 * size_t(c.host.dims[0]));
    if (s_ > 0.0) {
      c.host.setRateRows(ulo, uhi);
      c.A->update(c.host.A, r0, r1);
    }
    if (held_.bytes()) {
      const IVec<D>& fd = vc.fixed[a].dims();
      IVec<D> flo, fhi;
      for (int b = 0; b < D; ++b) flo[b] = std::max(lo[b] - 1, 0), fhi[b] = std::min(hi[b] + 2, fd[b]);
      const auto [f0, f1] = rowSpan(rowsOf<D>(fd, flo, fhi));
      uploadHeld(vc, a, f0, f1);
    }
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
  // Each component to the relative residual `tolerance` (within the CPU's
  // budget for the whole velocity system, sum_a ||r_a||^2 <= tol^2 sum_a
  // ||b_a||^2, which lets a small component stop sooner).
  SolverResult r;
  r.converged = true;
  for (int a = 0; a < D; ++a) {
    Component& c = *components_[size_t(a)];
    if (s != s_) {
      c.host.setRate(s);
      c.A->update(c.host.A);
    }
    // A component without a schedule (its right-hand side 0 so far: the
    // cross-flow before the lid has moved it) takes the others'.
    for (const auto& other : components_) c.pcg->adoptSchedule(other->pcg->schedule());
    run(FluidOp::ViscousSetup, a, s);
    storageBarrier();
    foldWorst(&r, c.pcg->solve(&b_, &x_, nullptr, {tolerance, 500}, true));
    run(FluidOp::ViscousStore, a, s);
    storageBarrier();
  }
  s_ = s;
  grid_.constrain(grid_.vel, real_);
  return r;
}

template <int D>
SolverResult GpuViscosity<D>::tally() {
  std::vector<GpuPcg*> solves;
  for (auto& c : components_) solves.push_back(c->pcg.get());
  SolverResult r;
  r.converged = true;
  for (const SolverResult& c : GpuPcg::tally(solves)) foldWorst(&r, c);
  return r;
}

template class GpuViscosity<2>;
template class GpuViscosity<3>;

}  // namespace morphoflow
