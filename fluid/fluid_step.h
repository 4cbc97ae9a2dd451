// The stable-fluids step (Stam 1999; with [smoke], Fedkiw, Stam & Jensen
// 2001), written once for every backend over its stages. The CPU
// (FluidSolver, fluid/fluid_solver.cpp) and the GPU (GpuFluid,
// gpu/gpu_fluid.cpp) supply the stages; the order is this file's alone.
// A backend's Stages has:
//   mark(k)           stage k of FluidStepStats begins (k = 4: the step ends)
//   resumeClock()     the stage goes on after a caller's work, whose time is
//                     not the stage's
//   smoke()           whether the scene has [smoke]
//   emitSmoke(dt)     the sources' smoke and heat
//   forces(dt)        the scene's forces (gravity, the dye's buoyancy)
//   smokeForces(dt)   buoyancy and vorticity confinement (eq. 8, 11)
//   constrain()       prescribed faces, periodic copies
//   advect(dt)        the velocity through itself, the dye and the
//                     temperature through the same field
//   releaseAdvected() the velocity advected through is no longer needed
//   injectInflowDye() dye stripes on the inflow side
//   decaySmoke(dt)    the smoke's dissipation and cooling
//   diffuse(dt)       the implicit viscosity
//   project(dt)       the pressure projection
//   advanceClock(dt)  time += dt, one more step
#pragma once

#include <functional>

namespace morphoflow {

template <class Stages>
void stepFluid(Stages& s, double dt, const std::function<void()>& afterAdvection = {}) {
  s.mark(0);
  // 1. forces
  if (s.smoke()) s.emitSmoke(dt);
  s.forces(dt);
  if (s.smoke()) s.smokeForces(dt);
  s.constrain();
  s.mark(1);
  // 2. advect
  s.advect(dt);
  s.constrain();
  s.injectInflowDye();
  if (s.smoke()) s.decaySmoke(dt);
  s.mark(2);
  if (afterAdvection) {  // (the coupled step's chemicals may start, or run)
    afterAdvection();
    s.resumeClock();
  }
  s.releaseAdvected();
  // 3. diffuse
  s.diffuse(dt);
  s.mark(3);
  // 4. project
  s.project(dt);
  s.mark(4);
  s.advanceClock(dt);
}

}  // namespace morphoflow
