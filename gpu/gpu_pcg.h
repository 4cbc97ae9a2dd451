// Preconditioned conjugate gradients (core/pcg.cpp) on the GPU, double
// vectors, preconditioned by a GpuMultigrid (MGPCG) or by the diagonal. The
// scalars stay on the device; the host reads the residual once an iteration
// to decide when to stop. Singular (pure Neumann) systems are solved for the
// mean-free solution, as on the CPU.
#pragma once

#include "core/pcg.h"
#include "core/solver_result.h"
#include "gpu/gpu_laplace.h"
#include "gpu/kernel_modes.h"
#include "gpu/gpu_reduction.h"

namespace morphoflow {

class GpuMultigrid;

class GpuPcg {
 public:
  explicit GpuPcg(const GpuLaplace& A);
  // Solves A x = b from x's current values to options.tolerance (relative
  // residual); b is made mean-free first when A is singular. M null: the
  // diagonal preconditioner.
  SolverResult solve(GpuBuffer* b, GpuBuffer* x, GpuMultigrid* M, const SolverOptions& options);
  GpuReduction& reduction() { return sums_; }

 private:
  void op(VectorOp name, const GpuBuffer& x, const GpuBuffer& y, const GpuBuffer& z, const GpuBuffer& q,
          std::array<int, 4> slots, bool first = false);
  void removeMean(GpuBuffer* x);
  const GpuLaplace& A_;
  GpuBuffer r_, p_, q_, z_;
  GpuReduction sums_;
};

}  // namespace morphoflow
