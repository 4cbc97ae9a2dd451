// The smoke shaped by its pattern (output.pattern_contrast), written once in
// kernels/pattern_density.inc: a patterned smoke scene's default `density`.
#pragma once

namespace morphoflow {

#define PD_FN(name) inline double name
#define PD_REAL double
#include "kernels/pattern_density.inc"
#undef PD_FN
#undef PD_REAL

}  // namespace morphoflow
