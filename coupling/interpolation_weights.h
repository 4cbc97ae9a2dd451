// The chemicals' interpolation weights (Catmull-Rom, cubic B-spline) from
// kernels/interpolation.inc, shared with the GPU (kernels/README.md).
#pragma once

namespace morphoflow {

#define WEIGHTS4(name, t, w) inline void name(double t, double* w)
#define PRECISE
#define W_REAL double
#include "kernels/interpolation.inc"
#undef WEIGHTS4
#undef PRECISE
#undef W_REAL

}  // namespace morphoflow
