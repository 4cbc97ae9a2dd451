#include "core/multigrid.h"

#include <cmath>

#include "core/parallel.h"

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

template <int D>
LaplaceSystem<D> coarsen(const LaplaceSystem<D>& F) {
  IVec<D> cd;
  for (int a = 0; a < D; ++a) cd[a] = (F.dims[a] + 1) / 2;
  LaplaceSystem<D> C(cd, F.periodic, F.scale / 4.0);
  const double inv2D = 1.0 / double(1 << D);
  forEachCell<D>(cd, [&](const IVec<D>& cc, size_t ci) {
    // Identity terms: Galerkin mean (scaled: coarse scale is fine scale / 4).
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
    C.c[ci] = float(4.0 * csum * inv2D);
    // Face between cc and cc + e_a: the 2^(D-1) fine faces at fine index 2 cc_a + 1.
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
      C.w[a][ci] = float(wsum / count);
    }
  });
  C.finalize();
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
  for (size_t l = 0; l < levels_.size(); ++l) {
    size_t n = level(int(l)).size();
    levels_[l].x.assign(n, 0.0);
    levels_[l].b.assign(n, 0.0);
    levels_[l].r.assign(n, 0.0);
  }
}

template <int D>
void Multigrid<D>::restrict(int l) {
  const LaplaceSystem<D>& F = level(l);
  const LaplaceSystem<D>& C = level(l + 1);
  const Vector& r = levels_[size_t(l)].r;
  Vector& b = levels_[size_t(l) + 1].b;
  const double inv2D = 1.0 / double(1 << D);
  forEachCell<D>(C.dims, [&](const IVec<D>& cc, size_t ci) {
    if (C.diag[ci] <= 0) {
      b[ci] = 0.0;
      return;
    }
    // Fine cells whose prolongation stencil can touch cc: 2cc-1 .. 2cc+2
    // (wrapped); the weight is a product of per-axis weights.
    int fi[D][4];
    double wt[D][4];
    for (int a = 0; a < D; ++a)
      for (int m = 0; m < 4; ++m) {
        int f = 2 * cc[a] - 1 + m;
        wt[a][m] = 0.0;
        fi[a][m] = 0;
        if (f < 0 || f >= F.dims[a]) {
          if (!F.periodic[a]) continue;
          f = (f + F.dims[a]) % F.dims[a];
        }
        fi[a][m] = f;
        wt[a][m] = prolongWeight1(f, cc[a], C.dims[a], C.periodic[a]);
      }
    double sum = 0.0;
    const size_t sx = 1, sy = size_t(F.dims[0]);
    const size_t sz = D == 3 ? sy * size_t(F.dims[1]) : 0;
    for (int mz = 0; mz < (D == 3 ? 4 : 1); ++mz) {
      double wz = 1.0;
      size_t oz = 0;
      if constexpr (D == 3) {
        wz = wt[2][mz];
        if (wz == 0.0) continue;
        oz = size_t(fi[2][mz]) * sz;
      }
      for (int my = 0; my < 4; ++my) {
        double wy = wz * wt[1][my];
        if (wy == 0.0) continue;
        size_t oy = oz + size_t(fi[1][my]) * sy;
        for (int mx = 0; mx < 4; ++mx) {
          double wx = wy * wt[0][mx];
          if (wx != 0.0) sum += wx * r[oy + size_t(fi[0][mx]) * sx];
        }
      }
    }
    b[ci] = sum * inv2D;
  });
}

template <int D>
void Multigrid<D>::prolongAdd(int l) {
  const LaplaceSystem<D>& F = level(l);
  const LaplaceSystem<D>& C = level(l + 1);
  const Vector& xc = levels_[size_t(l) + 1].x;
  Vector& x = levels_[size_t(l)].x;
  forEachCell<D>(F.dims, [&](const IVec<D>& f, size_t fi) {
    if (F.diag[fi] <= 0) return;
    int lo[D], hi[D];
    double wlo[D];
    for (int a = 0; a < D; ++a) {
      int parent = f[a] >> 1;
      int nb = (f[a] & 1) ? parent + 1 : parent - 1;
      if (nb < 0 || nb >= C.dims[a]) {
        if (C.periodic[a])
          nb = (nb + C.dims[a]) % C.dims[a];
        else
          nb = parent;
      }
      lo[a] = parent;
      hi[a] = nb;
      wlo[a] = nb == parent ? 1.0 : 0.75;
    }
    double v = 0.0;
    for (int k = 0; k < (1 << D); ++k) {
      IVec<D> cc;
      double wgt = 1.0;
      for (int a = 0; a < D; ++a) {
        bool up = (k >> a) & 1;
        if (up && hi[a] == lo[a]) {
          wgt = 0.0;
          break;
        }
        cc[a] = up ? hi[a] : lo[a];
        wgt *= up ? 1.0 - wlo[a] : wlo[a];
      }
      if (wgt != 0.0) v += wgt * xc[C.diag.index(cc)];
    }
    x[fi] += v;
  });
}

template <int D>
void Multigrid<D>::cycle(int l) {
  Level& L = levels_[size_t(l)];
  const LaplaceSystem<D>& A = level(l);
  if (l + 1 == levels()) {
    // Coarsest level: solve accurately with CG so the cycle stays linear.
    std::fill(L.x.begin(), L.x.end(), 0.0);
    SolverOptions o;
    o.tolerance = 1e-10;
    o.maxIterations = 20 * int(A.size()) + 50;
    solvePCG<D>(A, L.b, &L.x, nullptr, o);
    return;
  }
  for (int s = 0; s < options_.preSmooth; ++s) A.gaussSeidel(L.b, &L.x, false);
  A.residual(L.b, L.x, &L.r);
  restrict(l);
  std::fill(levels_[size_t(l) + 1].x.begin(), levels_[size_t(l) + 1].x.end(), 0.0);
  cycle(l + 1);
  prolongAdd(l);
  for (int s = 0; s < options_.postSmooth; ++s) A.gaussSeidel(L.b, &L.x, true);
}

template <int D>
void Multigrid<D>::vcycle(const Vector& b, Vector* x) {
  Level& L0 = levels_[0];
  L0.b = b;
  L0.x = *x;
  cycle(0);
  *x = L0.x;
}

template <int D>
void Multigrid<D>::apply(const Vector& r, Vector* z) {
  Level& L0 = levels_[0];
  L0.b = r;
  std::fill(L0.x.begin(), L0.x.end(), 0.0);
  cycle(0);
  *z = L0.x;
}

template <int D>
SolverResult Multigrid<D>::solve(const Vector& bIn, Vector* x, const SolverOptions& opt,
                                 Interrupter* interrupter) {
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
  Vector r(b.size());
  result.residual = fine_.residual(b, *x, &r) / bnorm;
  while (result.residual > opt.tolerance && result.iterations < opt.maxIterations) {
    vcycle(b, x);
    if (fine_.singular()) fine_.removeNullSpace(x);
    ++result.iterations;
    result.residual = fine_.residual(b, *x, &r) / bnorm;
    if (interrupter && interrupter->progress(-1.0)) break;
  }
  result.converged = result.residual <= opt.tolerance;
  return result;
}

template class Multigrid<2>;
template class Multigrid<3>;

}  // namespace morphoflow
