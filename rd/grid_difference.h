// Central difference of a cell-centred field along one axis, in cells (the
// grid spacing cancels wherever only the gradient's direction matters):
// wrapped on periodic axes, one-sided at walls.
#pragma once

#include "core/grid.h"

namespace morphoflow {

template <int D>
double centralDifference(const Grid<double, D>& u, const IVec<D>& c, int a, bool periodic) {
  const int n = u.dim(a);
  IVec<D> lo = c, hi = c;
  lo[a] = c[a] - 1;
  hi[a] = c[a] + 1;
  double span = 2.0;
  if (periodic) {
    lo[a] = (lo[a] + n) % n;
    hi[a] = hi[a] % n;
  } else {
    if (lo[a] < 0) lo[a] = 0, span = 1.0;
    if (hi[a] >= n) hi[a] = n - 1, span = 1.0;
  }
  return (u[u.index(hi)] - u[u.index(lo)]) / span;
}

}  // namespace morphoflow
