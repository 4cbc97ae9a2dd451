// What every iterative solver returns; tests assert on it.
#pragma once

namespace morphoflow {

struct SolverResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;  // final relative residual ||b - Ax|| / ||b||
};

}  // namespace morphoflow
