// Bi- and trilinear interpolation from kernels/multilinear.inc, shared with
// the GPU (kernels/README.md): for any scalar or vector-lane type T.
#pragma once

namespace morphoflow {

#define ML_FN           \
  template <class ML_T> \
  [[gnu::always_inline]] inline ML_T
#define PRECISE
#include "kernels/multilinear.inc"
#undef ML_FN
#undef PRECISE

}  // namespace morphoflow
