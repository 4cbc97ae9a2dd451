#include "core/chebyshev.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/parallel.h"
#include "core/row_stencil.h"
#include "core/simd_dispatch.h"
#include "core/work_pool.h"

namespace morphoflow {

namespace {

template <int D>
constexpr size_t kPacked = 2 * D + 1;  // floats per cell outside a uniform span
// A cyclic round ends within about 1.25 of the full iteration's residual
// (tests/core/test_chebyshev.cpp): its steps are asked for this much more.
constexpr double kCyclicMargin = 1.3;

// The interval [1 - rho, 1 + rho] is centred on 1 (theta = 1), so a step is
// e_k = e_{k-2} + w_k (J e_{k-1} - e_{k-2}), with the Jacobi map
// J e = g + D^-1 W e (the e_{k-1} terms of g - M e cancel), e_1 = g and
// e_0 = 0: Chebyshev-accelerated Jacobi.
//
// One row's uniform span (every face weighs wu, one diagonal): the loop
// vectorises; `first` is step 2, whose e_0 is 0 (its buffer unset).
template <int D, bool First, bool Weighted>
__attribute__((always_inline)) inline void uniformSteps(size_t lo, size_t hi, const float* __restrict xl,
                                                        const float* __restrict xh, const float* __restrict yl,
                                                        const float* __restrict yh, const float* __restrict zl,
                                                        const float* __restrict zh, const float* __restrict g,
                                                        float* __restrict e, float wu, float inv, float omega) {
  for (size_t i = lo; i < hi; ++i) {
    float nb = (xh[i] + xl[i]) + (yh[i] + yl[i]);
    if constexpr (D == 3) nb += zh[i] + zl[i];
    if constexpr (Weighted) nb *= wu;
    const float jacobi = g[i] + inv * nb;
    if constexpr (First)
      e[i] = omega * jacobi;
    else
      e[i] = e[i] + omega * (jacobi - e[i]);
  }
}

// The neighbours' rows: x low and high (this row's values shifted), then y and z.
struct NeighbourRows {
  const float *xl, *xh, *yl, *yh, *zl, *zh;
};

template <int D, bool First, bool Weighted>
void uniformStepsSse(size_t lo, size_t hi, const NeighbourRows& n, const float* g, float* e, float wu, float inv,
                     float omega) {
  uniformSteps<D, First, Weighted>(lo, hi, n.xl, n.xh, n.yl, n.yh, n.zl, n.zh, g, e, wu, inv, omega);
}
#if MORPHOFLOW_AVX2_KERNELS
// The same loop compiled for AVX2 (eight lanes; no FMA, so the same bits).
template <int D, bool First, bool Weighted>
__attribute__((target("avx2"))) void uniformStepsAvx(size_t lo, size_t hi, const NeighbourRows& n, const float* g,
                                                     float* e, float wu, float inv, float omega) {
  uniformSteps<D, First, Weighted>(lo, hi, n.xl, n.xh, n.yl, n.yh, n.zl, n.zh, g, e, wu, inv, omega);
}
#endif

// uniformSteps over [lo, hi), AVX2 where the CPU has it.
template <int D, bool First>
void uniformRun(size_t lo, size_t hi, const NeighbourRows& n, const float* g, float* e, float wu, float inv,
                float omega) {
  const bool weighted = wu != 1.0f;
#if MORPHOFLOW_AVX2_KERNELS
  if (useAvx2()) {
    (weighted ? uniformStepsAvx<D, First, true> : uniformStepsAvx<D, First, false>)(lo, hi, n, g, e, wu, inv, omega);
    return;
  }
#endif
  (weighted ? uniformStepsSse<D, First, true> : uniformStepsSse<D, First, false>)(lo, hi, n, g, e, wu, inv, omega);
}

// Step `First ? 2 : k` on one row, cur = e_{k-1}, e = e_{k-2} (overwritten).
// The cells outside the row's uniform span take their coefficients from
// `packed`: per cell, 1 / diag and the face weights in neighbourSum's order
// (x high, x low, then high and low along each further axis), contiguous, so
// a row end costs one short read rather than a cache line from each of D + 1
// full-size grids.
template <int D, bool First>
void stepRow(const LaplaceSystem<D>& A, size_t row, size_t y, size_t z, const float* cur, float* e,
             const float* g, const float* zeros, const float* packed, float omega) {
  const size_t nx = size_t(A.dims[0]);
  const RowStencil<D, float> s = rowStencil<D, float>(A, cur, zeros, zeros, row, y, z);
  const float* cr = cur + s.base;
  const float* gr = g + s.base;
  float* er = e + s.base;
  auto general = [&](size_t from, size_t to) {
    for (size_t i = from; i < to; ++i, packed += kPacked<D>) {
      const size_t il = i == 0 ? nx - 1 : i - 1, ih = i + 1 == nx ? 0 : i + 1;  // weight 0 unless periodic
      float nb = packed[1] * cr[ih] + packed[2] * cr[il];
      for (int a = 1; a < D; ++a) nb += packed[2 * a + 1] * s.xhi[a][i] + packed[2 * a + 2] * s.xlo[a][i];
      const float jacobi = gr[i] + packed[0] * nb;  // inactive: 1 / diag = 0 and g = 0 keep e = 0
      er[i] = First ? omega * jacobi : er[i] + omega * (jacobi - er[i]);
    }
  };
  const auto& span = A.sweepSpan(row);
  if (span.lo >= span.hi) {
    general(0, nx);
    return;
  }
  general(0, span.lo);
  // The neighbour rows (their cell 0); in 2D the z pair repeats the y pair, unused.
  const NeighbourRows n{cr - 1, cr + 1, s.xlo[1], s.xhi[1], s.xlo[D - 1], s.xhi[D - 1]};
  uniformRun<D, First>(span.lo, span.hi, n, gr, er, span.w, A.invDiag(s.base + span.lo), omega);
  general(span.hi, nx);
}

// Step `First ? 2 : k` on the cells of one colour of one row, in the
// cyclic layout (each colour's cells of a row in slots x / 2): e = that
// colour's e_{k-2} (overwritten), g its g, cur the other colour's e_{k-1}
// in this row, and lo[a], hi[a] in the neighbour rows along y and z (the
// other colour's cells there sit at the same x, so in the same slots).
// s: the colour's first x in this row. The arithmetic is stepRow's, term
// for term.
template <int D, bool First>
void colourRow(const LaplaceSystem<D>& A, size_t row, size_t s, const float* cur, const float* const* lo,
               const float* const* hi, float* e, const float* g, const float* packed, float omega) {
  const size_t nx = size_t(A.dims[0]);
  const auto& span = A.sweepSpan(row);
  const size_t spanLo = std::min<size_t>(span.lo, span.hi), spanHi = span.hi;
  auto general = [&](size_t from, size_t to) {  // cells x = from, from + 2, .. < to of this colour
    for (size_t x = from + ((from + s) & 1); x < to; x += 2) {
      const float* pk = packed + kPacked<D> * (x < spanLo ? x : x - (spanHi - spanLo));
      const size_t xl = x == 0 ? nx - 1 : x - 1, xh = x + 1 == nx ? 0 : x + 1;  // weight 0 unless periodic
      const size_t j = x / 2;
      float nb = pk[1] * cur[xh / 2] + pk[2] * cur[xl / 2];
      for (int a = 1; a < D; ++a) nb += pk[2 * a + 1] * hi[a][j] + pk[2 * a + 2] * lo[a][j];
      const float jacobi = g[j] + pk[0] * nb;  // inactive: 1 / diag = 0 and g = 0 keep e = 0
      e[j] = First ? omega * jacobi : e[j] + omega * (jacobi - e[j]);
    }
  };
  if (spanLo >= spanHi) {
    general(0, nx);
    return;
  }
  general(0, spanLo);
  // The span's cells of this colour: x = 2 j + s; their x neighbours are
  // the other colour's slots j - 1 + s (x - 1) and j + s (x + 1).
  const size_t jlo = (spanLo + 1 - s) / 2, jhi = (spanHi + 1 - s) / 2;
  const NeighbourRows n{cur + s - 1, cur + s, lo[1], hi[1], lo[D - 1], hi[D - 1]};
  uniformRun<D, First>(jlo, jhi, n, g, e, span.w, LaplaceSystem<D>::inverse(A.diag.row(row)[spanLo]), omega);
  general(spanHi, nx);
}

}  // namespace

template <int D>
Chebyshev<D>::Chebyshev(const LaplaceSystem<D>& A, const ChebyshevLayout& layout, ChebyshevWork* work)
    : A_(A), layout_(layout), work_(work ? work : &own_) {
  layout_.stepsPerPass = std::max(1, layout_.stepsPerPass);
  if (layout_.slabs <= 0) layout_.slabs = hardwareThreads();
  zeros_.assign(size_t(A.dims[0]), 0.0f);
  refresh();  // the other vectors wait for the first solve: a caller may only want the bound
}

template <int D>
void Chebyshev<D>::refresh() {
  const size_t n = A_.size(), nx = size_t(A_.dims[0]), rows = n / nx;
  // Rows alike in their stored rows (diagonal, c, the weights of their
  // faces) and domain edges have the same bounds, span and packed
  // coefficients: each kind is visited once (a box's few, whatever its
  // size; an obstacle's as many as it has rows).
  using Key = std::array<uintptr_t, 2 * D + 2>;
  auto at = [](const float* p) { return reinterpret_cast<uintptr_t>(p); };
  std::vector<std::pair<Key, size_t>> kinds(rows);
  parallelFor(
      rows,
      [&](size_t row) {
        const RowStencil<D, float> s = rowStencil<D, float>(A_, zerosOf(), zerosOf(), zerosOf(), row);
        Key key{at(A_.diag.row(row)), at(A_.c.row(row)), at(A_.w[0].row(row))};
        uintptr_t edges = 0;
        size_t rest = row;
        for (int a = 1; a < D; ++a) {
          const int k = int(rest % size_t(A_.dims[a]));
          rest /= size_t(A_.dims[a]);
          key[size_t(2 * a + 1)] = at(A_.w[a].row(row));
          key[size_t(2 * a + 2)] = at(s.wlo[a]);
          edges |= uintptr_t(k == 0) << (2 * a) | uintptr_t(k == A_.dims[a] - 1) << (2 * a + 1);
        }
        key[size_t(2 * D + 1)] = edges;
        kinds[row] = {key, row};
      },
      256);
  std::sort(kinds.begin(), kinds.end());
  std::vector<size_t> first;  // where each kind's rows begin in `kinds`
  for (size_t j = 0; j < rows; ++j)
    if (j == 0 || kinds[j].first != kinds[j - 1].first) first.push_back(j);
  first.push_back(rows);
  const size_t count = first.size() - 1;
  // The coefficients of the cells outside each kind's uniform span, packed.
  std::vector<size_t> start(count + 1, 0);
  for (size_t g = 0; g < count; ++g) {
    const auto& span = A_.sweepSpan(kinds[first[g]].second);
    start[g + 1] = start[g] + (nx - (span.hi - span.lo)) * kPacked<D>;
  }
  packed_.resize(start[count]);
  if (packed_.capacity() > 2 * packed_.size()) packed_.shrink_to_fit();
  packedStart_.resize(rows);
  // rho = max (diag - c) / diag (diag sums c and the cell's face weights),
  // and the diagonal's range: maxima, so any order.
  std::vector<std::array<double, 3>> m(count);
  parallelFor(count, [&](size_t g) {
    const size_t row = kinds[first[g]].second;
    const float *d = A_.diag.row(row), *c = A_.c.row(row);
    std::array<double, 3> r{0.0, 0.0, 0.0};  // rho, the largest diagonal, 1 / the smallest
    for (size_t i = 0; i < nx; ++i) {
      const double di = d[i];
      r[0] = std::max(r[0], di > 0 ? (di - double(c[i])) / di : 0.0);
      r[1] = std::max(r[1], di);
      r[2] = std::max(r[2], di > 0 ? 1.0 / di : 0.0);
    }
    m[g] = r;
    packRow(row, packed_.data() + start[g]);
    for (size_t j = first[g]; j < first[g + 1]; ++j) packedStart_[kinds[j].second] = start[g];
  });
  std::array<double, 3> most{0.0, 0.0, 0.0};
  for (const auto& r : m)
    for (size_t k = 0; k < 3; ++k) most[k] = std::max(most[k], r[k]);
  rho_ = most[0];
  // The face weights' float sum may round below diag - c: a margin far
  // above it (it costs nothing in the steps' count).
  rho_ = std::min(1.0, rho_ * (1.0 + 1e-5));
  const double dmax = most[1], dminInv = most[2];
  diagRatio_ = dmax > 0 ? dmax * dminInv : 1.0;
  // Two colours like a chessboard's where every periodic axis is even.
  cyclic_ = layout_.cyclic && nx >= 2;
  for (int a = 0; a < D; ++a) cyclic_ = cyclic_ && !(A_.periodic[a] && A_.dims[a] % 2);
  hx_ = (nx + 1) / 2;
  // w_1 = 1, w_2 = 1 / (1 - rho^2 / 2), w_k = 1 / (1 - rho^2 w_{k-1} / 4).
  omega_.assign(2, 1.0f);
  double w = 1.0;
  for (int k = 2; k < 4096 && applicable(); ++k) {
    w = k == 2 ? 1.0 / (1.0 - rho_ * rho_ / 2.0) : 1.0 / (1.0 - rho_ * rho_ * w / 4.0);
    omega_.push_back(float(w));
    if (k > 64 && float(w) == omega_[size_t(k) - 1]) break;  // converged to its limit
  }
}

// Row `row`'s coefficients outside its uniform span: per cell 1 / diag and
// the face weights in neighbourSum's order.
template <int D>
void Chebyshev<D>::packRow(size_t row, float* out) const {
  const size_t nx = size_t(A_.dims[0]);
  const RowStencil<D, float> s = rowStencil<D, float>(A_, zerosOf(), zerosOf(), zerosOf(), row);
  const auto& span = A_.sweepSpan(row);
  const float *dr = A_.diag.row(row), *w0 = A_.w[0].row(row);
  for (size_t i = 0; i < nx; ++i) {
    if (i >= span.lo && i < span.hi) continue;
    const size_t il = i == 0 ? nx - 1 : i - 1;
    *out++ = LaplaceSystem<D>::inverse(dr[i]);
    *out++ = w0[i];
    *out++ = (i == 0 && !A_.periodic[0]) ? 0.0f : w0[il];
    for (int a = 1; a < D; ++a) {
      *out++ = A_.w[a].row(row)[i];
      *out++ = s.wlo[a][i];
    }
  }
}

template <int D>
int Chebyshev<D>::stepsFor(double factor) const {
  if (rho_ <= 0.0) return 1;  // M = I: one step is exact
  if (!applicable()) return std::numeric_limits<int>::max();  // no bound
  const double target = std::max(1.0, factor * std::sqrt(diagRatio_));
  return std::max(1, int(std::ceil(std::acosh(target) / std::acosh(1.0 / rho_))));
}

template <int D>
template <class Op>
void Chebyshev<D>::pipeline(const int m, Op&& op) {
  const size_t planes = size_t(A_.dims[D - 1]);
  const bool wrap = A_.periodic[D - 1];
  if (m == 1 || (wrap && planes < size_t(2 * m + 2))) {  // a periodic cut needs the room below
    // Each step in a pass of its own: a plane then reads finished planes only.
    for (int t = 1; t <= m; ++t)
      parallelFor(planes, [&](size_t q) { op(t, q); }, std::max<size_t>(1, 16384 / (A_.size() / planes)));
    return;
  }
  // Slabs at least 2m + 2 planes thick, so the triangles around two cuts
  // neither overlap nor read what the other writes.
  const size_t slabs = std::max<size_t>(1, std::min(size_t(layout_.slabs), planes / size_t(2 * m + 2)));
  auto begin = [&](size_t j) { return j * planes / slabs; };
  // Step t shrinks t planes away from each cut (a slab edge that is not
  // the domain's, or the periodic wrap); within a slab, step t on plane
  // p - t + 1 follows step t - 1 on plane p.
  parallelFor(slabs, [&](size_t j) {
    const size_t lo = begin(j), hi = begin(j + 1);
    const bool cutLo = j > 0 || wrap, cutHi = j + 1 < slabs || wrap;
    for (size_t p = lo; p < hi + size_t(m) - 1; ++p)
      for (int t = 1; t <= m; ++t) {
        if (p < lo + size_t(t) - 1) break;
        const size_t q = p - size_t(t - 1);
        if ((cutLo && q < lo + size_t(t)) || (cutHi && q + size_t(t) >= hi) || q >= hi) continue;
        op(t, q);
      }
  });
  // The triangles: step t on the 2t planes around each cut.
  const size_t cuts = wrap ? slabs : slabs - 1;
  parallelFor(cuts, [&](size_t j) {
    const size_t cut = wrap ? begin(j) : begin(j + 1);
    for (int t = 1; t <= m; ++t)
      for (size_t d = 0; d < size_t(2 * t); ++d) op(t, (cut + planes - size_t(t) + d) % planes);
  });
}

template <int D>
void Chebyshev<D>::rows(size_t q, auto&& fn) const {
  const size_t perPlane = D == 3 ? size_t(A_.dims[1]) : 1;
  for (size_t k = 0; k < perPlane; ++k) fn(q * perPlane + k, D == 3 ? k : q, D == 3 ? q : 0);
}

template <int D>
void Chebyshev<D>::step(int level, size_t q, bool jacobi) {
  if (cyclic_) return colourStep(level, q, jacobi);
  const float* cur = work_->e[(level - 1) & 1].data();
  float* e = work_->e[level & 1].data();
  const float omega = omega_[std::min(size_t(level), omega_.size() - 1)];
  rows(q, [&](size_t row, size_t y, size_t z) {
    if (level == 2)
      stepRow<D, true>(A_, row, y, z, cur, e, work_->g.data(), zeros_.data(), packedRow(row), omega);
    else
      stepRow<D, false>(A_, row, y, z, cur, e, work_->g.data(), zeros_.data(), packedRow(row), omega);
  });
}

template <int D>
void Chebyshev<D>::colourStep(int level, size_t q, bool jacobi) {
  const size_t colour = size_t(level & 1), rowsTotal = A_.size() / size_t(A_.dims[0]);
  const float* cur = work_->e[1 - colour].data();
  float* e = work_->e[colour].data();
  const float* g = work_->g.data() + colour * rowsTotal * hx_;
  const float omega = jacobi ? 1.0f : omega_[std::min(size_t(level), omega_.size() - 1)];
  rows(q, [&](size_t row, size_t y, size_t z) {
    // The neighbour rows along y and z (the other colour's slots), zeros
    // across a non-periodic edge.
    const RowStencil<D, float> n = rowStencil<D, float>(A_, cur, zerosOf(), zerosOf(), row, y, z, hx_);
    const size_t s = (colour + y + z) & 1;  // this colour's first x in the row
    const size_t at = row * hx_;
    if (level == 2 || jacobi)  // e = omega J e_{k-1}
      colourRow<D, true>(A_, row, s, cur + at, n.xlo, n.xhi, e + at, g + at, packedRow(row), omega);
    else colourRow<D, false>(A_, row, s, cur + at, n.xlo, n.xhi, e + at, g + at, packedRow(row), omega);
  });
}

template <int D>
void Chebyshev<D>::residualPlane(const Vector& b, const Vector& x, size_t q) {
  // r = b - A x row by row into a row buffer (r itself never goes to
  // memory), then step 1: e_1 = g = rscale D^-1 r / scale.
  const size_t nx = size_t(A_.dims[0]);
  thread_local std::vector<double> buffer;
  buffer.resize(nx);
  const double sc = rscale_ / A_.scale;
  double sum = 0.0;
  const size_t half = A_.size() / nx * hx_;  // cyclic: colour 1's g from here
  rows(q, [&](size_t row, size_t y, size_t z) {
    sum += A_.residualRow(row, b, x, buffer.data());
    const size_t base = row * nx;
    // D^-1: one value on the row's uniform span, packed (first of each
    // cell's coefficients) outside it.
    const auto& span = A_.sweepSpan(row);
    const size_t lo = std::min<size_t>(span.lo, span.hi), hi = span.hi;
    const float* packed = packedRow(row);
    double* __restrict v = buffer.data();  // r, then g
    auto outside = [&](size_t from, size_t to) {
      for (size_t i = from; i < to; ++i, packed += kPacked<D>) v[i] = double(float(v[i] * sc * double(*packed)));
    };
    outside(0, lo);
    if (lo < hi) {
      const double inv = double(LaplaceSystem<D>::inverse(A_.diag.row(row)[lo]));
      for (size_t i = lo; i < hi; ++i) v[i] = double(float(v[i] * sc * inv));
    }
    outside(hi, nx);
    if (!cyclic_) {
      float* __restrict g = work_->g.data() + base;
      float* __restrict e = work_->e[1].data() + base;
      for (size_t i = 0; i < nx; ++i) g[i] = e[i] = float(v[i]);
      return;
    }
    // Each colour's cells to its slots; e_1 = g in both (a round of one
    // step uses both).
    for (size_t colour = 0; colour < 2; ++colour) {
      const size_t at = row * hx_;
      float* __restrict g = work_->g.data() + colour * half + at;
      float* __restrict e = work_->e[colour].data() + at;
      for (size_t i = (colour + y + z) & 1; i < nx; i += 2) g[i / 2] = e[i / 2] = float(v[i]);
    }
  });
  planeSquares_[q] = sum;
}

template <int D>
void Chebyshev<D>::addCorrection(Vector* x, const float* e0, const float* e1, size_t q) const {
  const size_t nx = size_t(A_.dims[0]);
  const double inv = 1.0 / rscale_;
  rows(q, [&](size_t row, size_t y, size_t z) {
    double* __restrict xr = x->data() + row * nx;
    if (!cyclic_) {
      const float* __restrict er = e0 + row * nx;
      for (size_t i = 0; i < nx; ++i) xr[i] += double(er[i]) * inv;
      return;
    }
    const float* e[2] = {e0 + row * hx_, e1 + row * hx_};
    for (size_t colour = 0; colour < 2; ++colour)
      for (size_t i = (colour + y + z) & 1; i < nx; i += 2) xr[i] += double(e[colour][i / 2]) * inv;
  });
}

template <int D>
double Chebyshev<D>::residualNorm() const {
  double sum = 0.0;  // in plane order: independent of how the planes were scheduled
  for (double v : planeSquares_) sum += v;
  return std::sqrt(sum);
}

template <int D>
SolverResult Chebyshev<D>::solve(const Vector& b, Vector* xp, const SolverOptions& options, double bnorm) {
  if (!applicable()) return solvePCG<D>(A_, b, xp, nullptr, options);  // no bound: plain CG
  Vector& x = *xp;
  const size_t n = A_.size(), nx = size_t(A_.dims[0]);
  resizeExactly(&x, n, 0.0);
  SolverResult result;
  if (bnorm < 0.0) bnorm = norm2(b);
  if (bnorm == 0.0) {
    std::fill(x.begin(), x.end(), 0.0);
    result.converged = true;
    return result;
  }
  const size_t slots = cyclic_ ? n / nx * hx_ : n;  // per colour where cyclic
  for (auto& v : work_->e) resizeExactly(&v, slots);
  resizeExactly(&work_->g, cyclic_ ? 2 * slots : n);
  planeSquares_.assign(size_t(A_.dims[D - 1]), 0.0);
  // g of order 1 in float for any residual from 1e-30 ||b|| up.
  rscale_ = std::sqrt(double(n)) / bnorm;
  const double budget = options.tolerance * bnorm;
  pipeline(1, [&](int, size_t q) { residualPlane(b, x, q); });
  double rnorm = residualNorm();
  // Rounds of at most 1e5 each: the float steps resolve that much of the
  // correction. A well conditioned operator (a 1e6 reduction in at most 48
  // steps: nu dt / h^2 up to about 5 in 2D) takes 1e6, saving a round and
  // its residual pass; further out the float rounding, which grows with the
  // steps, would fall short of 1e6 and cost steps (docs/performance.md).
  const double kRoundFactor = stepsFor(1e6) <= 48 ? 1e6 : 1e5;
  int rounds = 0;
  while (rnorm > budget && result.iterations < options.maxIterations && rounds < 16) {
    // (Cyclic: the reduced system's residual, up to about 1.25 times the
    // full iteration's, whose bound stepsFor follows.)
    const double factor = std::min(rnorm / budget, kRoundFactor) * (cyclic_ ? kCyclicMargin : 1.0);
    const int steps = std::min(stepsFor(factor), options.maxIterations - result.iterations);
    // Steps 2.. (step 1 came with the residual), layout_.stepsPerPass per
    // pass; cyclic, then the colour left at e_{k-1} from the other's e_k
    // by a Jacobi half step, so that its residual is 0.
    const int last = cyclic_ && steps > 1 ? steps + 1 : steps;
    for (int done = 1; done < last;) {
      const int m = std::min(layout_.stepsPerPass, last - done);
      pipeline(m, [&](int t, size_t q) { step(done + t, q, done + t > steps); });
      done += m;
    }
    // x += e / rscale on plane q, then the new residual (and the next
    // round's g) on plane q - 1, whose neighbours are then all updated.
    const float* e0 = work_->e[cyclic_ ? 0 : steps & 1].data();
    const float* e1 = work_->e[1].data();
    pipeline(2, [&](int t, size_t q) {
      if (t == 2) return residualPlane(b, x, q);
      addCorrection(&x, e0, e1, q);
    });
    rnorm = residualNorm();
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
