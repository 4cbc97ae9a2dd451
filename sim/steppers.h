// The one place that decides how a scene's parts are stepped on a backend:
// whether the scene runs there at all (the GPU's refusals, naming the stage
// it lacks), and the fluid, layer and coupled steppers the simulations hold
// (fluid/fluid_stepper.h, rd/layer_stepper.h, coupling/coupled_stepper.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "coupling/ard_solver.h"
#include "coupling/coupled_stepper.h"
#include "fluid/fluid_stepper.h"
#include "rd/layer_stepper.h"
#include "scenes/scene.h"
#include "core/backend.h"
#include "sim/rd_scene_setup.h"

namespace morphoflow {

// Throws UserError when the scene cannot run on the backend (the GPU: a
// stage it has no program for, named; no OpenGL 4.3 context; too little
// device memory). Nothing is allocated before this says yes.
void checkBackend(const Scene& scene, Backend backend);

// A solver tolerance the scene gives below what the backend's precision
// reaches (gpu.precision float: gpu/gpu_reals.h toleranceFloor), and the one
// used (a defaulted one is raised too, unsaid; run.json's gpu.tolerances).
struct RaisedTolerance {
  std::string key;
  double asked, used;
};
std::vector<RaisedTolerance> raisedTolerances(const Scene& scene, Backend backend);

// The stepper of `host`, from its current state (which it must outlive).
template <int D>
std::unique_ptr<FluidStepper<D>> makeFluidStepper(const Scene& scene, Backend backend, FluidSolver<D>* host);

// The stepper of an RD-only scene's layer `host`, from its current state:
// the plain explicit step fused (float species), every other step the
// RDSolver's own; on the GPU, the explicit step in float, the others in the
// scene's gpu.precision.
template <int D>
std::unique_ptr<LayerStepper<D>> makeLayerStepper(const Scene& scene, Backend backend, RDSolver<D>* host);

// The coupled step of `fluid` and `ard` (whose domain is `domain`), from their current state.
template <int D>
std::unique_ptr<CoupledStepper<D>> makeCoupledStepper(const Scene& scene, Backend backend, FluidSolver<D>* fluid,
                                                  ARDSolver<D>* ard, const ChemicalDomain<D>& domain);

// How a coarse-to-fine start steps its coarse levels on the backend.
template <int D>
CoarseAdvance<D> coarseAdvance(const Scene& scene, Backend backend);

}  // namespace morphoflow
