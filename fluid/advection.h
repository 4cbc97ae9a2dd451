// Semi-Lagrangian advection (Stam 1999; Kim & Lin eq. 19-20) with a midpoint
// (RK2) back-trace, and the second-order MacCormack (Selle et al. 2008) and
// BFECC (Kim et al. 2005) variants, clamped to the values of the first-order
// stencil so they stay bounded. Unconditionally stable at any CFL number.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "core/mac_velocity.h"
#include "core/work_pool.h"
#include "fluid/fluid_settings.h"

namespace morphoflow {

// Scratch grids of the second-order schemes: one set, reshaped for each
// field advected (the fields are advected one after another), so it costs
// one grid shape's worth, not one per shape; a solver lends it storage from
// its WorkPool for the advection stage only.
template <int D>
struct AdvectionScratch {
  struct Set {
    Grid<float, D> lo, hi, back, fwd;  // fwd: BFECC's only (reshaped there)
  };
  Set set;
  // Borrows the grids' storage from a pool for one advection stage, and
  // gives it back.
  void borrow(WorkPool* pool, AdvectionScheme scheme) {
    if (scheme == AdvectionScheme::SemiLagrangian) return;  // it uses none
    each([&](std::vector<float>& v) { pool->lend(&v); }, scheme == AdvectionScheme::Bfecc);
  }
  void giveBack(WorkPool* pool) {
    each([&](std::vector<float>& v) { pool->give(&v); }, true);
  }
  Set& forShape(const IVec<D>& dims) {
    for (Grid<float, D>* g : {&set.lo, &set.hi, &set.back}) g->reshape(dims);
    return set;
  }

 private:
  template <class F>
  void each(F&& f, bool withFwd) {
    for (Grid<float, D>* g : {&set.lo, &set.hi, &set.back}) f(g->values());
    if (withFwd) f(set.fwd.values());
  }
};

// How many rows along each axis a trace through u over +-dt can move a
// sample and its interpolation stencil, at most (from the largest |u_a| on
// the faces); nullopt where u is not finite or an axis is periodic.
template <int D>
std::optional<std::array<int, D>> traceReach(const MacVelocity<D>& u, double dt);

// dst(x) = src(x - dt u(x)): every sample of `src` (laid out by `layout`) is
// traced back through `u`. src and dst must not alias. With `reach`
// (traceReach of the same u and dt; a field on u's cells or faces), a row
// of samples whose every trace ends among samples bitwise equal to its own
// (a row of empty space: no smoke, the ambient temperature) is written
// without tracing, as the value the interpolation of equal samples gives:
// the result is bitwise the same, at a cost that follows the rows that
// hold something. Returns the rows its passes traced.
template <int D>
size_t advectField(const Grid<float, D>& src, const Layout<D>& layout, const MacVelocity<D>& u,
                 double dt, AdvectionScheme scheme, Grid<float, D>* dst,
                 AdvectionScratch<D>* scratch = nullptr, const std::array<int, D>* reach = nullptr);

// Advects every component of a MAC velocity through itself.
template <int D>
void advectVelocity(const MacVelocity<D>& u, double dt, AdvectionScheme scheme, MacVelocity<D>* dst,
                    AdvectionScratch<D>* scratch = nullptr);

// The feet of traceBack (the same midpoint rule, in single precision with
// the semi-Lagrangian row kernels) from the cell centres of a grid of
// `cells` cells of size h over u's domain, in that grid's cell coordinates
// (centre k at k). Returns false, leaving feet alone, when u has a periodic
// axis (which these kernels do not take).
template <int D>
bool traceCellFeet(const MacVelocity<D>& u, double dt, const IVec<D>& cells, double h,
                   std::array<std::vector<float>, D>* feet);

// Foot of the characteristic through x over a step dt (midpoint rule).
template <int D>
inline Vec<D> traceBack(const MacVelocity<D>& u, const Vec<D>& x, double dt) {
  Vec<D> mid = x - 0.5 * dt * u.sample(x);
  return x - dt * u.sample(mid);
}

}  // namespace morphoflow
