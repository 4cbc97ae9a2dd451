// What every iterative solver returns; tests assert on it.
#pragma once

#include <algorithm>

namespace morphoflow {

struct SolverResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;  // final relative residual ||b - Ax|| / ||b||
};

// Folds r into the worst of several solves (the components or species of
// one step): converged only if all did, the most iterations, the largest
// residual.
inline void foldWorst(SolverResult* worst, const SolverResult& r) {
  worst->converged = worst->converged && r.converged;
  worst->iterations = std::max(worst->iterations, r.iterations);
  worst->residual = std::max(worst->residual, r.residual);
}

}  // namespace morphoflow
