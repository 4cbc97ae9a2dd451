#include "gpu/gpu_pcg.h"

#include <cmath>

#include "gpu/compute_program.h"
#include "gpu/gpu_kernels.h"
#include "gpu/gpu_multigrid.h"

namespace morphoflow {

namespace {
// The scalar slots (GpuReduction).
enum Slot { kBB = 0, kRR = 1, kPQ = 2, kRZ0 = 3, kRZ1 = 4, kSum = 5, kCount = 6 };
}  // namespace

GpuPcg::GpuPcg(const GpuLaplace& A)
    : A_(A), r_(A.size() * sizeof(double)), p_(A.size() * sizeof(double)), q_(A.size() * sizeof(double)),
      z_(A.size() * sizeof(double)) {
  if (A_.singular()) sums_.activeCount(A_.diag(), A_.size(), kCount);
}

void GpuPcg::op(VectorOp name, const GpuBuffer& x, const GpuBuffer& y, const GpuBuffer& z, const GpuBuffer& q,
                std::array<int, 4> slots, bool first) {
  const ComputeProgram& p = useKernel("vector_ops.comp", std::string("#define ") + define(name));
  setUniform(p, "n", int(A_.size()));
  setUniform(p, "slots", slots);
  setUniform(p, "first", first ? 1 : 0);
  x.bind(0);
  y.bind(1);
  z.bind(2);
  q.bind(3);
  A_.diag().bind(4);  // (no float vector in these ops)
  A_.diag().bind(5);
  sums_.scalars().bind(6);
  dispatchFlat(A_.size(), name == VectorOp::UpdateXR ? 48.0 : name == VectorOp::UpdateP ? 24.0 : 20.0);
  storageBarrier();
}

void GpuPcg::removeMean(GpuBuffer* x) {
  sums_.activeSum(*x, A_.diag(), A_.size(), kSum);
  op(VectorOp::SubMean, *x, *x, *x, *x, {kSum, kCount, 0, 0});
}

SolverResult GpuPcg::solve(GpuBuffer* bp, GpuBuffer* xp, GpuMultigrid* M, const SolverOptions& options) {
  GpuBuffer &b = *bp, &x = *xp;
  const size_t n = A_.size();
  SolverResult result;
  if (A_.singular()) removeMean(&b);
  sums_.dot(b, b, n, kBB);
  const double bnorm = std::sqrt(sums_.read()[kBB]);
  if (bnorm == 0.0) {
    x.zero();
    result.converged = true;
    return result;
  }
  A_.residual(b, x, &r_, false);
  sums_.dot(r_, r_, n, kRR);
  result.residual = std::sqrt(sums_.read()[kRR]) / bnorm;
  int rz = kRZ0;
  auto precondition = [&](int slot) {
    if (M)
      M->apply(r_, &z_, sums_.scalars(), kRR);
    else
      op(VectorOp::Jacobi, r_, z_, z_, z_, {0, 0, 0, 0});
    sums_.dot(r_, z_, n, slot);
  };
  if (result.residual > options.tolerance) {
    precondition(rz);
    op(VectorOp::UpdateP, z_, p_, p_, p_, {0, 0, 0, 0}, true);
    for (int it = 1; it <= options.maxIterations; ++it) {
      A_.apply(p_, &q_);
      sums_.dot(p_, q_, n, kPQ);
      op(VectorOp::UpdateXR, x, r_, p_, q_, {rz, kPQ, 0, 0});
      sums_.dot(r_, r_, n, kRR);
      const std::vector<double> s = sums_.read();
      result.iterations = it;
      result.residual = std::sqrt(s[kRR]) / bnorm;
      if (!(s[kPQ] > 0.0) || result.residual <= options.tolerance) break;
      const int next = rz == kRZ0 ? kRZ1 : kRZ0;
      precondition(next);
      op(VectorOp::UpdateP, z_, p_, p_, p_, {next, rz, 0, 0});
      rz = next;
    }
  }
  // The true residual, not the recursively updated one.
  A_.residual(b, x, &r_, false);
  sums_.dot(r_, r_, n, kRR);
  result.residual = std::sqrt(sums_.read()[kRR]) / bnorm;
  if (A_.singular()) removeMean(&x);
  result.converged = result.residual <= options.tolerance * 1.0001;
  return result;
}

}  // namespace morphoflow
