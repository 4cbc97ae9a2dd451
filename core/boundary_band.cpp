#include "core/boundary_band.h"

#include <algorithm>
#include <limits>

#include "core/parallel.h"

namespace morphoflow {

namespace {

// Cell k's neighbour one step along axis a (side -1 or +1), wrapped across a
// periodic axis; false beyond a wall.
template <int D>
bool neighbour(const LaplaceSystem<D>& A, const IVec<D>& k, int a, int side, size_t* j) {
  bool inside = true;
  *j = shiftedIndex<D>(A.dims, A.periodic, k, side * unitVector<D>(a), &inside);
  return inside;
}

// The active cells either side of the faces of axis a with a weight below 1
// inside the domain, appended to *cells. Each stored row of weights is
// scanned once: most rows share the uniform one.
template <int D>
void cutFaceCells(const LaplaceSystem<D>& A, int a, std::vector<uint32_t>* cells) {
  const RowField<D>& w = A.w[a];
  const size_t nx = size_t(A.dims[0]), rows = A.size() / nx;
  // x < last: the faces inside the domain along x
  const size_t last = a == 0 && !A.periodic[0] ? nx - 1 : nx;
  std::vector<uint8_t> cut(w.storedRows());
  parallelFor(cut.size(), [&](size_t k) {
    const float* row = w.stored(uint32_t(k));
    cut[k] = std::any_of(row, row + last, [](float v) { return v < 1.0f; });
  });
  std::vector<std::vector<uint32_t>> found(rows);
  parallelFor(
      rows,
      [&](size_t r) {
        if (!cut[w.storedRow(r)]) return;
        const IVec<D> first = A.diag.coord(r * nx);
        if (a > 0 && first[a] + 1 == A.dims[a] && !A.periodic[a]) return;  // the faces across the wall
        const float* row = w.row(r);
        for (size_t x = 0; x < last; ++x) {
          if (!(row[x] < 1.0f)) continue;
          IVec<D> k = first;
          k[0] = int(x);
          const size_t i = r * nx + x;
          size_t j = 0;
          neighbour<D>(A, k, a, 1, &j);
          for (size_t c : {i, j})
            if (A.diag[c] > 0.0f) found[r].push_back(uint32_t(c));
        }
      },
      64);
  for (const std::vector<uint32_t>& f : found) cells->insert(cells->end(), f.begin(), f.end());
}

void sortUnique(std::vector<uint32_t>* v) {
  std::sort(v->begin(), v->end());
  v->erase(std::unique(v->begin(), v->end()), v->end());
}

}  // namespace

template <int D>
BoundaryBand<D> boundaryBand(const LaplaceSystem<D>& A, int width) {
  BoundaryBand<D> band;
  if (A.size() == 0 || A.size() > size_t(std::numeric_limits<uint32_t>::max())) return band;
  std::vector<uint32_t> cells;
  for (int a = 0; a < D; ++a) cutFaceCells<D>(A, a, &cells);
  sortUnique(&cells);
  for (int step = 0; step < width; ++step) {  // one face further
    std::vector<uint32_t> grown = cells;
    for (uint32_t i : cells) {
      const IVec<D> k = A.diag.coord(i);
      for (int a = 0; a < D; ++a)
        for (int side : {-1, 1}) {
          size_t j = 0;
          if (neighbour<D>(A, k, a, side, &j) && A.diag[j] > 0.0f) grown.push_back(uint32_t(j));
        }
    }
    sortUnique(&grown);
    cells.swap(grown);
  }
  for (uint32_t i : cells) {
    const IVec<D> k = A.diag.coord(i);
    int parity = 0;
    for (int a = 0; a < D; ++a) parity += k[a];
    band.colour[size_t(parity & 1)].push_back(i);
  }
  for (size_t c = 0; c < 2; ++c) {
    const std::vector<uint32_t>& of = band.colour[c];
    band.stencil[c].resize(of.size());
    parallelFor(
        of.size(),
        [&](size_t n) {
          const size_t i = of[n];
          const IVec<D> k = A.diag.coord(i);
          BandStencil<D>& s = band.stencil[c][n];
          for (int a = 0; a < D; ++a) {
            size_t lo = 0, hi = 0;
            const bool hasLo = neighbour<D>(A, k, a, -1, &lo), hasHi = neighbour<D>(A, k, a, 1, &hi);
            s.j[size_t(2 * a)] = uint32_t(hasLo ? lo : i);  // (beyond a wall: itself, weight 0)
            s.w[size_t(2 * a)] = hasLo ? A.w[a][lo] : 0.0f;
            s.j[size_t(2 * a + 1)] = uint32_t(hasHi ? hi : i);
            s.w[size_t(2 * a + 1)] = hasHi ? A.w[a][i] : 0.0f;
          }
          s.inv = A.invDiag(i);
        },
        1024);
  }
  return band;
}

template <int D, class T>
void sweepBand(const LaplaceSystem<D>& A, const BoundaryBand<D>& band, const T* b, T* x, bool reverse) {
  const T inv = T(1.0 / A.scale);
  for (int q = 0; q < 2; ++q) {
    const size_t c = size_t(reverse ? 1 - q : q);
    const uint32_t* cells = band.colour[c].data();
    const BandStencil<D>* stencil = band.stencil[c].data();
    // (a colour's cells read the other colour only: in any order, in parallel)
    parallelFor(
        band.colour[c].size(),
        [&](size_t n) {
          const BandStencil<D>& s = stencil[n];
          const size_t i = cells[n];
          T sum = b[i] * inv;
          for (size_t k = 0; k < 2 * D; ++k) sum += T(s.w[k]) * x[s.j[k]];
          x[i] = sum * T(s.inv);
        },
        1024);
  }
}

template BoundaryBand<2> boundaryBand<2>(const LaplaceSystem<2>&, int);
template BoundaryBand<3> boundaryBand<3>(const LaplaceSystem<3>&, int);
template void sweepBand<2, float>(const LaplaceSystem<2>&, const BoundaryBand<2>&, const float*, float*, bool);
template void sweepBand<3, float>(const LaplaceSystem<3>&, const BoundaryBand<3>&, const float*, float*, bool);
template void sweepBand<2, double>(const LaplaceSystem<2>&, const BoundaryBand<2>&, const double*, double*, bool);
template void sweepBand<3, double>(const LaplaceSystem<3>&, const BoundaryBand<3>&, const double*, double*, bool);

}  // namespace morphoflow
