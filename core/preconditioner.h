// A symmetric positive definite preconditioner: z = M^{-1} r.
#pragma once

#include <span>

#include "core/laplace_system.h"
#include "core/parallel.h"

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
  // A preconditioner that can form the last applyDot's z again from its own
  // state (while that r is unchanged) says so here: PCG then passes z = null
  // to applyDot, which returns r . z only, and forms its search direction
  // through direction(), one vector fewer written and read per iteration.
  virtual bool recomputesZ() const { return false; }
  // p = z + beta p, or p = z when `first`, with the last applyDot's z.
  virtual void direction(double beta, bool first, Vector* p) {
    (void)beta, (void)first, (void)p;
  }
  // The caller's storage that no one reads while applyDot runs (PCG's q,
  // whose z is recomputed), lent until scratch({}): a preconditioner may
  // keep its work there in place of vectors of its own.
  virtual void scratch(std::span<double> s) { (void)s; }

 protected:
  // direction() for a preconditioner that forms z_i as zAt(i).
  template <class ZAt>
  static void formDirection(ZAt&& zAt, double beta, bool first, Vector* pp) {
    double* __restrict p = pp->data();  // raw: stores through the vector would reload its data pointer
    if (first)
      parallelFor(pp->size(), [&](size_t i) { p[i] = zAt(i); }, 4096);
    else
      parallelFor(pp->size(), [&](size_t i) { p[i] = zAt(i) + beta * p[i]; }, 4096);
  }
};

}  // namespace morphoflow
