// kernels/obstacle_shape.inc in C++: an obstacle's signed distance and a
// rigid body's velocity, written once for the CPU and the
// GPU (gpu/shaders/cut_geometry.comp; kernels/README.md).
#pragma once

#include <cmath>

namespace morphoflow::obstacle_shape {

#define OS_REAL double
#define OS_FN inline double
#define OS_VOID inline void
#define OS_IN3(name) const double* name
#define OS_IN9(name) const double* name
#define OS_OUT3(name) double* name
#define OS_SQRT std::sqrt
#define OS_ABS std::abs
#define OS_TRUNC std::trunc
#define OS_LIT(v) v
#define OS_PRECISE
#define OS_TEXEL(i) double(field[i])
#define OS_FIELD_PARAM const float *field,
#define OS_FIELD_ARG field,
#include "kernels/obstacle_shape.inc"
#undef OS_REAL
#undef OS_FN
#undef OS_VOID
#undef OS_IN3
#undef OS_IN9
#undef OS_OUT3
#undef OS_SQRT
#undef OS_ABS
#undef OS_TRUNC
#undef OS_LIT
#undef OS_PRECISE
#undef OS_TEXEL
#undef OS_FIELD_PARAM
#undef OS_FIELD_ARG

}  // namespace morphoflow::obstacle_shape
