// The boundary band of a LaplaceSystem: its active cells beside a face that
// an obstacle cuts or closes (a weight below 1 between two cells of the
// domain), and the active cells within `width` faces of those. A multigrid
// level smooths its band more than the rest (McAdams, Sifakis & Teran
// 2010's boundary smoothing): there the coarse levels' averaged fractions
// stand in worst for the fine ones, and the cycle leaves its largest error.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/laplace_system.h"

namespace morphoflow {

// A band cell's update, x_i = (b_i / scale + sum_k w_k x_{j_k}) inv, with
// the system's coefficients when the band was found: its neighbours low
// and high along each axis (itself with weight 0 beyond a wall).
template <int D>
struct BandStencil {
  std::array<uint32_t, 2 * D> j;
  std::array<float, 2 * D> w;
  float inv;  // 1 / diag_i
};

template <int D>
struct BoundaryBand {
  // The band's cells of colour (x + y (+ z)) % 2 == 0 and 1, ascending,
  // and their stencils.
  std::array<std::vector<uint32_t>, 2> colour;
  std::array<std::vector<BandStencil<D>>, 2> stencil;

  bool empty() const { return colour[0].empty() && colour[1].empty(); }
  size_t size() const { return colour[0].size() + colour[1].size(); }
};

// Marks a band is found with, a byte a cell and a byte a row: all zero
// between calls, so a caller that finds bands often (a moving obstacle's
// multigrid, every step) keeps them and skips their clearing.
struct BandMarks {
  std::vector<uint8_t> cell, row;
};

// A's band (none on a system of 2^32 cells or more); marks: kept for the
// next call, or none.
template <int D>
BoundaryBand<D> boundaryBand(const LaplaceSystem<D>& A, int width, BandMarks* marks = nullptr);

// One red-black Gauss-Seidel sweep of A on the band's cells alone, colour 0
// first (1 first when `reverse`, the first's adjoint): x_i = (b_i / scale +
// sum_f w_f x_j) / diag_i, A's coefficients as the band holds them. A's
// colours must not meet across a periodic axis (an even count of cells
// along each).
template <int D, class T>
void sweepBand(const LaplaceSystem<D>& A, const BoundaryBand<D>& band, const T* b, T* x, bool reverse);

}  // namespace morphoflow
