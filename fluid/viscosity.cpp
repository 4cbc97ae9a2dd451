#include "fluid/viscosity.h"

#include <algorithm>

#include "core/jacobi.h"
#include "core/parallel.h"

namespace morphoflow {

template <int D>
ViscositySolver<D>::ViscositySolver(const VelocityConstraints<D>& vc, const SolverOptions& options)
    : vc_(vc), options_(options) {
  const IVec<D>& n = vc_.cells;
  const std::array<bool, D> periodic = vc_.periodic();
  for (int a = 0; a < D; ++a) {
    Component& C = comp_[size_t(a)];
    const Grid<uint8_t, D>& fixed = vc_.fixed[a];
    const Grid<float, D>& value = vc_.value[a];
    // Unknowns: the face grid, less the duplicate face n_a on a periodic axis.
    C.dims = n + unitVector<D>(a);
    if (periodic[size_t(a)]) C.dims[a] = n[a];
    C.A = LaplaceSystem<D>(C.dims, periodic, 1.0);
    C.cBoundary = Grid<float, D>(C.dims, 0.0f);
    C.boundaryRhs.assign(C.A.size(), 0.0);
    C.b.assign(C.A.size(), 0.0);
    C.x.assign(C.A.size(), 0.0);
    forEachCell<D>(C.dims, [&](const IVec<D>& k, size_t i) {
      size_t gi = fixed.index(k);
      if (fixed[gi]) return;
      double c = 0.0, extra = 0.0;
      for (int bx = 0; bx < D; ++bx) {
        for (int dir = -1; dir <= 1; dir += 2) {
          IVec<D> nb = k;
          nb[bx] += dir;
          if (nb[bx] < 0 || nb[bx] >= C.dims[bx]) {
            if (periodic[size_t(bx)]) {
              nb[bx] = (nb[bx] + C.dims[bx]) % C.dims[bx];
            } else {
              if (bx == a) continue;  // an outflow face: zero gradient
              const DomainSide& side = vc_.boundaries.side(bx, dir > 0);
              if (side.kind == BoundaryKind::Outflow) continue;
              // Ghost mirrored about the wall: u_g = 2 u_wall - u.
              double uw = side.kind == BoundaryKind::Wall ? side.wallVelocity[size_t(a)] : 0.0;
              c += 2.0;
              extra += 2.0 * uw;
              continue;
            }
          }
          size_t ni = fixed.index(nb);
          if (fixed[ni]) {
            c += 1.0;
            extra += double(value[ni]);
          } else if (dir > 0) {
            C.A.w[bx][i] = 1.0f;
          }
        }
      }
      C.cBoundary[i] = float(c);
      C.boundaryRhs[i] = extra;
    });
  }
}

namespace {
constexpr double kMultigridAbove = 0.1;  // nu dt / h^2 from which multigrid preconditions
// Three smoothing sweeps each way: the identity term makes the viscous
// systems better conditioned than the pressure's, and with the sweeps in one
// pass over memory a third sweep costs less than the outer iteration it
// saves (measured at 512^2, 64^3 and 128^3: docs/performance.md).
const MultigridOptions kViscosityCycle{3, 3, 4};
}  // namespace

template <int D>
SolverResult ViscositySolver<D>::diffuse(MacVelocity<D>* u, double nu, double dt) {
  SolverResult worst;
  worst.converged = true;
  if (nu <= 0 || dt <= 0) return worst;
  const double s = nu * dt / (vc_.h * vc_.h);
  // The components' solves are independent: run them side by side (each
  // still splits into row tasks), so the small loops of the coarse
  // multigrid levels of one overlap with another's work.
  std::array<SolverResult, D> results;
  parallelFor(size_t(D), [&](size_t ai) {
    const int a = int(ai);
    Component& C = comp_[ai];
    Grid<float, D>& g = (*u)[a];
    const Grid<uint8_t, D>& fixed = vc_.fixed[a];
    // Unknown i is face gi of the component's grid: the same index unless a
    // periodic axis drops the duplicate face layer.
    const bool sameIndex = C.dims == g.dims();
    auto eachUnknown = [&](auto&& fn) {
      if (sameIndex)
        parallelFor(C.A.size(), [&](size_t i) { fn(i, i); }, 4096);
      else
        forEachCell<D>(C.dims, [&](const IVec<D>& k, size_t i) { fn(i, g.index(k)); });
    };
    if (s != s_) {  // A = s (c + sum w (x_i - x_j)), c = 1/s + boundary terms
      C.A.scale = s;
      eachUnknown([&](size_t i, size_t gi) { C.A.c[i] = fixed[gi] ? 0.0f : float(1.0 / s + C.cBoundary[i]); });
      C.A.finalize();
      // Far below s ~ 0.1 the diagonal dominates and Jacobi needs a handful
      // of iterations; above, multigrid keeps the count independent of s and
      // is the faster (measured at 512^2 and 64^3: docs/performance.md).
      if (s <= kMultigridAbove)
        C.multigrid.reset();
      else if (C.multigrid)
        C.multigrid->refresh();
      else
        C.multigrid = std::make_unique<Multigrid<D>>(C.A, kViscosityCycle);
    }
    // Warm start: the increment's rate, linearly extrapolated in steps.
    const Vector &r1 = C.rate[0], &r0 = C.rate[1];
    const int history = C.history;
    eachUnknown([&](size_t i, size_t gi) {
      const double rate = history >= 2 ? 2.0 * r1[i] - r0[i] : history == 1 ? r1[i] : 0.0;
      C.x[i] = fixed[gi] ? 0.0 : double(g[gi]) + s * rate;
      C.b[i] = fixed[gi] ? 0.0 : double(g[gi]) + s * C.boundaryRhs[i];
    });
    JacobiPreconditioner<D> jacobi(C.A);
    Preconditioner* M = C.multigrid ? static_cast<Preconditioner*>(C.multigrid.get()) : &jacobi;
    results[ai] = solvePCG<D>(C.A, C.b, &C.x, M, options_, nullptr, &C.workspace);
    std::swap(C.rate[0], C.rate[1]);  // the older slot takes the new rate
    Vector& rate = C.rate[0];
    rate.resize(C.A.size());
    const double invS = 1.0 / s;
    eachUnknown([&](size_t i, size_t gi) {
      if (fixed[gi]) {
        rate[i] = 0.0;
        return;
      }
      rate[i] = (C.x[i] - double(g[gi])) * invS;
      g[gi] = float(C.x[i]);
    });
    C.history = std::min(C.history + 1, 2);
  });
  for (const SolverResult& r : results) foldWorst(&worst, r);
  s_ = s;
  vc_.apply(u);
  return worst;
}

template class ViscositySolver<2>;
template class ViscositySolver<3>;

}  // namespace morphoflow
