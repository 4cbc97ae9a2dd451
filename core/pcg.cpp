#include "core/pcg.h"

#include <cmath>

#include "core/anisotropic_system.h"
#include "core/parallel.h"
#include "core/work_pool.h"

namespace morphoflow {

namespace {

// The algorithm for any symmetric operator with size/apply/residual/singular/removeNullSpace.
template <class Op>
SolverResult pcg(const Op& A, const Vector& bIn, Vector* xp, Preconditioner* M, const SolverOptions& opt,
                 PcgWorkspace* workspace) {
  Vector& x = *xp;
  const size_t n = A.size();
  resizeExactly(&x, n, 0.0);
  SolverResult result;
  PcgWorkspace local;
  PcgWorkspace& ws = workspace ? *workspace : local;
  const bool recompute = M && M->recomputesZ();  // z is then never stored
  // b turns into r in place when it can be rebuilt for the final residual.
  bool consume = false;
  if constexpr (requires { A.residualInPlace(&ws.b, x); }) consume = ws.regenerate && &bIn == &ws.b;
  for (Vector* v : {&ws.r, &ws.p, &ws.q})
    if (!(consume && v == &ws.r)) resizeExactly(v, n);
  const Vector* bp = &bIn;
  if (A.singular()) {  // keep the system consistent (in place when b is ws.b)
    if (&bIn != &ws.b) ws.b = bIn;
    A.removeNullSpace(&ws.b);
    bp = &ws.b;
  }
  const double bnorm0 = norm2(*bp);
  if (bnorm0 == 0.0) {
    std::fill(x.begin(), x.end(), 0.0);
    result.converged = true;
    return result;
  }
  // A tiny right-hand side (a decaying species near 1e-150) would underflow
  // the inner products: solve for x / |b| instead and scale back.
  const double unit = bnorm0 < 1e-100 || bnorm0 > 1e100 ? 1.0 / bnorm0 : 1.0;
  if (unit != 1.0) {
    if (bp != &ws.b) ws.b = *bp;
    for (double& v : ws.b) v *= unit;
    for (double& v : x) v *= unit;
    bp = &ws.b;
  }
  const Vector& b = *bp;
  const double bnorm = unit == 1.0 ? bnorm0 : norm2(b);
  // z = M^-1 r lives in q's storage: q = A p is dead once r is updated, and
  // z once it has gone into p (one vector less to hold).
  Vector &r = ws.r, &p = ws.p, &q = ws.q, &z = q;
  double rnorm = 0.0;
  if constexpr (requires { A.residualInPlace(&ws.b, x); })
    if (consume) {
      rnorm = A.residualInPlace(&ws.b, x);
      std::swap(ws.b, ws.r);  // b's storage is r now; b is rebuilt at the end
    }
  if (!consume) rnorm = A.residual(b, x, &r);
  result.residual = rnorm / bnorm;
  if (result.residual <= opt.tolerance) {
    result.converged = true;
    if (unit != 1.0)
      for (double& v : x) v /= unit;
    return result;
  }
  // z = M^-1 r; returns r . z (fused into the preconditioner's last pass).
  auto precondition = [&]() -> double {
    if (!M) {
      z = r;
      if (A.singular()) A.removeNullSpace(&z);
      return dot(r, z);
    }
    // A singular system's z may carry a constant, left in place: A maps it
    // to zero and the mean-free r is orthogonal to it, so the iteration is
    // the same; x's resulting drift is removed at the end.
    return M->applyDot(r, rnorm, recompute ? nullptr : &z);
  };
  // q is dead while a z that is recomputed is formed: the preconditioner's
  // work, lent until the solve ends (however it ends).
  struct Lent {
    Preconditioner* M;
    ~Lent() {
      if (M) M->scratch({});
    }
  } lent{recompute ? M : nullptr};
  if (recompute) M->scratch(q);
  double rz = precondition();
  if (recompute)
    M->direction(0.0, true, &p);
  else
    p = z;
  for (int it = 1; it <= opt.maxIterations; ++it) {
    double pq;
    if constexpr (requires { A.applyDot(p, &q); })
      pq = A.applyDot(p, &q);
    else {
      A.apply(p, &q);
      pq = dot(p, q);
    }
    if (!(pq > 0.0)) break;  // breakdown: A not SPD on this subspace
    double alpha = rz / pq;
    {
      // Raw pointers: through the vectors, each store would reload their data pointers.
      double* __restrict xd = x.data();
      double* __restrict rd = r.data();
      const double* __restrict pd = p.data();
      const double* __restrict qd = q.data();
      rnorm = std::sqrt(deterministicSum(n, [&](size_t i) {
        xd[i] += alpha * pd[i];
        rd[i] -= alpha * qd[i];
        return rd[i] * rd[i];
      }));
    }
    result.iterations = it;
    result.residual = rnorm / bnorm;
    if (result.residual <= opt.tolerance) break;
    double rzNew = precondition();
    double beta = rzNew / rz;
    rz = rzNew;
    if (recompute)
      M->direction(beta, false, &p);
    else
      parallelFor(n, [&](size_t i) { p[i] = z[i] + beta * p[i]; }, 4096);
  }
  // Report the true residual, not the recursively updated one.
  if (consume) {  // b again, as it was solved for, in p (no longer needed)
    ws.regenerate(&p);
    if (A.singular()) A.removeNullSpace(&p);
    if (unit != 1.0)
      for (double& v : p) v *= unit;
    result.residual = A.residual(p, x, &q) / bnorm;
  } else {
    result.residual = A.residual(b, x, &r) / bnorm;
  }
  if (A.singular()) A.removeNullSpace(&x);
  if (unit != 1.0)
    for (double& v : x) v /= unit;
  result.converged = result.residual <= opt.tolerance * 1.0001;
  return result;
}

}  // namespace

template <int D>
SolverResult solvePCG(const LaplaceSystem<D>& A, const Vector& b, Vector* x, Preconditioner* M,
                      const SolverOptions& options, PcgWorkspace* workspace) {
  return pcg(A, b, x, M, options, workspace);
}

template <int D>
SolverResult solvePCG(const AnisotropicSystem<D>& A, const Vector& b, Vector* x, Preconditioner* M,
                      const SolverOptions& options, PcgWorkspace* workspace) {
  if (!A.hasCross) return pcg(A.axis, b, x, M, options, workspace);
  return pcg(A, b, x, M, options, workspace);
}

template SolverResult solvePCG<2>(const AnisotropicSystem<2>&, const Vector&, Vector*, Preconditioner*,
                                  const SolverOptions&, PcgWorkspace*);
template SolverResult solvePCG<3>(const AnisotropicSystem<3>&, const Vector&, Vector*, Preconditioner*,
                                  const SolverOptions&, PcgWorkspace*);
template SolverResult solvePCG<2>(const LaplaceSystem<2>&, const Vector&, Vector*, Preconditioner*,
                                  const SolverOptions&, PcgWorkspace*);
template SolverResult solvePCG<3>(const LaplaceSystem<3>&, const Vector&, Vector*, Preconditioner*,
                                  const SolverOptions&, PcgWorkspace*);

}  // namespace morphoflow
