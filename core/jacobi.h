// Diagonal (Jacobi) preconditioner: cheap, parallel, enough for the
// diagonally dominant systems of implicit viscosity and diffusion.
#pragma once

#include "core/parallel.h"
#include "core/preconditioner.h"

namespace morphoflow {

template <int D>
class JacobiPreconditioner final : public Preconditioner {
 public:
  explicit JacobiPreconditioner(const LaplaceSystem<D>& A) : A_(A) {}
  void apply(const Vector& r, Vector* z) override {
    z->resize(r.size());
    const double inv = 1.0 / A_.scale;
    parallelFor(r.size(), [&](size_t i) {
      float d = A_.diag[i];
      (*z)[i] = d > 0 ? r[i] * inv / d : 0.0;
    }, 4096);
  }
  double applyDot(const Vector& r, double, Vector* z) override {
    z->resize(r.size());
    const double inv = 1.0 / A_.scale;
    return deterministicSum(r.size(), [&](size_t i) {
      float d = A_.diag[i];
      double zi = d > 0 ? r[i] * inv / d : 0.0;
      (*z)[i] = zi;
      return r[i] * zi;
    });
  }

 private:
  const LaplaceSystem<D>& A_;
};

}  // namespace morphoflow
