// The two-species reaction models of rd/models.h in GLSL, term for term, for
// the explicit step (float) and Kim & Lin's Newton (double).
#pragma once

#include <string>

namespace morphoflow {

// #defines of RATES(x, r) and JACOBIAN(x, J) (J row-major, dR_s / dx_t) for
// the model, in single or double precision (the model's parameters in p[]),
// or "" when the model has no GPU program (the multi-species models).
std::string gpuReaction(const std::string& model, bool doublePrecision = false);

}  // namespace morphoflow
