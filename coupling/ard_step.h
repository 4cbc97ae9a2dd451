// The advection-reaction-diffusion step of seed 001 sec. 5, written once for
// every backend over its stages. The CPU (ARDSolver, coupling/ard_solver.cpp)
// and the GPU (GpuARDSolver, gpu/gpu_ard_solver.cpp) supply the stages; the
// order is this file's alone. A backend's Stages has:
//   reactDiffuse(dt)  the reaction-diffusion layer's step (eq. 6, then eq. 13)
//   emptySolids()     the chemicals inside obstacles set to their solid values
//   advect(dt)        the species carried by the fluid's velocity (eq. 19-20)
// The step's two halves are apart so that a coupled step can start the
// second when the fluid's velocity is ready (coupling/cpu_coupled_stepper.h).
#pragma once

#include "coupling/coupling_choices.h"

namespace morphoflow {

// React and diffuse over rdTimeScale dt of the layer's own time (none when
// the chemicals are passive); obstacles then hold no chemical.
template <class Stages>
void reactDiffuseChemicals(Stages& s, CouplingMode mode, double rdTimeScale, double dt) {
  if (mode != CouplingMode::Passive) s.reactDiffuse(rdTimeScale * dt);
  if (mode == CouplingMode::ARD) s.emptySolids();
}

// Carry the species over dt (not when the layer ignores the flow).
template <class Stages>
void advectChemicals(Stages& s, CouplingMode mode, double dt) {
  if (mode != CouplingMode::RDOnly) s.advect(dt);
}

// BFECC's passes (Kim, Liu, Llamas & Rossignac 2005): forward phi^ = A(phi),
// backward phi_b = A^-1(phi^), then the compensated forward step
// A(phi + (phi - phi_b) / 2), limited to the range of phi's neighbours of
// the foot.
template <class Forward, class Backward, class Compensated>
void bfeccPasses(Forward&& forward, Backward&& backward, Compensated&& compensated) {
  forward();
  backward();
  compensated();
}

}  // namespace morphoflow
