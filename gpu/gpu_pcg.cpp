#include "gpu/gpu_pcg.h"

#include <algorithm>
#include <cmath>

#include "gpu/compute_program.h"
#include "gpu/gl_context.h"
#include "gpu/gpu_multigrid.h"
#include "gpu/gpu_programs.h"
#include "gpu/gpu_reals.h"

namespace morphoflow {

namespace {
// The scalar slots (GpuReduction).
enum Slot { kBB = 0, kRR = 1, kPQ = 2, kRZ0 = 3, kRZ1 = 4, kSum = 5, kCount = 6, kPQ1 = 7 };
constexpr GpuGate::Slots kGateSlots{kBB, kRR, kPQ};
constexpr int kCalibrationLook = 8;  // iterations between looks while the schedule is calibrated
}  // namespace

GpuPcgWork::GpuPcgWork(size_t size, GpuPrecision precision)
    : n(size),
      real(precision),
      r(realBuffer(n, real)),
      p(realBuffer(n, real)),
      q(realBuffer(n, real)),
      z(realBuffer(n, real)),
      p2(realBuffer(n, real)) {}

GpuPcg::GpuPcg(const GpuLaplace& A, std::shared_ptr<GpuPcgWork> work)
    : A_(A),
      work_(work ? std::move(work) : std::make_shared<GpuPcgWork>(A.size(), A.precision())),
      r_(work_->r),
      p_(work_->p),
      q_(work_->q),
      z_(work_->z),
      p2_(work_->p2),
      sums_(A.precision()) {
  if (work_->n < A.size() || work_->real != A.precision())
    throw GpuError("a solve's work vectors are smaller than its system, or of another precision");
  if (A_.singular()) sums_.activeCount(A_.diag(), A_.size(), kCount);
  last_.converged = true;
}

void GpuPcg::op(VectorOp name, const GpuBuffer& x, const GpuBuffer& y, const GpuBuffer& z, const GpuBuffer& q,
                std::array<int, 4> slots, bool first, const SolverOptions* check) {
  // (every PCG op has its reductions fused in: DOT_PARTIAL)
  const ComputeProgram& p =
      useProgram("vector_ops.comp",
                 std::string("#define ") + define(name) + "\n#define DOT_PARTIAL" + (check ? "\n#define GATE" : ""),
                 A_.precision(), A_.solutionPrecision());
  if (check) gate_.checkInNext(kGateSlots, check->tolerance, check->maxIterations);
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
  // (UpdateXR: x and r read and written, p, q; and w with the diagonal)
  const double r = double(realBytes(A_.precision())), xr = double(realBytes(A_.solutionPrecision()));
  const double bytes = name == VectorOp::UpdateXR  ? 2 * xr + 4 * r + (slots[3] >= 0 ? 2.5 * r : 0.0)
                       : name == VectorOp::UpdateP ? 3 * r
                                                   : 2 * r + 4;
  sums_.partials().bind(8);
  z_.bind(9);  // the fused diagonal preconditioner's z
  countGpuTraffic(double(A_.size()) * bytes);
  dispatchGroups(GpuReduction::groups(A_.size()), 1);
  storageBarrier();
}

SolverResult GpuPcg::solve(GpuBuffer* bp, GpuBuffer* xp, GpuMultigrid* M, const SolverOptions& options, bool deferred) {
  GpuBuffer &b = *bp, &x = *xp;
  // Each dot product's partial pass is fused into the kernel that makes its
  // terms, its final pass into the gate's kernel or the kernel that uses it.
  // r = b - A x with r . r's partials, b . b's, and (diagonal) z = D^-1 r
  // with r . z's; singular, b made mean-free first (its sum's partials before)
  const bool singular = A_.singular();
  if (singular) sums_.activeSum(b, A_.diag(), A_.size(), kSum, true);
  const bool jacobiApart = M || A_.hasCross();  // (the kernel with mixed terms has no room for z)
  A_.residual(b, x, &r_, sums_.fused(kRR),
              {.scalars = &sums_.scalars(), .bb = kBB, .rz = jacobiApart ? -1 : kRZ0, .z = &z_,
               .bSum = singular ? kSum : -1, .count = kCount});
  // In float the recursive residual drifts from the true one by rounding
  // (about 1e-6 of ||b||): the iterations aim at half the tolerance, so the
  // true residual, which decides convergence at the end, meets it.
  SolverOptions target = options;
  if (A_.precision() == GpuPrecision::Float) target.tolerance *= 0.5;
  gate_.start(sums_.scalars(), kGateSlots, target.tolerance, target.maxIterations, finals(kRR, kBB));
  gate_.enter();
  if (jacobiApart) precondition(M, kRZ0);
  // The scheduled iterations, or (calibrating) until the device says it stopped.
  const bool calibrating = ahead_ == 0;
  const int queue = calibrating ? options.maxIterations : std::min(ahead_, options.maxIterations);
  if (!calibrating && !A_.hasCross()) {
    iterateFused(&x, M, target, queue);
  } else {
    op(VectorOp::UpdateP, z_, p_, p_, p_, {kRZ0, kRZ0, 0, 0}, true);
    int rz = kRZ0;
    for (int it = 1; it <= queue; ++it) {
      const int next = rz == kRZ0 ? kRZ1 : kRZ0;
      A_.apply(p_, &q_, sums_.fused(kPQ));
      // x += alpha p, r -= alpha q (and, diagonal, z = D^-1 r)
      op(VectorOp::UpdateXR, x, r_, p_, q_, {rz, kPQ, kRR, M ? -1 : next});
      if (M) precondition(M, next);
      // p = z + beta p, then the stopping test (past it, the p update and the
      // multigrid cycle before it were work the result does not use)
      op(VectorOp::UpdateP, z_, p_, p_, p_, {next, rz, kPQ, kRR}, false, &target);
      rz = next;
      if (calibrating && it % kCalibrationLook == 0 && !gate_.going()) break;
    }
  }
  gate_.leave();
  // The true residual, not the recursively updated one (b = 0: x = 0 first,
  // as on the CPU); singular, with x's sum's partials, then x made mean-free.
  A_.residual(b, x, &r_, sums_.fused(kRR), {.scalars = &sums_.scalars(), .noRhs = kBB, .xSum = singular ? kSum : -1});
  gate_.finish(sums_.scalars(), kGateSlots, options.tolerance, finals(kRR, -1));
  if (singular) op(VectorOp::SubMean, x, x, x, x, {kSum, kCount, 0, 0});
  if (calibrating || !deferred) return fromTally(gate_.read(), true);
  return last_;
}

GpuGate::Finals GpuPcg::finals(int a, int b) const {
  return GpuGate::Finals{&sums_.partials(), {a, b}, GpuReduction::groups(A_.size())};
}

void GpuPcg::precondition(GpuMultigrid* M, int slot) {  // z = M r, with r . z's partials
  if (M)
    M->apply(r_, &z_, sums_.scalars(), kRR, sums_.fused(slot));
  else
    op(VectorOp::Jacobi, r_, z_, z_, z_, {slot, 0, 0, 0});
}

void GpuPcg::iterateFused(GpuBuffer* xp, GpuMultigrid* M, const SolverOptions& options, int queue) {
  GpuBuffer &x = *xp, *p = &p_, *pOther = &p2_;
  int rz = kRZ0, rzBefore = kRZ0, pq = kPQ, pqBefore = kPQ1;
  for (int it = 1; it <= queue; ++it) {
    const int next = rz == kRZ0 ? kRZ1 : kRZ0;
    if (it == 1) {  // p = z and q = A p in one pass
      A_.applyUpdatingP(*p, z_, pOther, &q_, sums_.fused(pq), sums_.scalars(), {rz, rz, 0, 0}, true);
      std::swap(p, pOther);
    } else {
      // p = z + beta p and q = A p in one pass, then the stopping test of the iteration before
      gate_.checkInNext({kBB, kRR, pqBefore}, options.tolerance, options.maxIterations);
      A_.applyUpdatingP(*p, z_, pOther, &q_, sums_.fused(pq), sums_.scalars(), {rz, rzBefore, pqBefore, kRR});
      std::swap(p, pOther);
    }
    // x += alpha p, r -= alpha q (and, diagonal, z = D^-1 r)
    op(VectorOp::UpdateXR, x, r_, *p, q_, {rz, pq, kRR, M ? -1 : next});
    if (M && it < queue) precondition(M, next);
    rzBefore = rz;
    rz = next;
    std::swap(pq, pqBefore);
  }
  // the last iteration's test
  gate_.check(sums_.scalars(), {kBB, kRR, pqBefore}, options.tolerance, options.maxIterations, finals(pqBefore, kRR));
}

SolverResult GpuPcg::fromTally(const GpuGate::Tally& t, bool last) {
  SolverResult r;
  r.converged = last ? t.lastConverged : t.unconverged == 0;
  r.iterations =
      int(last ? t.lastIterations : (t.iterations + t.solves - 1) / std::max(t.solves, 1u));  // (a solve's mean)
  r.residual = last ? t.lastResidual : t.maxResidual;
  // The schedule: the most iterations seen, a quarter more and 2; doubled
  // where it cut a solve short; calibrated again while the solves took none
  // (a right-hand side of 0: the velocity component of a flow that has not started).
  const int most = int(t.maxIterations);
  const bool cut = t.unconverged > 0 && ahead_ > 0 && most >= ahead_;
  ahead_ = cut ? 2 * ahead_ : most == 0 ? 0 : std::max(ahead_ / 2, most + most / 4 + 2);
  gate_.resetTally();
  last_ = r;
  return r;
}

SolverResult GpuPcg::tally() {
  const GpuGate::Tally t = gate_.read();
  if (t.solves == 0) return last_;
  return fromTally(t, false);
}

std::vector<SolverResult> GpuPcg::tally(const std::vector<GpuPcg*>& solves) {
  std::vector<const GpuGate*> gates;
  for (const GpuPcg* s : solves) gates.push_back(&s->gate_);
  const std::vector<GpuGate::Tally> tallies = GpuGate::read(gates);
  std::vector<SolverResult> results;
  for (size_t k = 0; k < solves.size(); ++k)
    results.push_back(tallies[k].solves == 0 ? solves[k]->last_ : solves[k]->fromTally(tallies[k], false));
  return results;
}

}  // namespace morphoflow
