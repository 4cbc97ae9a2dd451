#include "fluid/viscosity.h"

#include <algorithm>

#include "core/jacobi.h"
#include "core/parallel.h"

namespace morphoflow {

template <int D>
SolverResult ViscositySolver<D>::diffuse(MacVelocity<D>* u, double nu, double dt) const {
  SolverResult worst;
  worst.converged = true;
  if (nu <= 0 || dt <= 0) return worst;
  const double s = nu * dt / (vc_.h * vc_.h);
  const IVec<D>& n = vc_.cells;
  const std::array<bool, D> periodic = vc_.periodic();
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    const Grid<uint8_t, D>& fixed = vc_.fixed[a];
    // Unknowns: the face grid, less the duplicate face n_a on a periodic axis.
    IVec<D> sd = g.dims();
    if (periodic[size_t(a)]) sd[a] = n[a];
    LaplaceSystem<D> A(sd, periodic, s);
    Vector b(A.size(), 0.0), x(A.size(), 0.0);
    forEachCell<D>(sd, [&](const IVec<D>& k, size_t i) {
      size_t gi = g.index(k);
      if (fixed[gi]) return;
      double c = 1.0 / s, extra = 0.0;
      for (int bx = 0; bx < D; ++bx) {
        for (int dir = -1; dir <= 1; dir += 2) {
          IVec<D> nb = k;
          nb[bx] += dir;
          if (nb[bx] < 0 || nb[bx] >= sd[bx]) {
            if (periodic[size_t(bx)]) {
              nb[bx] = (nb[bx] + sd[bx]) % sd[bx];
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
          size_t ni = g.index(nb);
          if (fixed[ni]) {
            c += 1.0;
            extra += double(g[ni]);
          } else if (dir > 0) {
            A.w[bx][i] = 1.0f;
          }
        }
      }
      A.c[i] = float(c);
      b[i] = double(g[gi]) + s * extra;
      x[i] = double(g[gi]);
    });
    A.finalize();
    JacobiPreconditioner<D> M(A);
    SolverResult r = solvePCG<D>(A, b, &x, &M, options_);
    forEachCell<D>(sd, [&](const IVec<D>& k, size_t i) {
      size_t gi = g.index(k);
      if (!fixed[gi]) g[gi] = float(x[i]);
    });
    worst.converged = worst.converged && r.converged;
    worst.iterations = std::max(worst.iterations, r.iterations);
    worst.residual = std::max(worst.residual, r.residual);
  }
  vc_.apply(u);
  return worst;
}

template class ViscositySolver<2>;
template class ViscositySolver<3>;

}  // namespace morphoflow
