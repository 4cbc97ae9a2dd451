// Whether the GL driver runs Kim & Lin's implicit reaction (the per-cell
// Newton of kernels/newton.inc in rd_react.comp) in the double precision it
// is written in. Some drivers do not: NVIDIA's 580 driver on an H200 holds
// the Newton's arrays at single precision (the inputs lose everything past
// 2^-24), so Newton cannot meet its 1e-12 tolerance and fails in most cells.
// The GPU backend refuses Kim & Lin's integrator on such a driver rather than
// run it wrongly (sim/steppers.cpp).
#pragma once

#include <string>

namespace morphoflow {

// "" when one stiff implicit step of `model` (default parameters, 10 times
// its fastest rate, 128 cells) on the GPU agrees with the CPU's to 1e-9 of the
// step's change and fails in no more cells; otherwise what differed. Checked
// once per model and process.
std::string gpuNewtonDefect(const std::string& model);

}  // namespace morphoflow
