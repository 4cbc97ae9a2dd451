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

// Scratch of the second-order schemes: the forward pass's stencil bounds
// (lo, hi) and the backward pass (back), float arrays in the bytes of the
// pool's idle double vectors, sized for the largest field advected (the
// fields are advected one after another, through the same arrays); BFECC's
// corrected field, traced again, is a grid. A solver lends them from its
// WorkPool for the advection stage only.
template <int D>
struct AdvectionScratch {
  FloatArrays arrays;  // lo, hi, back
  Grid<float, D> fwd;  // BFECC's (reshaped there)
  // Borrows for fields of at most n samples, and gives back.
  void borrow(WorkPool* pool, AdvectionScheme scheme, size_t n) {
    if (scheme == AdvectionScheme::SemiLagrangian) return;  // it uses none
    arrays.lend(pool, 3, n);
    if (scheme == AdvectionScheme::Bfecc) pool->lend(&fwd.values());
  }
  void giveBack(WorkPool* pool) {
    arrays.give(pool);
    pool->give(&fwd.values());
  }
  float* lo() const { return arrays[0]; }
  float* hi() const { return arrays[1]; }
  float* back() const { return arrays[2]; }
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
// axis (which these kernels do not take). feet[a] holds a value per cell.
template <int D>
bool traceCellFeet(const MacVelocity<D>& u, double dt, const IVec<D>& cells, double h,
                   const std::array<float*, D>& feet);

// Foot of the characteristic through x over a step dt (midpoint rule).
template <int D>
inline Vec<D> traceBack(const MacVelocity<D>& u, const Vec<D>& x, double dt) {
  Vec<D> mid = x - 0.5 * dt * u.sample(x);
  return x - dt * u.sample(mid);
}

}  // namespace morphoflow
