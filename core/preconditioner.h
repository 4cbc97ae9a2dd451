// A symmetric positive definite preconditioner: z = M^{-1} r.
#pragma once

#include "core/laplace_system.h"

namespace morphoflow {

class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  virtual void apply(const Vector& r, Vector* z) = 0;
  // z = M^{-1} r and returns r . z (PCG's next inner product, fused where a
  // preconditioner can). rnorm = ||r||_2, known to the caller.
  virtual double applyDot(const Vector& r, double rnorm, Vector* z) {
    (void)rnorm;
    apply(r, z);
    return dot(r, *z);
  }
};

}  // namespace morphoflow
