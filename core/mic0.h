// Modified incomplete Cholesky, MIC(0), preconditioner for a LaplaceSystem
// (Bridson, "Fluid Simulation for Computer Graphics", fig. 5.7: tuning 0.97,
// safety 0.25). Its triangular solves are sequential; couplings that wrap
// around periodic edges are left out of the factor.
#pragma once

#include "core/preconditioner.h"

namespace morphoflow {

template <int D>
class MIC0Preconditioner final : public Preconditioner {
 public:
  explicit MIC0Preconditioner(const LaplaceSystem<D>& A, double tuning = 0.97, double safety = 0.25);
  void apply(const Vector& r, Vector* z) override;

 private:
  const LaplaceSystem<D>& A_;
  Vector precon_;  // 1 / sqrt(e_i) of the modified factor
  Vector q_;
};

}  // namespace morphoflow
