// The neighbour rows of one row of a LaplaceSystem, shared by its kernels
// (A x, the smoother) and by the Chebyshev iteration's sweeps. Internal to
// core/: include it from kernels' .cpp files only.
#pragma once

#include <cstddef>

#include "core/laplace_system.h"

namespace morphoflow {

// Neighbour rows along axes >= 1 of one row. Periodic axes wrap; across a
// non-periodic edge the neighbour row is a row of zeros (no race, no branch).
template <int D, class T>
struct RowStencil {
  size_t base;
  const T* xlo[D];
  const T* xhi[D];
  const float* wlo[D];  // w[a] of the row below (coupling to this row)
};

// Row `row` at coordinates y (and z) along axes 1 (and 2). `rowLength`:
// the values x holds a row (0: the grid's; the cyclic Chebyshev iteration's
// colours hold half a row each).
template <int D, class T>
inline RowStencil<D, T> rowStencil(const LaplaceSystem<D>& A, const T* x, const T* zx, const float* zw, size_t row,
                                   size_t y, size_t z, size_t rowLength = 0) {
  RowStencil<D, T> s{};
  const IVec<D>& dims = A.dims;
  size_t nx = rowLength ? rowLength : size_t(dims[0]), ny = size_t(dims[1]);
  s.base = row * nx;
  for (int a = 1; a < D; ++a) {
    size_t k = a == 1 ? y : z, n = size_t(dims[a]);
    size_t stride = a == 1 ? nx : nx * ny;
    bool p = A.periodic[a];
    if (k > 0 || p) {
      size_t lo = k > 0 ? s.base - stride : s.base + (n - 1) * stride;
      s.xlo[a] = x + lo;
      s.wlo[a] = A.w[a].row(lo / nx);
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

template <int D, class T>
inline RowStencil<D, T> rowStencil(const LaplaceSystem<D>& A, const T* x, const T* zx, const float* zw, size_t row) {
  const size_t ny = size_t(A.dims[1]);
  return rowStencil<D, T>(A, x, zx, zw, row, row % ny, D == 3 ? row / ny : 0);
}

// Neighbour sum sum_f w_f x_j(f) of cell i of a row; il/ih are the x
// neighbours (wrapped) and wl the weight of the low x face.
template <int D, class T>
inline T neighbourSum(const RowStencil<D, T>& s, const float* const* wa, const T* xr, size_t i, size_t il,
                      size_t ih, float wl) {
  T sum = T(wa[0][i]) * xr[ih] + T(wl) * xr[il];
  for (int a = 1; a < D; ++a) sum += T(wa[a][i]) * s.xhi[a][i] + T(s.wlo[a][i]) * s.xlo[a][i];
  return sum;
}

}  // namespace morphoflow
