// The reaction-diffusion layer's step (seed 001 eq. 6 and 13), written once
// for every backend over its stages. Every integrator is a theta scheme on
// the diffusion,
//   (1 - theta dt d lap) x' = x + dt R + (1 - theta) dt d lap x,
// with R = R(x) lagged, or for Kim & Lin the implicit reaction step first.
// The CPU (RDSolver, rd/rd_solver.cpp) and the GPU (GpuRDLayer,
// gpu/gpu_rd_layer.cpp) supply the stages; the order is this file's alone.
// A backend's Stages has:
//   begin()                   the frozen species' values (first step), the
//                             step's statistics reset
//   dynamicTensor(), buildTensor()  a tensor from the state (eq. 18-19)
//   lobes(), buildLobes()     cosine lobes from the state (eq. 17)
//   react(dt, implicit)       the rates R, or Kim & Lin's Newton step in place
//   lendWork(), giveWork()    the solves' work vectors
//   species(), diffusion(s)   the species count, species s's coefficient
//   explicitPart(s, dt, explicitD, implicit)  x += dt R + explicitD lap x
//   diffuse(s, thetaDt)       (1 - thetaDt d lap) x' = x, a SolverResult
//   fold(result)              the diffusion solves' statistics
//   clampSpecies()            the clamped species at 0 and above
//   holdFixed()               fixed regions back to their values
//   advanceClock(dt)          time += dt, one more step
#pragma once

#include <vector>

#include "core/solver_result.h"
#include "rd/rd_settings.h"

namespace morphoflow {

template <class Stages>
void stepReactionDiffusion(Stages& s, RDIntegrator integrator, double dt) {
  s.begin();
  // The operators from the state at the step's start.
  if (s.dynamicTensor()) s.buildTensor();
  if (s.lobes()) s.buildLobes();
  const bool implicitReaction = integrator == RDIntegrator::KimLin;
  const double theta = diffusionTheta(integrator);
  s.react(dt, implicitReaction);
  // The species are independent from here on: one after another, sharing
  // the solvers' work vectors.
  s.lendWork();
  std::vector<SolverResult> solves;
  for (int k = 0; k < s.species(); ++k) {
    const double explicitD = (1.0 - theta) * dt * s.diffusion(k);
    s.explicitPart(k, dt, explicitD, implicitReaction);
    solves.push_back(s.diffuse(k, theta * dt));
  }
  s.giveWork();
  for (const SolverResult& r : solves) s.fold(r);
  s.clampSpecies();
  s.holdFixed();
  s.advanceClock(dt);
}

}  // namespace morphoflow
