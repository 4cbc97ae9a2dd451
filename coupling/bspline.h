// Cubic B-spline interpolation of cell-centred samples (Unser 1999): the
// coefficients c solve (c[i-1] + 4 c[i] + c[i+1]) / 6 = f[i] along every
// axis, by the recursive filter with pole z = sqrt(3) - 2 (a causal and an
// anti-causal pass per line), with mirror-symmetric walls (f[-k] = f[k]) or
// periodic axes; the spline through them interpolates f with fourth-order
// accuracy. The chemicals' bspline advection samples it at each foot and
// clamps the value to the range of the foot's 2^D cell neighbours, so no
// species leaves its bounds or turns negative.
#pragma once

#include <array>

#include "core/grid.h"

namespace morphoflow {

// c <- the coefficients of f (c may be f's own storage).
template <int D>
void bsplineCoefficients(const Grid<double, D>& f, const std::array<bool, D>& periodic, Grid<double, D>* c);

// The spline of coefficients `c` at grid coordinate x (cell centres at
// integers; walls clamp x, periodic axes wrap), clamped to the range of
// f's 2^D cells around x.
template <int D>
double sampleBSpline(const Grid<double, D>& c, const Grid<double, D>& f, const std::array<bool, D>& periodic,
                     const Vec<D>& x);

}  // namespace morphoflow
