// Semi-Lagrangian advection of reaction-diffusion species by a fluid velocity
// (seed 001 sec. 5, eq. 18-20): every RD cell centre x is traced back through
// the fluid's MAC velocity, x* = x - dt u(x - dt/2 u(x)) (midpoint), and takes
// the species' value at x*. The RD grid may have another resolution than the
// fluid grid: the velocity is sampled at RD cell centres in world space.
//
// Interpolation is linear (eq. 20), cubic (Catmull-Rom per axis, clamped to
// the 2^D linear neighbours so it adds no new extrema) or bspline (the cubic
// B-spline of the species' prefiltered coefficients, clamped the same way:
// coupling/bspline.h) or bfecc (linear samples forward, backward and forward
// again, the error estimate subtracted, limited the same way: Kim et al.
// 2005). Feet beyond a wall are
// clamped to it; periodic axes wrap. Past the outermost cell centre of an
// inflow side the value blends linearly into the inflow concentration, which
// it takes at the wall and beyond (chemical flowing in, seed 001 fig. 6);
// solid (obstacle) cells hold the solid values (no chemical).
#pragma once

#include <array>
#include <vector>

#include "core/work_pool.h"
#include "core/grid.h"
#include "core/mac_velocity.h"
#include "coupling/coupling_choices.h"

namespace morphoflow {

template <int D>
struct ChemicalDomain {
  IVec<D> cells{0};                       // the RD grid
  double h = 1.0;                         // its cell size (same world units as the fluid)
  std::array<bool, D> periodic{};         // wrap back-traces along these axes
  std::array<std::array<bool, 2>, D> inflow{};  // sides (lo, hi) that bring in chemical
  std::vector<double> inflowValues;       // per species, at inflow sides
  std::vector<uint8_t> solid;             // per RD cell (empty: none)
  std::vector<double> solidValues;        // per species, inside solids
};

template <int D>
class ChemicalAdvector {
 public:
  ChemicalAdvector(ChemicalDomain<D> domain, ChemicalInterpolation interpolation);

  // species[s] <- species[s](x*) for every RD cell; deterministic for any
  // thread count (every cell is computed independently).
  // The feet and the species' scratch are borrowed from `pool` (if given)
  // for the call; the species go through the scratch one at a time.
  void advect(const MacVelocity<D>& u, double dt, const std::vector<Grid<double, D>*>& species,
              WorkPool* pool = nullptr) {
    trace(u, dt, pool);
    carry(species, pool);
  }
  // advect in two halves: the feet through u (after which u is not read),
  // then the species carried to them (the feet go back to the pool).
  void trace(const MacVelocity<D>& u, double dt, WorkPool* pool = nullptr);
  void carry(const std::vector<Grid<double, D>*>& species, WorkPool* pool = nullptr);
  // New solid cells (a moving obstacle; per RD cell, empty: none).
  void setSolid(std::vector<uint8_t> solid) { domain_.solid = std::move(solid); }
  // Sets the solid cells of every species to the solid values.
  void emptySolids(const std::vector<Grid<double, D>*>& species) const;

  const ChemicalDomain<D>& domain() const { return domain_; }

 private:
  size_t cells() const;       // the domain's
  bool weighsInflow() const;  // whether a side lets chemicals in (their values given)
  ChemicalDomain<D> domain_;
  ChemicalInterpolation interpolation_;
  // Foot of every cell (grid coordinates, per axis; single precision, as
  // the fluid's own traces: 1e-7 of the domain, far below a cell), then
  // (bfecc) the feet over -dt: float arrays in the pool's double vectors,
  // from trace to carry.
  FloatArrays feet_;
  std::array<float*, D> feet(int set) const {
    std::array<float*, D> f;
    for (int a = 0; a < D; ++a) f[size_t(a)] = feet_[size_t(set * D + a)];
    return f;
  }
  std::vector<double> fromInflow_;  // weight of the inflow value (1: the foot left through an inflow side); empty
                                    // without an inflow side
  std::vector<double> backFromInflow_;  // bfecc: the weights of the feet over -dt
  WorkPool own_;                        // what a call without a pool borrows from
  Grid<double, D> scratch_;  // one species' advected values (borrowed, with a pool)
  Grid<double, D> coefficients_;  // bspline: one species' spline coefficients; bfecc: its backward step
};

// Value of g at continuous grid coordinate c (cell centres at integers),
// linear or clamped Catmull-Rom, wrapping periodic axes and clamping others.
template <int D>
double sampleChemical(const Grid<double, D>& g, const std::array<bool, D>& periodic, const Vec<D>& c,
                      ChemicalInterpolation interpolation);

}  // namespace morphoflow
