// Whether the GL driver computes Kim & Lin's implicit reaction (the per-cell
// Newton of kernels/newton.inc in rd_react.comp) correctly in a precision.
// Some drivers do not in double: NVIDIA's 580 driver on an H200 holds the
// Newton's double arrays at single precision (the inputs lose everything
// past 2^-24), so Newton cannot meet its double tolerance and fails in most
// cells. The GPU backend refuses a scene whose precision the driver gets
// wrong rather than run it wrongly (sim/steppers.cpp); float, the default,
// is every driver's native arithmetic.
#pragma once

#include <string>

#include "core/backend.h"

namespace morphoflow {

// "" when one stiff implicit step of `model` (default parameters, 10 times
// its fastest rate, 128 cells) on the GPU in `real` agrees with the CPU's
// (to 1e-9 of the step's change in every cell in double; to 1e-4 in all but
// 1 cell in 32 in float) and fails in no more cells; otherwise what differed. Checked once per model, precision and
// process.
std::string gpuNewtonDefect(const std::string& model, GpuPrecision real);

}  // namespace morphoflow
