// A symmetric positive definite preconditioner: z = M^{-1} r.
#pragma once

#include "core/laplace_system.h"

namespace morphoflow {

class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  virtual void apply(const Vector& r, Vector* z) = 0;
};

}  // namespace morphoflow
