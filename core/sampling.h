// Linear (bi-/trilinear) sampling of a grid at a continuous position.
//
// A Layout says where sample k of a grid sits in world space:
//   x_a = (k_a + offset_a) * h, with offset 0.5 for cell centres and 0 for
// faces normal to a. Periodic axes wrap with period = cell count along the
// axis; other axes clamp to the outermost samples.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "core/grid.h"
#include "core/multilinear.h"

namespace morphoflow {

template <int D>
struct Layout {
  double h = 1.0;                       // cell size
  Vec<D> offset{0.5};                   // sample offset in cells
  std::array<bool, D> periodic{};       // wrap along this axis
  IVec<D> period{0};                    // cell count (wrap period) per axis

  static Layout cellCentred(double h, const IVec<D>& cells, const std::array<bool, D>& periodic) {
    Layout l;
    l.h = h;
    l.offset = Vec<D>(0.5);
    l.periodic = periodic;
    l.period = cells;
    return l;
  }
  static Layout face(int axis, double h, const IVec<D>& cells, const std::array<bool, D>& periodic) {
    Layout l = cellCentred(h, cells, periodic);
    l.offset[axis] = 0.0;
    return l;
  }
  // Continuous grid coordinate of a world position.
  Vec<D> toGrid(const Vec<D>& x) const { return x / h - offset; }
  Vec<D> toWorld(const IVec<D>& k) const { return (Vec<D>(k) + offset) * h; }
};

// A grid coordinate every sampler can index with: NaN (the trace through a
// diverged velocity) becomes 0 and magnitudes beyond 2^30 cells are capped,
// so the conversions to int stay defined; coordinates in range pass as they are.
inline double boundedCoordinate(double g) {
  constexpr double kMax = double(1 << 30);
  if (g >= -kMax && g <= kMax) return g;
  return g > 0.0 ? kMax : (g < 0.0 ? -kMax : 0.0);
}

namespace detail {
// Lower sample index and weight of the upper one along one axis.
inline void axisStencil(double g, int n, bool periodic, int period, int* i0, int* i1, double* t) {
  g = boundedCoordinate(g);
  if (periodic) {
    double f = std::floor(g);
    *t = g - f;
    int i = int(f) % period;
    if (i < 0) i += period;
    *i0 = i;
    *i1 = (i + 1) % period;
    // Face grids carry one extra sample equal to sample 0; cells wrap.
    if (n > period && *i1 == 0) *i1 = period;
    return;
  }
  g = std::clamp(g, 0.0, double(n - 1));
  int i = std::min(int(g), n - 2 < 0 ? 0 : n - 2);
  *i0 = i;
  *i1 = std::min(i + 1, n - 1);
  *t = g - i;
}
}  // namespace detail

// Bi-/trilinear interpolation of g between the samples i0 and i1 along each
// axis, weight t of i1; lo/hi (both or neither) receive the 2^D samples' min
// and max.
template <typename T, int D>
T interpolateStencil(const Grid<T, D>& g, const int* i0, const int* i1, const double* t, T* lo = nullptr,
                     T* hi = nullptr) {
  size_t s1 = size_t(g.dim(0));
  auto at = [&](int x0, int y0, int z0) -> T {
    size_t idx = size_t(x0) + s1 * size_t(y0);
    if constexpr (D == 3) idx += s1 * size_t(g.dim(1)) * size_t(z0);
    return g[idx];
  };
  T result;
  T mn, mx;
  if constexpr (D == 2) {
    T v00 = at(i0[0], i0[1], 0), v10 = at(i1[0], i0[1], 0);
    T v01 = at(i0[0], i1[1], 0), v11 = at(i1[0], i1[1], 0);
    result = bilinear(v00, v10, v01, v11, T(t[0]), T(t[1]));
    if (lo) {
      mn = std::min({v00, v10, v01, v11});
      mx = std::max({v00, v10, v01, v11});
    }
  } else {
    T v[8];
    for (int k = 0; k < 8; ++k)
      v[k] = at((k & 1) ? i1[0] : i0[0], (k & 2) ? i1[1] : i0[1], (k & 4) ? i1[2] : i0[2]);
    result = trilinear(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], T(t[0]), T(t[1]), T(t[2]));
    if (lo) {
      mn = *std::min_element(v, v + 8);
      mx = *std::max_element(v, v + 8);
    }
  }
  if (lo) {
    *lo = mn;
    *hi = mx;
  }
  return result;
}

// Sample `g` at world position x. If lo/hi are given, they receive the
// minimum and maximum of the 2^D samples used (for limiters).
template <typename T, int D>
T sampleLinear(const Grid<T, D>& g, const Layout<D>& layout, const Vec<D>& x, T* lo = nullptr,
               T* hi = nullptr) {
  Vec<D> gc = layout.toGrid(x);
  int i0[D], i1[D];
  double t[D];
  for (int a = 0; a < D; ++a)
    detail::axisStencil(gc[a], g.dim(a), layout.periodic[a], layout.period[a], &i0[a], &i1[a],
                        &t[a]);
  return interpolateStencil<T, D>(g, i0, i1, t, lo, hi);
}

}  // namespace morphoflow
