// The GPU's real vectors (core/backend.h's GpuPrecision): their element
// size, the shaders' REAL type for them, and the host's doubles written to
// and read from them (exact both ways in double; rounded to nearest into float).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/backend.h"
#include "gpu/gpu_buffer.h"

namespace morphoflow {

constexpr size_t realBytes(GpuPrecision p) { return p == GpuPrecision::Float ? 4 : 8; }
// The #defines the real shaders take: REAL (float or double), REAL2, REAL3,
// XREAL (a Krylov solve's solution: `solution`'s type, e.g. a float solve's
// pressure kept in double),
// REAL_HUGE (a value past every field's) and REAL_TINY (the smallest normal
// magnitude Newton's pivots are compared with); REAL_IS_DOUBLE in double.
std::string realDefines(GpuPrecision p, GpuPrecision solution);
// The smallest relative residual a Krylov solve is asked for in `p`: 0 in
// double; in float 4e-6, what float's vectors reach with double sums (a
// scene's smaller tolerance is raised to it: sim/steppers.h raisedTolerances).
constexpr double toleranceFloor(GpuPrecision p) { return p == GpuPrecision::Float ? 4e-6 : 0.0; }
// A buffer of n reals (zeroed).
GpuBuffer realBuffer(size_t n, GpuPrecision p);
// A buffer holding `values` in p.
GpuBuffer realBuffer(const std::vector<double>& values, GpuPrecision p);
void uploadReals(GpuBuffer* b, const std::vector<double>& values, GpuPrecision p, size_t firstElement = 0);
std::vector<double> readReals(const GpuBuffer& b, size_t n, GpuPrecision p, size_t firstElement = 0);

}  // namespace morphoflow
