// `morphoflow bench memory`: the peak memory per cell of fluid, reaction-
// diffusion and coupled runs in 2D and 3D. Each case is a short run of a
// shipped scene in a process of its own (peak memory only grows within a
// process), read back from its run.json: the peak, the peak beyond a tiny
// run's (the fixed overhead: code, libraries, thread stacks) per cell, and
// the run's own estimate against the peak.
#pragma once

#include "bench/bench_suites.h"

namespace morphoflow {

bool runMemoryBench(const BenchOptions& options);

}  // namespace morphoflow
