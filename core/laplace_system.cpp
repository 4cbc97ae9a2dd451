#include "core/laplace_system.h"

#include <cmath>

#include "core/parallel.h"

namespace morphoflow {

namespace {

// Neighbour rows along axes >= 1 of one row. Periodic axes wrap; across a
// non-periodic edge the neighbour row is a row of zeros (no race, no branch).
template <int D>
struct RowStencil {
  size_t base;
  const double* xlo[D];
  const double* xhi[D];
  const float* wlo[D];  // w[a] of the row below (coupling to this row)
};

template <int D>
RowStencil<D> rowStencil(const LaplaceSystem<D>& A, const double* x, const double* zx,
                         const float* zw, size_t row) {
  RowStencil<D> s{};
  const IVec<D>& dims = A.dims;
  size_t nx = size_t(dims[0]), ny = size_t(dims[1]);
  s.base = row * nx;
  size_t y = row % ny, z = D == 3 ? row / ny : 0;
  for (int a = 1; a < D; ++a) {
    size_t k = a == 1 ? y : z, n = size_t(dims[a]);
    size_t stride = a == 1 ? nx : nx * ny;
    bool p = A.periodic[a];
    if (k > 0 || p) {
      size_t lo = k > 0 ? s.base - stride : s.base + (n - 1) * stride;
      s.xlo[a] = x + lo;
      s.wlo[a] = A.w[a].data() + lo;
    } else {
      s.xlo[a] = zx;
      s.wlo[a] = zw;
    }
    if (k + 1 < n || p)
      s.xhi[a] = x + (k + 1 < n ? s.base + stride : s.base - (n - 1) * stride);
    else
      s.xhi[a] = zx;
  }
  return s;
}

}  // namespace

template <int D>
LaplaceSystem<D>::LaplaceSystem(const IVec<D>& d, const std::array<bool, D>& p, double s)
    : dims(d), periodic(p), scale(s), c(d, 0.0f), diag(d, 0.0f) {
  for (int a = 0; a < D; ++a) w[a] = Grid<float, D>(d, 0.0f);
  zerosX_.assign(size_t(d[0]), 0.0);
  zerosW_.assign(size_t(d[0]), 0.0f);
}

template <int D>
void LaplaceSystem<D>::finalize() {
  // Zero the couplings that would wrap across a non-periodic edge.
  for (int a = 0; a < D; ++a) {
    if (periodic[a]) continue;
    forEachCell<D>(dims, [&](const IVec<D>& cell, size_t i) {
      if (cell[a] == dims[a] - 1) w[a][i] = 0.0f;
    });
  }
  invDiag_.assign(size(), 0.0);
  forEachCell<D>(dims, [&](const IVec<D>& cell, size_t i) {
    float d = c[i];
    for (int a = 0; a < D; ++a) {
      IVec<D> lo = cell;
      lo[a] = cell[a] == 0 ? dims[a] - 1 : cell[a] - 1;
      d += w[a][i] + w[a][w[a].index(lo)];
    }
    diag[i] = d;
    invDiag_[i] = d > 0 ? 1.0 / double(d) : 0.0;
  });
  active_ = size_t(deterministicSum(diag.size(), [&](size_t i) { return diag[i] > 0 ? 1.0 : 0.0; }));
  singular_ = deterministicMax(c.size(), [&](size_t i) { return c[i]; }) <= 0.0;
}

// Neighbour sum sum_f w_f x_j(f) of cell i of a row; il/ih are the x
// neighbours (wrapped) and wl the weight of the low x face.
template <int D>
inline double neighbourSum(const RowStencil<D>& s, const float* const* wa, const double* xr, size_t i,
                           size_t il, size_t ih, float wl) {
  double sum = double(wa[0][i]) * xr[ih] + double(wl) * xr[il];
  for (int a = 1; a < D; ++a) sum += double(wa[a][i]) * s.xhi[a][i] + double(s.wlo[a][i]) * s.xlo[a][i];
  return sum;
}

// Face sum sum_f w_f (x_i - x_j(f)): with the c term this is A x, written so
// that every face's two contributions cancel to round-off (mass conservation
// does not rest on a float diagonal matching its weights).
template <int D>
inline double faceSum(const RowStencil<D>& s, const float* const* wa, const double* xr, size_t i, size_t il,
                      size_t ih, float wl) {
  const double xi = xr[i];
  double sum = double(wa[0][i]) * (xi - xr[ih]) + double(wl) * (xi - xr[il]);
  for (int a = 1; a < D; ++a)
    sum += double(wa[a][i]) * (xi - s.xhi[a][i]) + double(s.wlo[a][i]) * (xi - s.xlo[a][i]);
  return sum;
}

template <int D>
void LaplaceSystem<D>::apply(const Vector& x, Vector* yp) const {
  Vector& y = *yp;
  const size_t nx = size_t(dims[0]);
  const bool px = periodic[0];
  parallelForRows<D>(dims, [&](size_t row) {
    RowStencil<D> s = rowStencil<D>(*this, x.data(), zerosX_.data(), zerosW_.data(), row);
    const float* wa[D];
    for (int a = 0; a < D; ++a) wa[a] = w[a].data() + s.base;
    const float* cr = c.data() + s.base;
    const double* xr = x.data() + s.base;
    double* yr = y.data() + s.base;
    auto edge = [&](size_t i) {
      size_t il = i == 0 ? nx - 1 : i - 1, ih = i + 1 == nx ? 0 : i + 1;
      float wl = (i == 0 && !px) ? 0.0f : wa[0][il];
      yr[i] = scale * (double(cr[i]) * xr[i] + faceSum<D>(s, wa, xr, i, il, ih, wl));
    };
    edge(0);
    for (size_t i = 1; i + 1 < nx; ++i)  // interior: no wrap, no branch
      yr[i] = scale * (double(cr[i]) * xr[i] + faceSum<D>(s, wa, xr, i, i - 1, i + 1, wa[0][i - 1]));
    if (nx > 1) edge(nx - 1);
  });
}

template <int D>
double LaplaceSystem<D>::residual(const Vector& b, const Vector& x, Vector* r) const {
  apply(x, r);
  Vector& rr = *r;
  parallelFor(rr.size(), [&](size_t i) { rr[i] = diag[i] > 0 ? b[i] - rr[i] : 0.0; }, 4096);
  return norm2(rr);
}

template <int D>
void LaplaceSystem<D>::gaussSeidel(const Vector& b, Vector* xp, bool reverse) const {
  Vector& x = *xp;
  const size_t nx = size_t(dims[0]);
  const bool px = periodic[0];
  const double inv = 1.0 / scale;
  // An odd periodic axis couples cells of one colour across the wrap: run
  // such systems row by row so the sweep stays deterministic and race-free.
  bool serial = false;
  for (int a = 1; a < D; ++a) serial |= periodic[a] && (dims[a] % 2 == 1);
  size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= size_t(dims[a]);
  for (int pass = 0; pass < 2; ++pass) {
    int colour = reverse ? 1 - pass : pass;
    auto sweepRow = [&](size_t row) {
      RowStencil<D> s = rowStencil<D>(*this, x.data(), zerosX_.data(), zerosW_.data(), row);
      size_t parity = row % size_t(dims[1]);
      if constexpr (D == 3) parity += row / size_t(dims[1]);
      const float* wa[D];
      for (int a = 0; a < D; ++a) wa[a] = w[a].data() + s.base;
      const double* rd = invDiag_.data() + s.base;
      const double* br = b.data() + s.base;
      double* xr = x.data() + s.base;
      // x_i = (b_i / scale + sum_f w_f x_j) / diag_i; invDiag is 0 on inactive cells.
      auto edge = [&](size_t i) {
        size_t il = i == 0 ? nx - 1 : i - 1, ih = i + 1 == nx ? 0 : i + 1;
        float wl = (i == 0 && !px) ? 0.0f : wa[0][il];
        xr[i] = (br[i] * inv + neighbourSum<D>(s, wa, xr, i, il, ih, wl)) * rd[i];
      };
      size_t i = (size_t(colour) + parity) & 1;
      if (i == 0) {
        edge(0);
        i = 2;
      }
      for (; i + 1 < nx; i += 2)
        xr[i] = (br[i] * inv + neighbourSum<D>(s, wa, xr, i, i - 1, i + 1, wa[0][i - 1])) * rd[i];
      if (i + 1 == nx && nx > 1) edge(i);
    };
    if (serial)
      for (size_t r = 0; r < rows; ++r) sweepRow(r);
    else
      parallelForRows<D>(dims, sweepRow);
  }
}

template <int D>
void LaplaceSystem<D>::removeNullSpace(Vector* xp) const {
  Vector& x = *xp;
  if (active_ == 0) return;
  double mean = deterministicSum(x.size(), [&](size_t i) { return diag[i] > 0 ? x[i] : 0.0; }) /
                double(active_);
  parallelFor(x.size(), [&](size_t i) { x[i] = diag[i] > 0 ? x[i] - mean : 0.0; }, 4096);
}

template <int D>
LaplaceSystem<D> makeNeumannLaplacian(const IVec<D>& dims, const std::array<bool, D>& periodic,
                                      double h) {
  LaplaceSystem<D> s(dims, periodic, 1.0 / (h * h));
  for (int a = 0; a < D; ++a) s.w[a].fill(1.0f);
  s.finalize();
  return s;
}

double dot(const Vector& a, const Vector& b) {
  return deterministicSum(a.size(), [&](size_t i) { return a[i] * b[i]; });
}
double norm2(const Vector& a) { return std::sqrt(dot(a, a)); }
void axpy(double alpha, const Vector& x, Vector* y) {
  Vector& yy = *y;
  parallelFor(x.size(), [&](size_t i) { yy[i] += alpha * x[i]; }, 4096);
}

template struct LaplaceSystem<2>;
template struct LaplaceSystem<3>;
template LaplaceSystem<2> makeNeumannLaplacian<2>(const IVec<2>&, const std::array<bool, 2>&, double);
template LaplaceSystem<3> makeNeumannLaplacian<3>(const IVec<3>&, const std::array<bool, 3>&, double);

}  // namespace morphoflow
