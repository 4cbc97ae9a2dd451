#include "core/boundary_band.h"

#include <algorithm>
#include <atomic>
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

// The band's marks: a cell's 0 (not in it) or s + 1 (reached at step s, 1
// beside a cut face), a row's 1 when any of its cells is marked. Cells are
// marked from any thread, with one value a step: relaxed atomics.
void mark(BandMarks* m, size_t i, size_t nx, uint8_t s) {
  std::atomic_ref<uint8_t>(m->cell[i]).store(s, std::memory_order_relaxed);
  std::atomic_ref<uint8_t>(m->row[i / nx]).store(1, std::memory_order_relaxed);
}
uint8_t markOf(const BandMarks& m, size_t i) {
  return std::atomic_ref<const uint8_t>(m.cell[i]).load(std::memory_order_relaxed);
}

// The active cells either side of the faces of axis a with a weight below 1
// inside the domain, marked 1. Each stored row of weights is scanned once:
// most rows share the uniform one.
template <int D>
void markCutFaceCells(const LaplaceSystem<D>& A, int a, BandMarks* marks) {
  const RowField<D>& w = A.w[a];
  const size_t nx = size_t(A.dims[0]), rows = A.size() / nx;
  // x < last: the faces inside the domain along x
  const size_t last = a == 0 && !A.periodic[0] ? nx - 1 : nx;
  std::vector<uint8_t> cut(w.storedRows());
  parallelFor(cut.size(), [&](size_t k) {
    const float* row = w.stored(uint32_t(k));
    cut[k] = std::any_of(row, row + last, [](float v) { return v < 1.0f; });
  });
  parallelFor(
      rows,
      [&](size_t r) {
        if (!cut[w.storedRow(r)]) return;
        const IVec<D> first = A.diag.coord(r * nx);
        if (a > 0 && first[a] + 1 == A.dims[a] && !A.periodic[a]) return;  // the faces across the wall
        // the cells beyond the row's faces: the next along x, or the next row's along a
        size_t next = 0;
        if (a > 0) neighbour<D>(A, first, a, 1, &next);
        const float* row = w.row(r);
        const float* diag = A.diag.row(r);
        const float* diagNext = a == 0 ? diag : A.diag.row(next / nx);
        for (size_t x = 0; x < last; ++x) {
          if (!(row[x] < 1.0f)) continue;
          const size_t j = a == 0 ? (x + 1 == nx ? r * nx : r * nx + x + 1) : next + x;  // (x + 1 == nx: periodic)
          if (diag[x] > 0.0f) mark(marks, r * nx + x, nx, 1);
          if (diagNext[j % nx] > 0.0f) mark(marks, j, nx, 1);
        }
      },
      64);
}

// Step s of the growth: the active unmarked neighbours of the cells marked s, marked s + 1.
template <int D>
void growMarks(const LaplaceSystem<D>& A, uint8_t s, BandMarks* marks) {
  const size_t nx = size_t(A.dims[0]);
  parallelFor(
      marks->row.size(),
      [&](size_t r) {
        if (!std::atomic_ref<const uint8_t>(marks->row[r]).load(std::memory_order_relaxed)) return;
        const IVec<D> first = A.diag.coord(r * nx);
        for (size_t x = 0; x < nx; ++x) {
          if (markOf(*marks, r * nx + x) != s) continue;
          IVec<D> k = first;
          k[0] = int(x);
          for (int a = 0; a < D; ++a)
            for (int side : {-1, 1}) {
              size_t j = 0;
              if (neighbour<D>(A, k, a, side, &j) && A.diag[j] > 0.0f && markOf(*marks, j) == 0)
                mark(marks, j, nx, s + 1);
            }
        }
      },
      64);
}

