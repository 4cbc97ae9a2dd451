// `morphoflow bench preview`: the lit preview's cost per frame
// (render/lit_volume.h) at 128^3 and 256^3 (or --size), on a synthetic
// element: a rising column of smoke shaped by a gyroid labyrinth, an eighth
// of the box, rendered at 512 pixels square. Medians of interleaved runs of
// the lit preview and of the emission-absorption view it replaces for smoke.
#pragma once

#include "bench/bench_suites.h"

namespace morphoflow {

bool runPreviewBench(const BenchOptions& options);

}  // namespace morphoflow
