// The device's copy bandwidth, measured as FluidX3D reports its own: a
// kernel that reads and writes every byte once (shaders/copy.comp, a float4
// each invocation), the bytes read and written over the time, the median of
// five dispatches after a warm-up, in GB/s. The GPU suites give each
// figure as a fraction of it beside the fraction of the data sheet's peak.
#pragma once

#include <cstddef>

namespace morphoflow {

double measureCopyBandwidth(size_t bytes);

}  // namespace morphoflow
