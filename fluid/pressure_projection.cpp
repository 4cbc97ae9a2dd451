#include "fluid/pressure_projection.h"

#include <algorithm>

#include "core/masked_select.h"
#include "core/parallel.h"
#include "core/pcg.h"

namespace morphoflow {

namespace {
// kernels/projection.inc, shared with the GPU (kernels/README.md)
#define PP_FN inline double
#define PP_REAL double
#include "kernels/projection.inc"
#undef PP_FN
#undef PP_REAL
}  // namespace

namespace {
// Cell k's row of the pressure system: its upper faces' weights w[a] and
// its c. Each face weighs its open fraction (Batty et al. 2007 eq. 9): 1
// between two fluid cells, 0 at a staircase solid or inside a cut one, and
// beyond a non-periodic side of the domain (finalize's zeros, so that a
// system written a few rows at a time has them too).
template <int D>
void pressureCell(const VelocityConstraints<D>& vc, const IVec<D>& k, float* w, float* c) {
  const IVec<D>& n = vc.cells;
  const std::array<bool, D> periodic = vc.periodic();
  bool fluid = false;  // any open face: the cell holds fluid and a pressure
  for (int a = 0; a < D; ++a) {
    const IVec<D> up = k + unitVector<D>(a);  // the face between k and k + e_a
    const float below = vc.open[a](k);
    w[a] = vc.open[a](up);  // wraps on periodic axes
    fluid = fluid || w[a] > 0.0f || below > 0.0f;
    if (k[a] == n[a] - 1 && !periodic[size_t(a)]) w[a] = 0.0f;
  }
  *c = 0.0f;
  if (!fluid) return;
  for (int a = 0; a < D; ++a) {
    // p = 0 on an outflow side, through a ghost cell mirrored about the face.
    if (k[a] == 0 && vc.boundaries.side(a, false).kind == BoundaryKind::Outflow) *c += 2.0f * vc.open[a](k);
    if (k[a] == n[a] - 1 && vc.boundaries.side(a, true).kind == BoundaryKind::Outflow)
      *c += 2.0f * vc.open[a](k + unitVector<D>(a));
  }
}
}  // namespace

template <int D>
LaplaceSystem<D> pressureSystem(const VelocityConstraints<D>& vc) {
  LaplaceSystem<D> A(vc.cells, vc.periodic(), 1.0 / (vc.h * vc.h));
  forEachCell<D>(vc.cells, [&](const IVec<D>& k, size_t i) {
    float w[D], c;
    pressureCell<D>(vc, k, w, &c);
    for (int a = 0; a < D; ++a) A.w[a].at(i) = w[a];
    A.c.at(i) = c;
  });
  A.finalize();
  return A;
}
template LaplaceSystem<2> pressureSystem<2>(const VelocityConstraints<2>&);
template LaplaceSystem<3> pressureSystem<3>(const VelocityConstraints<3>&);

template <int D>
void updatePressureSystem(LaplaceSystem<D>* A, const VelocityConstraints<D>& vc, const IVec<D>& lo, const IVec<D>& hi) {
  // A cell's row reads the faces of its own and its neighbours' cells.
  const IVec<D> clo = pressureRowsChanged(lo, vc.cells, -1), chi = pressureRowsChanged(hi, vc.cells, 1);
  std::array<RowField<D>*, D + 1> fields;
  for (int a = 0; a < D; ++a) fields[size_t(a)] = &A->w[a];
  fields[D] = &A->c;
  rewriteRows<D, D + 1>(fields, rowsOf<D>(vc.cells, clo, chi), [&](size_t r, const std::array<float*, D + 1>& v) {
    IVec<D> k = latticeCoord<D>(vc.cells, r * size_t(vc.cells[0]));
    for (k[0] = clo[0]; k[0] < chi[0]; ++k[0]) {
      float w[D];
      pressureCell<D>(vc, k, w, &v[D][k[0]]);
      for (int a = 0; a < D; ++a) v[size_t(a)][k[0]] = w[a];
    }
  });
  A->finalizeRows(clo, chi);
}
template void updatePressureSystem<2>(LaplaceSystem<2>*, const VelocityConstraints<2>&, const IVec<2>&, const IVec<2>&);
template void updatePressureSystem<3>(LaplaceSystem<3>*, const VelocityConstraints<3>&, const IVec<3>&, const IVec<3>&);

template <int D>
PressureProjection<D>::PressureProjection(const VelocityConstraints<D>& vc, PressureSolver solver,
                                          const SolverOptions& options)
    : vc_(vc), solver_(solver), options_(options), A_(pressureSystem(vc)) {
  if (solver_ == PressureSolver::ICPCG)
    mic_ = std::make_unique<MIC0Preconditioner<D>>(A_);
  else multigrid_ = std::make_unique<Multigrid<D>>(A_, kPressureCycle);
  phi_.assign(A_.size(), 0.0);
}

template <int D>
void PressureProjection<D>::rebuild(const IVec<D>& lo, const IVec<D>& hi) {
  updatePressureSystem<D>(&A_, vc_, lo, hi);  // (same shape: the multigrid refers to A_)
  // The rows written; the next warm start is relaxed over them (project()), as the viscosity's.
  movedLo_ = pressureRowsChanged(lo, vc_.cells, -1);
  movedHi_ = pressureRowsChanged(hi, vc_.cells, 1);
  if (solver_ == PressureSolver::ICPCG) mic_ = std::make_unique<MIC0Preconditioner<D>>(A_);
  else multigrid_->refresh(movedLo_, movedHi_);
  // Cells the solid covers hold no pressure (those it covered before hold none already).
  if (!phi_.empty())
    for (size_t row : rowsOf<D>(vc_.cells, lo, hi))
      for (int x = lo[0]; x < hi[0]; ++x) {
        const size_t i = row * size_t(vc_.cells[0]) + size_t(x);
        if (vc_.solid[i] && A_.diag[i] == 0.0f) phi_[i] = 0.0;
      }
}

template <int D>
void PressureProjection<D>::divergence(const MacVelocity<D>& u, Vector* div) const {
  divergenceTimes(u, 1.0 / vc_.h, div);
}

template <int D>
void PressureProjection<D>::divergenceTimes(const MacVelocity<D>& u, double factor, Vector* div) const {
  div->resize(A_.size());
  const IVec<D>& n = vc_.cells;
  const size_t nx = size_t(n[0]);
  // Row by row: cell (x, row) has faces x and x + 1 of u_0's row and, along
  // each other axis a, the faces of u_a's rows k_a and k_a + 1.
  parallelForRows<D>(n, [&](size_t row) {
    size_t k[3] = {0, 0, 0}, rest = row;
    for (int a = 1; a < D; ++a) {
      k[a] = rest % size_t(n[a]);
      rest /= size_t(n[a]);
    }
    const float* lo[D];
    const float* hi[D];
    const float* openLo[D];  // the faces' open fractions (Batty et al. 2007: the flux through the fluid part)
    const float* openHi[D];
    lo[0] = u[0].data() + row * (nx + 1);
    hi[0] = lo[0] + 1;
    openLo[0] = vc_.open[0].row(row);
    openHi[0] = openLo[0] + 1;
    for (int a = 1; a < D; ++a) {
      // u_a's grid has n_a + 1 layers along a: its row index of (k_1, k_2).
      size_t r = 0;
      for (int b = D - 1; b >= 1; --b) r = r * size_t(n[b] + (b == a ? 1 : 0)) + k[b];
      const size_t layer = a == 1 ? 1 : size_t(n[1]);  // rows between layers k_a and k_a + 1
      lo[a] = u[a].data() + r * nx;
      hi[a] = lo[a] + layer * nx;
      openLo[a] = vc_.open[a].row(r);
      openHi[a] = vc_.open[a].row(r + layer);
    }
    const float* active = A_.diag.row(row);
    double* out = div->data() + row * nx;
    for (size_t x = 0; x < nx; ++x) {
      double d = 0.0;
      for (int a = 0; a < D; ++a)
        d += ppAxisFlux(double(openHi[a][x]), double(hi[a][x]), double(openLo[a][x]), double(lo[a][x]));
      out[x] = zeroWhere(active[x] == 0.0f, d * factor);
    }
    if (!vc_.solidFlux.empty()) {  // a moving solid's flux through the closed parts
      const double* solid = vc_.solidFlux.data() + row * nx;
      for (size_t x = 0; x < nx; ++x) out[x] += zeroWhere(active[x] == 0.0f, solid[x] * factor);
    }
  });
}

template <int D>
SolverResult PressureProjection<D>::project(MacVelocity<D>* u, double dt, double density, WorkPool* pool) {
  PcgWorkspace& w = workspace_;
  const std::initializer_list<Vector*> work = {&w.b, &w.p, &w.q};  // r: b's storage (regenerate)
  if (pool) {
    pool->lend(work);
    if (multigrid_) multigrid_->borrowFine(pool);
  }
  divergenceTimes(*u, -1.0 / vc_.h, &workspace_.b);  // rhs = -div u
  // Warm start: phi / dt (the pressure over the density) linearly
  // extrapolated from the last two projections, times this dt; after one
  // projection, the last phi scaled to this dt.
  if (solves_ >= 1 && lastDt_ > 0) {
    const double inv = 1.0 / lastDt_;
    const bool extrapolate = solves_ >= 2;
    ratePrev_.resize(phi_.size());
    parallelFor(phi_.size(), [&](size_t i) {
      const double rate = phi_[i] * inv;
      phi_[i] = ppWarmStart(rate, double(ratePrev_[i]), dt, extrapolate);
      ratePrev_[i] = float(rate);
    }, 4096);
  }
  // The warm start comes from solves before a moving obstacle rewrote the
  // rows [movedLo_, movedHi_), and its error there is the larger part of
  // the solve's (the body's cut cells hold nearly all of its residual):
  // red-black SOR sweeps over those rows first (docs/performance.md).
  if (solves_ >= 1) A_.relaxBox(workspace_.b, &phi_, movedLo_, movedHi_, relaxation_.sweeps, relaxation_.omega);
  movedLo_ = movedHi_ = IVec<D>(0);
  w.regenerate = [&](Vector* b) { divergenceTimes(*u, -1.0 / vc_.h, b); };
  SolverResult r;
  if (solver_ == PressureSolver::Multigrid)
    r = multigrid_->solve(workspace_.b, &phi_, options_);
  else
    r = solvePCG<D>(A_, workspace_.b, &phi_, solver_ == PressureSolver::ICPCG
                                          ? static_cast<Preconditioner*>(mic_.get())
                                          : static_cast<Preconditioner*>(multigrid_.get()),
                    options_, &workspace_);
  w.regenerate = nullptr;
  if (pool) {
    pool->give(work);
    pool->give(&w.r);
    if (multigrid_) multigrid_->giveBackFine(pool);
  }
  lastDt_ = dt;
  lastDensity_ = density;
  solves_ = dt > 0 ? std::min(solves_ + 1, 2) : 0;
  // u -= grad(phi) on every face that is not prescribed.
  const double invH = 1.0 / vc_.h;
  const IVec<D>& n = vc_.cells;
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    const Grid<uint8_t, D>& fixed = vc_.fixed[a];
    const bool periodic = vc_.boundaries.periodic(a);
    auto update = [&](const IVec<D>& k, size_t i) {
      if (fixed[i]) return;
      IVec<D> lo = k - unitVector<D>(a), hi = k;
      if (periodic) {
        if (lo[a] < 0) lo[a] += n[a];
        if (hi[a] >= n[a]) hi[a] -= n[a];
      }
      double pl, ph;
      if (lo[a] < 0) {  // outflow on the low side: ghost phi = -phi
        ph = phi_[A_.diag.index(hi)];
        pl = -ph;
      } else if (hi[a] >= n[a]) {
        pl = phi_[A_.diag.index(lo)];
        ph = -pl;
      } else {
        pl = phi_[A_.diag.index(lo)];
        ph = phi_[A_.diag.index(hi)];
      }
      g[i] = float(ppProjectedFace(double(g[i]), pl, ph, invH));
    };
    // Rows of faces between two cells inside the domain take their cells'
    // phi from two rows of cells (one row shifted by one along x); the
    // faces on the domain's sides (wrapped or mirrored) take update().
    const IVec<D> gd = g.dims();
    parallelForRows<D>(gd, [&](size_t row) {
      IVec<D> k(0);
      size_t rest = row, cellRow = 0, stride = 1;
      for (int b = 1; b < D; ++b) {
        k[b] = int(rest % size_t(gd[b]));
        rest /= size_t(gd[b]);
      }
      for (int b = D - 1; b >= 1; --b) cellRow = cellRow * size_t(n[b]) + size_t(std::min(k[b], n[b] - 1));
      for (int b = 1; b <= a; ++b) stride *= size_t(n[b - 1]);
      const size_t base = row * size_t(gd[0]);
      if (a > 0 && (k[a] == 0 || k[a] == n[a])) {
        for (int x = 0; x < gd[0]; ++x) {
          k[0] = x;
          update(k, base + size_t(x));
        }
        return;
      }
      const size_t nx = size_t(n[0]);
      const double* ph = phi_.data() + cellRow * nx;  // the cell at or after each face
      const double* pl = ph - stride;                 // the cell before it along a
      float* gr = g.data() + base;
      const uint8_t* fr = fixed.data() + base;
      const int x0 = a == 0 ? 1 : 0, x1 = n[0];
      for (int x = x0; x < x1; ++x)
        gr[x] = pick(fr[x], gr[x], float(ppProjectedFace(double(gr[x]), pl[x], ph[x], invH)));
      for (int x : {0, gd[0] - 1})
        if (x < x0 || x >= x1) {
          k[0] = x;
          update(k, base + size_t(x));
        }
    });
  }
  vc_.apply(u);
  return r;
}

