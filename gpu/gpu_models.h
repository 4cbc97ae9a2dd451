// The reaction models on the GPU: the same kernels/models/*.inc that
// rd/models.h includes, embedded into the shaders with the GLSL side of the
// kernels' dialect (kernels/README.md).
#pragma once

#include <string>

#include "core/backend.h"

namespace morphoflow {

// GLSL defining NSPECIES, NPARAMETERS and
//   void modelRates(T x[NSPECIES], T p[NPARAMETERS], out T r[NSPECIES])
//   void modelJacobian(T x[NSPECIES], T p[NPARAMETERS], out T J[NSPECIES * NSPECIES])
// (J row-major, dR_s / dx_t) for the model, in single or double precision
// (T), or "" for an unknown model.
std::string gpuReaction(const std::string& model, GpuPrecision precision);
// The model's species, 0 for an unknown model.
int gpuSpecies(const std::string& model);

}  // namespace morphoflow
