// The smoke stages of the fluid step (Fedkiw, Stam & Jensen 2001, "Visual
// simulation of smoke"), written once for 2D and 3D:
//   emission   rho += r_rho dt c, T += r_T dt c   (c: the cell's covered fraction)
//   buoyancy   f = (-alpha rho + beta (T - T_amb)) up               (their eq. 8)
//   confinement f = epsilon h (N x omega), N = grad|omega| / |grad|omega||  (eq. 11)
//   decay      rho *= exp(-k dt), T - T_amb *= exp(-c dt)  (exact for the step)
#pragma once

#include <cmath>

#include <vector>

#include "core/grid.h"
#include "core/mac_velocity.h"
#include "core/work_pool.h"
#include "fluid/fluid_settings.h"
#include "fluid/smoke_settings.h"

namespace morphoflow {

// The per-cell formulas, shared with the GPU (kernels/README.md).
#define SMOKE_FN(name) inline double name
#define SMOKE_F(name) inline float name
#define SMOKE_REAL double
#define SMOKE_SQRT std::sqrt
#include "kernels/smoke_physics.inc"
#undef SMOKE_FN
#undef SMOKE_F
#undef SMOKE_REAL
#undef SMOKE_SQRT

// A source's covered fraction of every cell (4^D samples a cell), solid
// cells excluded, with its region centred where its motion puts it at time
// t: the emission integrates to rate x time x the region's volume.
template <int D>
Grid<float, D> sourceCover(const SmokeSource& source, double t, const IVec<D>& cells, double h,
                           const Grid<uint8_t, D>& solid);
// Every fixed source's cover (a moving one's: zeros, computed each step it emits).
template <int D>
std::vector<Grid<float, D>> sourceCoverage(const std::vector<SmokeSource>& sources, const IVec<D>& cells, double h,
                                           const Grid<uint8_t, D>& solid);

// Emission over the step [t, t + dt) (each source for the part of the step
// inside its window; a moving one where it is at mid-step) into the smoke
// density and the temperature; injecting sources set the velocity of the
// faces they cover (blended by coverage).
template <int D>
void emitSmoke(const SmokeSettings& s, const std::vector<Grid<float, D>>& coverage, const Grid<uint8_t, D>& solid,
               double t, double dt, Grid<float, D>* density, Grid<float, D>* temperature, MacVelocity<D>* u);

// u += dt f for the buoyancy and the vorticity confinement, on work grids
// lent from `pool` for the stage.
template <int D>
void applySmokeForces(const SmokeSettings& s, const std::array<double, 3>& up, const Grid<float, D>& density,
                      const Grid<float, D>& temperature, double dt, MacVelocity<D>* u, WorkPool* pool);

// The decay of the step, exact: exp(-rate dt) applied once.
template <int D>
void decaySmoke(const SmokeSettings& s, double dt, Grid<float, D>* density, Grid<float, D>* temperature);

}  // namespace morphoflow
