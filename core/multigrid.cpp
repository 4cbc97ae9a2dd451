#include "core/multigrid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/parallel.h"
#include "core/simd4.h"

namespace morphoflow {

namespace {

// Weight of coarse index I in the prolongation of fine index i along one axis.
inline double prolongWeight1(int i, int I, int nCoarse, bool periodic) {
  int parent = i >> 1;
  int nb = (i & 1) ? parent + 1 : parent - 1;
  bool nbValid = true;
  if (nb < 0 || nb >= nCoarse) {
    if (periodic)
      nb = (nb + nCoarse) % nCoarse;
    else
      nbValid = false;
  }
  if (!nbValid) return I == parent ? 1.0 : 0.0;
  if (nb == parent) return I == parent ? 1.0 : 0.0;
  if (I == parent) return 0.75;
  if (I == nb) return 0.25;
  return 0.0;
}

template <int D>
bool canCoarsen(const LaplaceSystem<D>& A, int minCells) {
  for (int a = 0; a < D; ++a) {
    if ((A.dims[a] + 1) / 2 < minCells) return false;
    if (A.periodic[a] && A.dims[a] % 2 != 0) return false;
  }
  return true;
}

// Coarse cell cc of the re-discretisation of F: its identity term (the
// Galerkin mean, scaled: the coarse scale is the fine one / 4) and its faces'
// weights (the face between cc and cc + e_a: the mean of the 2^(D-1) fine
// faces at fine index 2 cc_a + 1).
template <int D>
void coarsenCell(const LaplaceSystem<D>& F, const IVec<D>& cc, float* c, float* w) {
  double csum = 0.0;
  for (int k = 0; k < (1 << D); ++k) {
    IVec<D> f;
    bool inside = true;
    for (int a = 0; a < D; ++a) {
      f[a] = 2 * cc[a] + ((k >> a) & 1);
      inside &= f[a] < F.dims[a];
    }
    if (inside) csum += F.c(f);
  }
  *c = float(4.0 * csum * (1.0 / double(1 << D)));
  for (int a = 0; a < D; ++a) {
    double wsum = 0.0;
    int count = 0;
    for (int k = 0; k < (1 << D); ++k) {
      if ((k >> a) & 1) continue;
      IVec<D> f;
      bool inside = true;
      for (int b = 0; b < D; ++b) {
        f[b] = b == a ? 2 * cc[a] + 1 : 2 * cc[b] + ((k >> b) & 1);
        inside &= f[b] < F.dims[b];
      }
      ++count;
      if (inside) wsum += F.w[a](f);
    }
    w[a] = float(wsum / count);
  }
}

// The coarse re-discretisation of F into C (already shaped (F.dims + 1) / 2).
template <int D>
void coarsenInto(const LaplaceSystem<D>& F, LaplaceSystem<D>* Cp) {
  LaplaceSystem<D>& C = *Cp;
  const IVec<D> cd = C.dims;
  C.scale = F.scale / 4.0;
  C.c = RowField<D>(cd, 0.0f);
  for (int a = 0; a < D; ++a) C.w[a] = RowField<D>(cd, 0.0f);
  forEachCell<D>(cd, [&](const IVec<D>& cc, size_t ci) {
    float w[D];
    coarsenCell<D>(F, cc, &C.c.at(ci), w);
    for (int a = 0; a < D; ++a) C.w[a].at(ci) = w[a];
  });
  C.finalize();
}

// The coarse cells [clo, chi) of C derived again from F (C derived from F
// before; F's coefficients changed only in the fine cells these cover).
// The rows stay compact, and the couplings across a non-periodic edge are
// zeroed here, as finalize() zeroes a dense field's.
template <int D>
void coarsenRegion(const LaplaceSystem<D>& F, LaplaceSystem<D>* Cp, const IVec<D>& clo, const IVec<D>& chi) {
  LaplaceSystem<D>& C = *Cp;
  std::array<RowField<D>*, D + 1> fields;
  for (int a = 0; a < D; ++a) fields[size_t(a)] = &C.w[a];
  fields[D] = &C.c;
  rewriteRows<D, D + 1>(fields, rowsOf<D>(C.dims, clo, chi), [&](size_t r, const std::array<float*, D + 1>& v) {
    IVec<D> k = latticeCoord<D>(C.dims, r * size_t(C.dims[0]));
    for (k[0] = clo[0]; k[0] < chi[0]; ++k[0]) {
      float w[D];
      coarsenCell<D>(F, k, &v[D][k[0]], w);
      for (int a = 0; a < D; ++a) v[size_t(a)][k[0]] = k[a] == C.dims[a] - 1 && !C.periodic[a] ? 0.0f : w[a];
    }
  });
  C.finalizeRows(clo, chi);
}

template <int D>
LaplaceSystem<D> coarsen(const LaplaceSystem<D>& F) {
  IVec<D> cd;
  for (int a = 0; a < D; ++a) cd[a] = (F.dims[a] + 1) / 2;
  LaplaceSystem<D> C(cd, F.periodic, F.scale / 4.0);
  coarsenInto(F, &C);
  return C;
}

}  // namespace

template <int D>
Multigrid<D>::Multigrid(const LaplaceSystem<D>& fine, const MultigridOptions& options)
    : fine_(fine), options_(options) {
  levels_.emplace_back();
  const LaplaceSystem<D>* cur = &fine_;
  while (canCoarsen(*cur, options_.minCoarseCells)) {
    Level next;
    next.A = coarsen(*cur);
    levels_.push_back(std::move(next));
    cur = &levels_.back().A;
  }
  for (size_t l = 0; l + 1 < levels_.size(); ++l) buildTransfer(int(l));
  findBands();
  // The levels' vectors: level 0's at the first cycle (ensureFine), the
  // coarse levels' placed for each (placeCoarse).
}

template <int D>
void Multigrid<D>::ensureFine() {
  const size_t n = fine_.size();
  for (FVector* v : {&fineX_, &fineB_, &fineR_})
    if (v->size() != n) v->assign(n, 0.0f);
  Level& L0 = levels_[0];
  L0.x = fineX_.data(), L0.b = fineB_.data(), L0.r = fineR_.data();
}

template <int D>
void Multigrid<D>::borrowFine(WorkPool* pool) {
  pool->lend({&fineX_, &fineB_, &fineR_});
  for (FVector* v : {&fineX_, &fineB_, &fineR_}) v->clear();  // ensureFine() zeroes them, as on first use
  ensureFine();
}

template <int D>
void Multigrid<D>::giveBackFine(WorkPool* pool) {
  pool->give({&fineX_, &fineB_, &fineR_});
}

namespace {
constexpr size_t padded(size_t n) { return (n + 15) / 16 * 16; }  // floats, to 64 bytes
}  // namespace

template <int D>
size_t Multigrid<D>::coarseFloats() const {
  size_t n = 0;
  for (int l = 1; l < levels(); ++l) n += 3 * padded(level(l).size());
  return n;
}

template <int D>
void Multigrid<D>::placeCoarse() {
  const size_t need = coarseFloats();
  inScratch_ = need > 0 && need <= 2 * scratch_.size();
  float* f = nullptr;
  if (inScratch_) {
    // The lent doubles' bytes hold floats now: their lifetime begins here,
    // the doubles' ends (both trivial: no code); releaseCoarse() restores them.
    f = ::new (static_cast<void*>(scratch_.data())) float[2 * scratch_.size()];
  } else {
    if (coarse_.size() != need) coarse_.assign(need, 0.0f);
    f = coarse_.data();
  }
  for (int l = 1; l < levels(); ++l) {
    const size_t n = padded(level(l).size());
    Level& L = levels_[size_t(l)];
    L.x = f, L.b = f + n, L.r = f + 2 * n;
    f += 3 * n;
  }
}

template <int D>
void Multigrid<D>::releaseCoarse() {
  if (inScratch_) ::new (static_cast<void*>(scratch_.data())) double[scratch_.size()];
  inScratch_ = false;
}

template <int D>
void Multigrid<D>::refresh() {
  for (size_t l = 1; l < levels_.size(); ++l) coarsenInto(level(int(l) - 1), &levels_[l].A);
  findBands();
}

template <int D>
void Multigrid<D>::findBands() {
  for (size_t l = 0; l < levels_.size(); ++l) {
    const LaplaceSystem<D>& A = level(int(l));
    const bool smoothed = options_.bandSweeps > 0 && l + 1 < levels_.size() && A.size() > options_.bandMinCells;
    levels_[l].band = smoothed ? boundaryBand<D>(A, options_.bandWidth, &bandMarks_) : BoundaryBand<D>{};
  }
}

template <int D>
void Multigrid<D>::refresh(IVec<D> lo, IVec<D> hi) {
  for (size_t l = 1; l < levels_.size(); ++l) {
    const LaplaceSystem<D>& C = levels_[l].A;
    for (int a = 0; a < D; ++a) {  // coarse cell K covers fine cells 2K and 2K + 1
      lo[a] = std::clamp(lo[a] / 2, 0, C.dims[a]);
      hi[a] = std::clamp((hi[a] + 1) / 2, lo[a], C.dims[a]);
    }
    coarsenRegion(level(int(l) - 1), &levels_[l].A, lo, hi);
  }
  findBands();
}

template <int D>
void Multigrid<D>::buildTransfer(int l) {
  const LaplaceSystem<D>& F = level(l);
  const LaplaceSystem<D>& C = level(l + 1);
  for (int a = 0; a < D; ++a) {
    AxisTransfer& t = levels_[size_t(l)].transfer[size_t(a)];
    int nf = F.dims[a], nc = C.dims[a];
    t.lo.assign(size_t(nf), 0);
    t.hi.assign(size_t(nf), 0);
    t.w.assign(size_t(nf), 1.0f);
    for (int f = 0; f < nf; ++f) {
      int parent = f >> 1;
      int nb = (f & 1) ? parent + 1 : parent - 1;
      if (nb < 0 || nb >= nc) nb = C.periodic[a] ? (nb + nc) % nc : parent;
      t.lo[size_t(f)] = parent;
      t.hi[size_t(f)] = nb;
      t.w[size_t(f)] = nb == parent ? 1.0f : 0.75f;
    }
    t.fine.assign(size_t(nc), {0, 0, 0, 0});
    t.fineWeight.assign(size_t(nc), {0.0f, 0.0f, 0.0f, 0.0f});
    for (int I = 0; I < nc; ++I)
      for (int m = 0; m < 4; ++m) {
        int f = 2 * I - 1 + m;
        if (f < 0 || f >= nf) {
          if (!F.periodic[a]) continue;
          f = (f + nf) % nf;
        }
        t.fine[size_t(I)][size_t(m)] = f;
        t.fineWeight[size_t(I)][size_t(m)] = float(prolongWeight1(f, I, nc, C.periodic[a]));
      }
    // The longest runs of the interior pattern (the tables' other entries stay in use).
    auto restrictStd = [&](int X) {
      const std::array<int, 4> f{2 * X - 1, 2 * X, 2 * X + 1, 2 * X + 2};
      const std::array<float, 4> w{0.25f, 0.75f, 0.75f, 0.25f};
      return t.fine[size_t(X)] == f && t.fineWeight[size_t(X)] == w;
    };
    auto prolongStd = [&](int X) {
      const size_t e = size_t(2 * X), o = e + 1;
      return X >= 1 && int(o) < nf && t.lo[e] == X && t.hi[e] == X - 1 && t.w[e] == 0.75f && t.lo[o] == X &&
             t.hi[o] == X + 1 && t.w[o] == 0.75f;
    };
    auto run = [&](auto&& standard, int* lo, int* hi) {
      int bestLo = 0, bestHi = 0;
      for (int X = 0; X < nc;) {
        if (!standard(X)) { ++X; continue; }
        int e = X;
        while (e < nc && standard(e)) ++e;
        if (e - X > bestHi - bestLo) bestLo = X, bestHi = e;
        X = e;
      }
      *lo = bestLo, *hi = bestHi;
    };
    run(restrictStd, &t.restrictLo, &t.restrictHi);
    run(prolongStd, &t.prolongLo, &t.prolongHi);
  }
}

// Row r of a lattice -> its coordinates along axes 1.. (index 0 unused).
template <int D>
inline void rowCoords(const IVec<D>& dims, size_t row, int* c) {
  c[0] = 0;
  for (int a = 1; a < D; ++a) {
    c[a] = int(row % size_t(dims[a]));
    row /= size_t(dims[a]);
  }
}

template <int D>
void Multigrid<D>::restrict(int l) {
  const LaplaceSystem<D>& F = level(l);
  const LaplaceSystem<D>& C = level(l + 1);
  const std::array<AxisTransfer, D>& T = levels_[size_t(l)].transfer;
  const float* r = levels_[size_t(l)].r;
  float* b = levels_[size_t(l) + 1].b;
  const float inv2D = 1.0f / float(1 << D);
  const size_t ncx = size_t(C.dims[0]), nfx = size_t(F.dims[0]);
  const size_t nfy = size_t(F.dims[1]);
  parallelForRows<D>(C.dims, [&](size_t row) {
    int cc[3];
    rowCoords<D>(C.dims, row, cc);
    // Restriction is separable: first the (up to) 4^(D-1) fine rows that
    // touch this coarse row, summed with their y (and z) weights along the
    // whole fine row, then the x stencil once on that sum.
    thread_local std::vector<float> combined;
    combined.resize(nfx);
    float* __restrict cy = combined.data();
    bool any = false;
    for (int mz = 0; mz < (D == 3 ? 4 : 1); ++mz) {
      float wz = 1.0f;
      size_t fz = 0;
      if constexpr (D == 3) {
        wz = T[2].fineWeight[size_t(cc[2])][size_t(mz)];
        fz = size_t(T[2].fine[size_t(cc[2])][size_t(mz)]);
        if (wz == 0.0f) continue;
      }
      for (int my = 0; my < 4; ++my) {
        const float wy = wz * T[1].fineWeight[size_t(cc[1])][size_t(my)];
        if (wy == 0.0f) continue;
        const float* __restrict fr = r + (fz * nfy + size_t(T[1].fine[size_t(cc[1])][size_t(my)])) * nfx;
        if (any)
          for (size_t i = 0; i < nfx; ++i) cy[i] += wy * fr[i];
        else
          for (size_t i = 0; i < nfx; ++i) cy[i] = wy * fr[i];
        any = true;
      }
    }
    if (!any) std::fill_n(cy, nfx, 0.0f);
    float* __restrict br = b + row * ncx;
    auto table = [&](size_t X) {
      const std::array<int, 4>& fx = T[0].fine[X];
      const std::array<float, 4>& wx = T[0].fineWeight[X];
      br[X] = wx[0] * cy[fx[0]] + wx[1] * cy[fx[1]] + wx[2] * cy[fx[2]] + wx[3] * cy[fx[3]];
    };
    const size_t lo = size_t(T[0].restrictLo), hi = size_t(T[0].restrictHi);
    for (size_t X = 0; X < lo; ++X) table(X);
    for (size_t X = lo; X < hi; ++X)  // the same sum without the tables
      br[X] = 0.25f * cy[2 * X - 1] + 0.75f * cy[2 * X] + 0.75f * cy[2 * X + 1] + 0.25f * cy[2 * X + 2];
    for (size_t X = hi; X < ncx; ++X) table(X);
    const float* cd = C.diag.row(row);
    for (size_t X = 0; X < ncx; ++X) br[X] = cd[X] > 0 ? br[X] * inv2D : 0.0f;
  });
}

template <int D>
void Multigrid<D>::prolongAdd(int l) {
  const LaplaceSystem<D>& F = level(l);
  const LaplaceSystem<D>& C = level(l + 1);
  const std::array<AxisTransfer, D>& T = levels_[size_t(l)].transfer;
  const float* xc = levels_[size_t(l) + 1].x;
  float* x = levels_[size_t(l)].x;
  const size_t ncx = size_t(C.dims[0]), nfx = size_t(F.dims[0]);
  const size_t ncy = size_t(C.dims[1]);
  parallelForRows<D>(F.dims, [&](size_t row) {
    int f[3];
    rowCoords<D>(F.dims, row, f);
    // The (up to) 2^(D-1) coarse rows and weights of this fine row.
    const float* crow[4];
    float cw[4];
    int nrows = 0;
    for (int kz = 0; kz < (D == 3 ? 2 : 1); ++kz) {
      float wz = 1.0f;
      size_t z = 0;
      if constexpr (D == 3) {
        size_t fz = size_t(f[2]);
        wz = kz ? 1.0f - T[2].w[fz] : T[2].w[fz];
        z = size_t(kz ? T[2].hi[fz] : T[2].lo[fz]);
        if (wz == 0.0f) continue;
      }
      for (int ky = 0; ky < 2; ++ky) {
        size_t fy = size_t(f[1]);
        float wy = wz * (ky ? 1.0f - T[1].w[fy] : T[1].w[fy]);
        if (wy == 0.0f) continue;
        size_t y = size_t(ky ? T[1].hi[fy] : T[1].lo[fy]);
        crow[nrows] = xc + (z * ncy + y) * ncx;
        cw[nrows++] = wy;
      }
    }
    // The coarse rows combined first (bilinear/trilinear is separable), then
    // interpolated along x.
    thread_local std::vector<float> combined;
    combined.resize(ncx);
    float* cy = combined.data();
    for (size_t X = 0; X < ncx; ++X) cy[X] = cw[0] * crow[0][X];
    for (int k = 1; k < nrows; ++k)
      for (size_t X = 0; X < ncx; ++X) cy[X] += cw[k] * crow[k][X];
    const float* fd = F.diag.row(row);
    float* xr = x + row * nfx;
    const int* lo = T[0].lo.data();
    const int* hi = T[0].hi.data();
    const float* wx = T[0].w.data();
    auto table = [&](size_t i) {
      if (fd[i] > 0) xr[i] += wx[i] * cy[lo[i]] + (1.0f - wx[i]) * cy[hi[i]];
    };
    const size_t fastLo = 2 * size_t(T[0].prolongLo), fastHi = 2 * size_t(T[0].prolongHi);
    for (size_t i = 0; i < fastLo; ++i) table(i);
    // Fine 2X and 2X + 1 from coarse X (3/4) and X -+ 1 (1/4), without the
    // tables: four coarse cells at a time (the scalar loop's arithmetic per
    // lane, interleaved into eight fine cells; masked where the diagonal is 0).
    size_t X0 = fastLo / 2;
    for (; X0 + 4 <= fastHi / 2; X0 += 4) {
      const vf4 c = load4(cy + X0);
      const vf4 ve = 0.75f * c + 0.25f * load4(cy + X0 - 1), vo = 0.75f * c + 0.25f * load4(cy + X0 + 1);
      float* out = xr + 2 * X0;
      const float* d = fd + 2 * X0;
      const vf4 a = MF_SHUFFLE(ve, vo, 0, 4, 1, 5), b = MF_SHUFFLE(ve, vo, 2, 6, 3, 7);
      store4(out, load4(out) + (vf4)((vi4)a & (load4(d) > 0.0f)));
      store4(out + 4, load4(out + 4) + (vf4)((vi4)b & (load4(d + 4) > 0.0f)));
    }
    for (size_t X = X0; X < fastHi / 2; ++X) {
      const float ve = 0.75f * cy[X] + 0.25f * cy[X - 1], vo = 0.75f * cy[X] + 0.25f * cy[X + 1];
      xr[2 * X] += fd[2 * X] > 0 ? ve : 0.0f;
      xr[2 * X + 1] += fd[2 * X + 1] > 0 ? vo : 0.0f;
    }
    for (size_t i = fastHi; i < nfx; ++i) table(i);
  });
}

template <int D>
void Multigrid<D>::cycle(int l) {
  Level& L = levels_[size_t(l)];
  const LaplaceSystem<D>& A = level(l);
  if (l + 1 == levels()) {
    // Coarsest level: solve accurately with CG (in double) so the cycle stays linear.
    coarseB_.assign(L.b, L.b + A.size());
    coarseX_.assign(A.size(), 0.0);
    SolverOptions o;
    o.tolerance = 1e-10;
    o.maxIterations = 20 * int(A.size()) + 50;
    solvePCG<D>(A, coarseB_, &coarseX_, nullptr, o, &coarseWork_);
    for (size_t i = 0; i < A.size(); ++i) L.x[i] = float(coarseX_[i]);
    return;
  }
  for (int s = 0; s < options_.preSmooth; ++s) A.gaussSeidel(L.b, L.x, false);
  for (int s = 0; s < options_.bandSweeps && !L.band.empty(); ++s) sweepBand<D, float>(A, L.band, L.b, L.x, false);
  A.defect(L.b, L.x, L.r);
  restrict(l);
  std::fill_n(levels_[size_t(l) + 1].x, level(l + 1).size(), 0.0f);
  cycle(l + 1);
  prolongAdd(l);
  for (int s = 0; s < options_.bandSweeps && !L.band.empty(); ++s) sweepBand<D, float>(A, L.band, L.b, L.x, true);
  for (int s = 0; s < options_.postSmooth; ++s) A.gaussSeidel(L.b, L.x, true);
}

template <int D>
double Multigrid<D>::scaledCycle(const Vector& r, double rscale, Vector* z, bool withDot) {
  ensureFine();
  Level& L0 = levels_[0];
  if (rscale == 0.0 || !std::isfinite(rscale)) {  // zero in, zero out; an overflow stays visible
    std::fill(fineX_.begin(), fineX_.end(), 0.0f);
    zScale_ = rscale == 0.0 ? 0.0 : std::numeric_limits<double>::quiet_NaN();  // z = 0 x: 0 or NaN
  } else {
    const double inv = 1.0 / rscale;
    // Raw pointers here and below: through the vectors, each store would
    // reload their data pointers and the loops would stay scalar.
    const double* __restrict rd = r.data();
    float* __restrict b = L0.b;
    float* __restrict x = L0.x;
    parallelFor(r.size(), [&](size_t i) {
      b[i] = float(rd[i] * inv);
      x[i] = 0.0f;
    }, 4096);
    placeCoarse();
    cycle(0);
    releaseCoarse();
    zScale_ = rscale;
  }
  const double* __restrict rd = r.data();
  const auto zi = zOf();
  if (!z) return deterministicSum(r.size(), [&](size_t i) { return rd[i] * zi(i); });
  z->resize(r.size());
  double* __restrict zz = z->data();
  if (!withDot) {
    parallelFor(r.size(), [&](size_t i) { zz[i] = zi(i); }, 4096);
    return 0.0;
  }
  return deterministicSum(r.size(), [&](size_t i) {
    zz[i] = zi(i);
    return rd[i] * zz[i];
  });
}

template <int D>
void Multigrid<D>::direction(double beta, bool first, Vector* p) {
  formDirection(zOf(), beta, first, p);
}

template <int D>
void Multigrid<D>::apply(const Vector& r, Vector* z) {
  // The cycle is linear: run it on r / max|r|.
  scaledCycle(r, deterministicMax(r.size(), [&](size_t i) { return std::abs(r[i]); }), z, false);
}

template <int D>
double Multigrid<D>::applyDot(const Vector& r, double rnorm, Vector* z) {
  // |r_i| <= ||r||_2: r / ||r||_2 is as safe in float as r / max|r|, and free.
  return scaledCycle(r, rnorm, z, true);
}

template <int D>
SolverResult Multigrid<D>::solve(const Vector& bIn, Vector* x, const SolverOptions& opt) {
  SolverResult result;
  Vector b = bIn;
  if (fine_.singular()) fine_.removeNullSpace(&b);
  x->resize(fine_.size(), 0.0);
  double bnorm = norm2(b);
  if (bnorm == 0.0) {
    std::fill(x->begin(), x->end(), 0.0);
    result.converged = true;
    return result;
  }
  r_.resize(b.size());
  result.residual = fine_.residual(b, *x, &r_) / bnorm;
  while (result.residual > opt.tolerance && result.iterations < opt.maxIterations) {
    apply(r_, &z_);  // the V-cycle on the defect equation A e = r
    axpy(1.0, z_, x);
    if (fine_.singular()) fine_.removeNullSpace(x);
    ++result.iterations;
    result.residual = fine_.residual(b, *x, &r_) / bnorm;
  }
  result.converged = result.residual <= opt.tolerance;
  return result;
}

template class Multigrid<2>;
template class Multigrid<3>;

}  // namespace morphoflow
