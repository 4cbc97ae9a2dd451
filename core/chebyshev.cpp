#include "core/chebyshev.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "core/row_stencil.h"
#include "core/simd_dispatch.h"

namespace morphoflow {

namespace {

// The interval [1 - rho, 1 + rho] is centred on 1 (theta = 1), so a step is
// e_k = e_{k-2} + w_k (J e_{k-1} - e_{k-2}), with the Jacobi map
// J e = g + D^-1 W e (the e_{k-1} terms of g - M e cancel), e_1 = g and
// e_0 = 0: Chebyshev-accelerated Jacobi.
//
// One row's uniform span (every face weighs wu, one diagonal): the loop
// vectorises; `first` is step 2, whose e_0 is 0 (its buffer unset).
template <int D, bool First, bool Weighted>
__attribute__((always_inline)) inline void uniformSteps(size_t lo, size_t hi, const float* __restrict c,
                                                        const float* __restrict yl, const float* __restrict yh,
                                                        const float* __restrict zl, const float* __restrict zh,
                                                        const float* __restrict g, float* __restrict e, float wu,
                                                        float inv, float omega) {
  for (size_t i = lo; i < hi; ++i) {
    float nb = (c[i + 1] + c[i - 1]) + (yh[i] + yl[i]);
    if constexpr (D == 3) nb += zh[i] + zl[i];
    if constexpr (Weighted) nb *= wu;
    const float jacobi = g[i] + inv * nb;
    if constexpr (First)
      e[i] = omega * jacobi;
    else
      e[i] = e[i] + omega * (jacobi - e[i]);
  }
}

template <int D, bool First, bool Weighted>
void uniformStepsSse(size_t lo, size_t hi, const float* c, const float* yl, const float* yh, const float* zl,
                     const float* zh, const float* g, float* e, float wu, float inv, float omega) {
  uniformSteps<D, First, Weighted>(lo, hi, c, yl, yh, zl, zh, g, e, wu, inv, omega);
}
#if MORPHOFLOW_AVX2_KERNELS
// The same loop compiled for AVX2 (eight lanes; no FMA, so the same bits).
template <int D, bool First, bool Weighted>
__attribute__((target("avx2"))) void uniformStepsAvx(size_t lo, size_t hi, const float* c, const float* yl,
                                                     const float* yh, const float* zl, const float* zh,
                                                     const float* g, float* e, float wu, float inv, float omega) {
  uniformSteps<D, First, Weighted>(lo, hi, c, yl, yh, zl, zh, g, e, wu, inv, omega);
}
#endif

// Step `First ? 2 : k` on one row, cur = e_{k-1}, e = e_{k-2} (overwritten).
template <int D, bool First>
void stepRow(const LaplaceSystem<D>& A, size_t row, size_t y, size_t z, const float* cur, float* e,
             const float* g, const float* zeros, float omega) {
  const size_t nx = size_t(A.dims[0]);
  const bool px = A.periodic[0];
  const RowStencil<D, float> s = rowStencil<D, float>(A, cur, zeros, zeros, row, y, z);
  const float* wa[D];
  for (int a = 0; a < D; ++a) wa[a] = A.w[a].data() + s.base;
  const float* ir = A.template invDiag<float>() + s.base;
  const float* cr = cur + s.base;
  const float* gr = g + s.base;
  float* er = e + s.base;
  auto update = [&](size_t i, float nb) {
    const float jacobi = gr[i] + ir[i] * nb;  // inactive: 1 / diag = 0 and g = 0 keep e = 0
    er[i] = First ? omega * jacobi : er[i] + omega * (jacobi - er[i]);
  };
  auto edge = [&](size_t i) {
    const size_t il = i == 0 ? nx - 1 : i - 1, ih = i + 1 == nx ? 0 : i + 1;
    const float wl = (i == 0 && !px) ? 0.0f : wa[0][il];
    update(i, neighbourSum<D, float>(s, wa, cr, i, il, ih, wl));
  };
  auto general = [&](size_t from, size_t to) {
    for (size_t i = from; i < to; ++i) update(i, neighbourSum<D, float>(s, wa, cr, i, i - 1, i + 1, wa[0][i - 1]));
  };
  edge(0);
  if (nx == 1) return;
  const auto& span = A.sweepSpan(row);
  if (span.lo < span.hi) {
    general(1, span.lo);
    const float* yl = s.xlo[1];  // the neighbour rows (their cell 0)
    const float* yh = s.xhi[1];
    const float* zl = s.xlo[D - 1];
    const float* zh = s.xhi[D - 1];
    const float inv = ir[span.lo];
    const bool weighted = span.w != 1.0f;
#if MORPHOFLOW_AVX2_KERNELS
    if (useAvx2()) {
      (weighted ? uniformStepsAvx<D, First, true> : uniformStepsAvx<D, First, false>)(
          span.lo, span.hi, cr, yl, yh, zl, zh, gr, er, span.w, inv, omega);
    } else
#endif
    {
      (weighted ? uniformStepsSse<D, First, true> : uniformStepsSse<D, First, false>)(
          span.lo, span.hi, cr, yl, yh, zl, zh, gr, er, span.w, inv, omega);
    }
    general(span.hi, nx - 1);
  } else {
    general(1, nx - 1);
  }
  edge(nx - 1);
}

}  // namespace

template <int D>
Chebyshev<D>::Chebyshev(const LaplaceSystem<D>& A, const ChebyshevLayout& layout) : A_(A), layout_(layout) {
  layout_.stepsPerPass = std::max(1, layout_.stepsPerPass);
  if (layout_.slabs <= 0) layout_.slabs = hardwareThreads();
  refresh();  // the vectors wait for the first solve: a caller may only want the bound
}

template <int D>
void Chebyshev<D>::refresh() {
  const size_t n = A_.size();
  // rho = max (diag - c) / diag: diag sums c and the cell's face weights.
  rho_ = deterministicMax(n, [&](size_t i) {
    const double d = A_.diag[i];
    return d > 0 ? (d - double(A_.c[i])) / d : 0.0;
  });
  // The face weights' float sum may round below diag - c: a margin far
  // above it (it costs nothing in the steps' count).
  rho_ = std::min(1.0, rho_ * (1.0 + 1e-5));
  const double dmax = deterministicMax(n, [&](size_t i) { return double(A_.diag[i]); });
  const double dminInv = deterministicMax(n, [&](size_t i) {
    const double d = A_.diag[i];
    return d > 0 ? 1.0 / d : 0.0;
  });
  diagRatio_ = dmax > 0 ? dmax * dminInv : 1.0;
  // w_1 = 1, w_2 = 1 / (1 - rho^2 / 2), w_k = 1 / (1 - rho^2 w_{k-1} / 4).
  omega_.assign(2, 1.0f);
  double w = 1.0;
  for (int k = 2; k < 4096 && applicable(); ++k) {
    w = k == 2 ? 1.0 / (1.0 - rho_ * rho_ / 2.0) : 1.0 / (1.0 - rho_ * rho_ * w / 4.0);
    omega_.push_back(float(w));
    if (k > 64 && float(w) == omega_[size_t(k) - 1]) break;  // converged to its limit
  }
}

template <int D>
int Chebyshev<D>::stepsFor(double factor) const {
  if (rho_ <= 0.0) return 1;  // M = I: one step is exact
  const double target = std::max(1.0, factor * std::sqrt(diagRatio_));
  return std::max(1, int(std::ceil(std::acosh(target) / std::acosh(1.0 / rho_))));
}

template <int D>
void Chebyshev<D>::plane(int level, size_t q, const Vector& r, double rscale) {
  const LaplaceSystem<D>& A = A_;
  const size_t nx = size_t(A.dims[0]);
  const size_t rows = D == 3 ? size_t(A.dims[1]) : 1;
  for (size_t k = 0; k < rows; ++k) {
    const size_t row = q * rows + k, y = D == 3 ? k : q, z = D == 3 ? q : 0;
    if (level == 1) {  // e_1 = g = rscale D^-1 r / scale
      const size_t base = row * nx;
      const double sc = rscale / A.scale;
      const double* __restrict inv = A.template invDiag<double>() + base;
      const double* __restrict rr = r.data() + base;
      float* __restrict g = g_.data() + base;
      float* __restrict e = e_[1].data() + base;
      for (size_t i = 0; i < nx; ++i) {
        g[i] = float(rr[i] * sc * inv[i]);
        e[i] = g[i];
      }
    } else {
      const float* cur = e_[(level - 1) & 1].data();
      float* e = e_[level & 1].data();
      if (level == 2)
        stepRow<D, true>(A, row, y, z, cur, e, g_.data(), zeros_.data(), omega_[2]);
      else
        stepRow<D, false>(A, row, y, z, cur, e, g_.data(), zeros_.data(),
                          omega_[std::min(size_t(level), omega_.size() - 1)]);
    }
  }
}

template <int D>
void Chebyshev<D>::run(int steps, const Vector& r, double rscale) {
  const size_t planes = size_t(A_.dims[D - 1]);
  const bool wrap = A_.periodic[D - 1];
  for (int done = 0; done < steps;) {
    int m = std::min(layout_.stepsPerPass, steps - done);
    // Slabs at least 2m + 2 planes thick, so the triangles around two cuts
    // neither overlap nor read what the other writes.
    const size_t slabs = std::max<size_t>(1, std::min(size_t(layout_.slabs), planes / size_t(2 * m + 2)));
    if (wrap && planes < size_t(2 * m + 2)) m = 1;  // a periodic cut needs the room as well
    const int first = done + 1;
    if (m == 1) {  // one step: each plane reads the other vector only
      parallelFor(planes, [&](size_t q) { plane(first, q, r, rscale); }, std::max<size_t>(1, 16384 / (A_.size() / planes)));
      done += 1;
      continue;
    }
    auto begin = [&](size_t j) { return j * planes / slabs; };
    // Step t shrinks t planes away from each cut (a slab edge that is not
    // the domain's, or the periodic wrap).
    parallelFor(slabs, [&](size_t j) {
      const size_t lo = begin(j), hi = begin(j + 1);
      const bool cutLo = j > 0 || wrap, cutHi = j + 1 < slabs || wrap;
      for (size_t p = lo; p < hi + size_t(m) - 1; ++p)
        for (int t = 1; t <= m; ++t) {
          if (p < lo + size_t(t) - 1) break;
          const size_t q = p - size_t(t - 1);
          if ((cutLo && q < lo + size_t(t)) || (cutHi && q + size_t(t) >= hi) || q >= hi) continue;
          plane(first + t - 1, q, r, rscale);
        }
    });
    // The triangles: step t on the 2t planes around each cut.
    const size_t cuts = wrap ? slabs : slabs - 1;
    parallelFor(cuts, [&](size_t j) {
      const size_t cut = wrap ? begin(j) : begin(j + 1);
      for (int t = 1; t <= m; ++t)
        for (size_t d = 0; d < size_t(2 * t); ++d) plane(first + t - 1, (cut + planes - size_t(t) + d) % planes, r, rscale);
    });
    done += m;
  }
}

template <int D>
SolverResult Chebyshev<D>::solve(const Vector& b, Vector* xp, const SolverOptions& options) {
  if (!applicable()) return solvePCG<D>(A_, b, xp, nullptr, options);  // no bound: plain CG
  Vector& x = *xp;
  const size_t n = A_.size();
  x.resize(n, 0.0);
  SolverResult result;
  const double bnorm = norm2(b);
  if (bnorm == 0.0) {
    std::fill(x.begin(), x.end(), 0.0);
    result.converged = true;
    return result;
  }
  for (auto& v : e_) v.resize(n);
  g_.resize(n);
  zeros_.assign(size_t(A_.dims[0]), 0.0f);
  r_.resize(n);
  const double budget = options.tolerance * bnorm;
  double rnorm = A_.residual(b, x, &r_);
  // Rounds of at most 1e4 each: the float steps resolve that much of the
  // correction with digits to spare.
  constexpr double kRoundFactor = 1e4;
  int rounds = 0;
  while (rnorm > budget && result.iterations < options.maxIterations && rounds < 16) {
    const int steps =
        std::min(stepsFor(std::min(rnorm / budget, kRoundFactor)), options.maxIterations - result.iterations);
    const double rscale = std::sqrt(double(n)) / rnorm;  // g of order 1 in float
    run(steps, r_, rscale);
    const float* __restrict e = e_[steps & 1].data();
    double* __restrict xd = x.data();
    const double inv = 1.0 / rscale;
    parallelFor(n, [&](size_t i) { xd[i] += double(e[i]) * inv; }, 4096);
    rnorm = A_.residual(b, x, &r_);
    result.iterations += steps;
    ++rounds;
  }
  result.residual = rnorm / bnorm;
  result.converged = rnorm <= budget * 1.0001;
  return result;
}

template class Chebyshev<2>;
template class Chebyshev<3>;

}  // namespace morphoflow