template <int D>
void PressureProjection<D>::adopt(const Vector& phi, double dt, double density) {
  phi_ = phi;
  lastDt_ = dt;
  lastDensity_ = density;
}

template <int D>
Grid<float, D> PressureProjection<D>::pressure() const {
  Grid<float, D> p(vc_.cells, 0.0f);
  if (lastDt_ <= 0) return p;
  const double s = lastDensity_ / lastDt_;
  parallelFor(p.size(), [&](size_t i) { p[i] = float(phi_[i] * s); }, 4096);
  return p;
}

template <int D>
void PressureProjection<D>::save(StateWriter* out) const {
  out->putVector("pressure.phi", phi_);
  out->put("pressure.rate_prev_size", ratePrev_.size());
  out->putVector("pressure.rate_prev", ratePrev_);
  out->put("pressure.last_dt", lastDt_);
  out->put("pressure.last_density", lastDensity_);
  out->put("pressure.solves", solves_);
}

template <int D>
void PressureProjection<D>::load(const StateReader& in) {
  in.getVector("pressure.phi", &phi_);
  size_t n = 0;
  in.get("pressure.rate_prev_size", &n);
  ratePrev_.resize(n == 0 ? 0 : phi_.size());
  in.getVector("pressure.rate_prev", &ratePrev_);
  in.get("pressure.last_dt", &lastDt_);
  in.get("pressure.last_density", &lastDensity_);
  in.get("pressure.solves", &solves_);
  // The checkpoint's run relaxed its rows at its last projection: the
  // obstacles placed again for the load rewrote none of its next step's.
  movedLo_ = movedHi_ = IVec<D>(0);
}

template class PressureProjection<2>;
template class PressureProjection<3>;

}  // namespace morphoflow