// Cell i's (at k) stencil as A holds it now.
template <int D>
BandStencil<D> bandStencil(const LaplaceSystem<D>& A, const IVec<D>& k, size_t i) {
  BandStencil<D> s;
  for (int a = 0; a < D; ++a) {
    size_t lo = 0, hi = 0;
    const bool hasLo = neighbour<D>(A, k, a, -1, &lo), hasHi = neighbour<D>(A, k, a, 1, &hi);
    s.j[size_t(2 * a)] = uint32_t(hasLo ? lo : i);  // (beyond a wall: itself, weight 0)
    s.w[size_t(2 * a)] = hasLo ? A.w[a][lo] : 0.0f;
    s.j[size_t(2 * a + 1)] = uint32_t(hasHi ? hi : i);
    s.w[size_t(2 * a + 1)] = hasHi ? A.w[a][i] : 0.0f;
  }
  s.inv = A.invDiag(i);
  return s;
}

}  // namespace

template <int D>
BoundaryBand<D> boundaryBand(const LaplaceSystem<D>& A, int width, BandMarks* kept) {
  BoundaryBand<D> band;
  if (A.size() == 0 || A.size() > size_t(std::numeric_limits<uint32_t>::max()) || width > 250) return band;
  const size_t nx = size_t(A.dims[0]), rows = A.size() / nx;
  BandMarks own;
  BandMarks& marks = kept ? *kept : own;
  if (marks.cell.size() < A.size()) marks.cell.assign(A.size(), 0);
  if (marks.row.size() < rows) marks.row.assign(rows, 0);
  for (int a = 0; a < D; ++a) markCutFaceCells<D>(A, a, &marks);
  for (int s = 1; s <= width; ++s) growMarks<D>(A, uint8_t(s), &marks);  // one face further
  // Each colour's cells in ascending order: counted row by row, then placed.
  std::vector<std::array<size_t, 2>> at(rows + 1, {0, 0});
  parallelFor(
      rows,
      [&](size_t r) {
        if (!marks.row[r]) return;
        const IVec<D> first = A.diag.coord(r * nx);
        int parity = 0;
        for (int a = 1; a < D; ++a) parity += first[a];
        for (size_t x = 0; x < nx; ++x)
          if (marks.cell[r * nx + x]) ++at[r + 1][size_t((parity + int(x)) & 1)];
      },
      64);
  for (size_t r = 0; r < rows; ++r)
    for (size_t c = 0; c < 2; ++c) at[r + 1][c] += at[r][c];
  for (size_t c = 0; c < 2; ++c) {
    band.colour[c].resize(at[rows][c]);
    band.stencil[c].resize(at[rows][c]);
  }
  parallelFor(
      rows,
      [&](size_t r) {
        if (!marks.row[r]) return;
        std::array<size_t, 2> next = at[r];
        IVec<D> k = A.diag.coord(r * nx);
        int parity = 0;
        for (int a = 1; a < D; ++a) parity += k[a];
        for (size_t x = 0; x < nx; ++x) {
          const size_t i = r * nx + x;
          if (!marks.cell[i]) continue;
          k[0] = int(x);
          const size_t c = size_t((parity + int(x)) & 1), n = next[c]++;
          band.colour[c][n] = uint32_t(i);
          band.stencil[c][n] = bandStencil<D>(A, k, i);
        }
        std::fill_n(marks.cell.data() + r * nx, nx, uint8_t(0));  // (all zero for the next call)
        marks.row[r] = 0;
      },
      64);
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

template BoundaryBand<2> boundaryBand<2>(const LaplaceSystem<2>&, int, BandMarks*);
template BoundaryBand<3> boundaryBand<3>(const LaplaceSystem<3>&, int, BandMarks*);
template void sweepBand<2, float>(const LaplaceSystem<2>&, const BoundaryBand<2>&, const float*, float*, bool);
template void sweepBand<3, float>(const LaplaceSystem<3>&, const BoundaryBand<3>&, const float*, float*, bool);
template void sweepBand<2, double>(const LaplaceSystem<2>&, const BoundaryBand<2>&, const double*, double*, bool);
template void sweepBand<3, double>(const LaplaceSystem<3>&, const BoundaryBand<3>&, const double*, double*, bool);

}  // namespace morphoflow
