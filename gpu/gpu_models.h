// The reaction models of rd/models.h in GLSL, term for term, for the
// explicit step (float, two species) and the double-precision layer (Newton
// and the rates, every model).
#pragma once

#include <string>

namespace morphoflow {

// #defines of NSPECIES, RATES(x, r) and JACOBIAN(x, J) (J row-major,
// dR_s / dx_t, entries not set are 0) for the model, in single or double
// precision (the model's parameters in p[]), or "" when it has no GPU
// program in that precision (single: the two-species models, for the
// explicit step; double: every model).
std::string gpuReaction(const std::string& model, bool doublePrecision = false);
// The model's species, 0 for a model the GPU does not know.
int gpuSpecies(const std::string& model);

}  // namespace morphoflow
