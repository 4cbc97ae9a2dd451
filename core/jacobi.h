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
    parallelFor(r.size(), [&](size_t i) { (*z)[i] = scaled(r, i); }, 4096);
  }
  double applyDot(const Vector& r, double, Vector* z) override {
    last_ = &r;
    if (!z) return deterministicSum(r.size(), [&](size_t i) { return r[i] * scaled(r, i); });
    z->resize(r.size());
    return deterministicSum(r.size(), [&](size_t i) {
      (*z)[i] = scaled(r, i);
      return r[i] * (*z)[i];
    });
  }
  bool recomputesZ() const override { return true; }
  void direction(double beta, bool first, Vector* p) override {
    const Vector& r = *last_;
    formDirection([&](size_t i) { return scaled(r, i); }, beta, first, p);
  }

 private:
  // z_i = r_i / (scale diag_i), 0 on inactive cells.
  double scaled(const Vector& r, size_t i) const {
    float d = A_.diag[i];
    return d > 0 ? r[i] * (1.0 / A_.scale) / d : 0.0;
  }
  const LaplaceSystem<D>& A_;
  const Vector* last_ = nullptr;  // the last applyDot's r
};

}  // namespace morphoflow
