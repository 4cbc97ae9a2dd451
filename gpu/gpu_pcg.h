// Preconditioned conjugate gradients (core/pcg.cpp) on the GPU, double
// vectors, preconditioned by a GpuMultigrid (MGPCG) or by the diagonal. The
// scalars stay on the device, and so does the decision to stop: a GpuGate
// (gpu_gate.h) turns the queued iterations past the CPU's stopping test into
// empty dispatches, so a solve queues a scheduled number of iterations and
// reads nothing back. The schedule is the most iterations a solve took in
// the last tally, a quarter more and 2 (the first solve calibrates it,
// looking every 8 iterations); a tally that shows the schedule cut a solve
// short doubles it. Singular (pure Neumann) systems are solved for the mean-free
// solution, as on the CPU.
#pragma once

#include <memory>
#include <vector>

#include "core/pcg.h"
#include "core/solver_result.h"
#include "gpu/gpu_gate.h"
#include "gpu/gpu_laplace.h"
#include "gpu/kernel_modes.h"
#include "gpu/gpu_reduction.h"

namespace morphoflow {

class GpuMultigrid;

// The vectors a solve works in (r, p, q, z and p's other buffer), for
// systems of up to n unknowns: one set serves several GpuPcgs whose solves
// never overlap (the pressure's and the viscosity's; a layer's species).
struct GpuPcgWork {
  GpuPcgWork(size_t n, GpuPrecision real);
  size_t n;
  GpuPrecision real;
  GpuBuffer r, p, q, z, p2;
};

class GpuPcg {
 public:
  // In `work` (null: a set of its own), whose size and precision must fit A's.
  explicit GpuPcg(const GpuLaplace& A, std::shared_ptr<GpuPcgWork> work = nullptr);
  // Solves A x = b from x's current values to options.tolerance (relative
  // residual); b is made mean-free first when A is singular. M null: the
  // diagonal preconditioner. Returns the solve's own result, read back (one
  // host wait) unless `deferred`: then the last tally's (tally()).
  SolverResult solve(GpuBuffer* b, GpuBuffer* x, GpuMultigrid* M, const SolverOptions& options, bool deferred = false);
  // The solves since the last tally, read back (one host wait): converged
  // when all were, a solve's mean iterations, the largest residual; and the
  // schedule adapted to them.
  SolverResult tally();
  // The tallies of several solves, in one host wait.
  static std::vector<SolverResult> tally(const std::vector<GpuPcg*>& solves);
  // The iterations a solve queues (0: not calibrated yet), and a schedule
  // taken from a like system's where this one has none (a right-hand side
  // that has stayed 0), so that it does not calibrate, reading back.
  int schedule() const { return ahead_; }
  void adoptSchedule(int ahead) {
    if (ahead_ == 0) ahead_ = ahead;
  }
  GpuReduction& reduction() { return sums_; }

 private:
  void op(VectorOp name, const GpuBuffer& x, const GpuBuffer& y, const GpuBuffer& z, const GpuBuffer& q,
          std::array<int, 4> slots, bool first = false, const SolverOptions* check = nullptr);
  // The scheduled iterations with each p update fused into the next
  // iteration's operator (GpuLaplace::applyUpdatingP).
  void precondition(GpuMultigrid* M, int slot);
  // The gate's final passes of these slots' partials (-1: none).
  GpuGate::Finals finals(int a, int b) const;
  void iterateFused(GpuBuffer* x, GpuMultigrid* M, const SolverOptions& options, int queue);
  SolverResult fromTally(const GpuGate::Tally& t, bool last);
  const GpuLaplace& A_;
  std::shared_ptr<GpuPcgWork> work_;
  GpuBuffer &r_, &p_, &q_, &z_, &p2_;  // work_'s; p2_: the p update's other buffer
  GpuReduction sums_;
  GpuGate gate_;
  int ahead_ = 0;  // iterations a solve queues; 0: not calibrated yet
  SolverResult last_;  // what deferred solves report
};

}  // namespace morphoflow
