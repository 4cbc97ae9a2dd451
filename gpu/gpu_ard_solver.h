// GpuARDSolver<D>: the advection-reaction-diffusion layer of ard_solver.h on
// the GPU, with the same modes: react and diffuse (gpu/gpu_rd_layer.h) over
// rdTimeScale dt, then carry the species with the GPU fluid's velocity
// (shaders/chem_advect.comp: the same feet, stencils, inflow blending and
// solids as chemical_advection.h; bspline's prefilter on the device). The
// species never leave the GPU.
#pragma once

#include <array>
#include <memory>

#include "gpu/gpu_stage_timer.h"

#include "coupling/ard_solver.h"
#include "coupling/chemical_advection.h"
#include "gpu/gpu_buffer.h"
#include "gpu/gpu_fluid.h"
#include "gpu/gpu_rd_layer.h"

namespace morphoflow {

template <int D>
class GpuARDSolver {
 public:
  // `layer` holds the species; `fluidCells`, `fluidH` and the domain's
  // periodic axes place the fluid's velocity.
  GpuARDSolver(GpuRDLayer<D>* layer, const ChemicalDomain<D>& domain, ChemicalInterpolation interpolation,
               CouplingMode mode, double rdTimeScale, const IVec<D>& fluidCells, double fluidH);

  // One step over dt of fluid time (seed 001 eq. 6, 19, 20): react and
  // diffuse over rdTimeScale dt, then advect over dt through the velocity the
  // fluid's last step advected through (so after the fluid's step, as the CPU's).
  void step(double dt, const GpuFluid<D>& fluid);
  // Sets the solid cells of both species to the solid values.
  void emptySolids();
  // A moving solid went from `was` to `now` (layer cells): the cells it
  // uncovers take their fluid neighbours' mean, those it covers the solid
  // values (coupling/solid_on_layer.h's followSolid), and the solid cells are `now`'s.
  void moveSolid(const Grid<uint8_t, D>& was, const Grid<uint8_t, D>& now);
  // The GPU's seconds of the two stages of the step before the last (timer queries).
  const std::array<double, ARDSolver<D>::kStages>& stageSeconds() const { return stageSeconds_; }
  // The stages' dispatches and host waits (gpu_counts.h).
  const GpuStageTimer& stageTimer() const { return *timer_; }

 private:
  void advect(double dt, const GpuFluid<D>& fluid);
  using Pair = std::array<GpuBuffer*, 2>;  // the two species' buffers
  void advectPass(double dt, const GpuFluid<D>& fluid, Pair from, Pair into, bool correct);

  GpuRDLayer<D>* layer_;
  ChemicalDomain<D> domain_;
  bool cubic_, spline_, bfecc_;
  CouplingMode mode_;
  double rdTimeScale_;
  std::array<int, 3> fluidCells_{1, 1, 1}, rdCells_{1, 1, 1}, periodic_{};
  double fluidH_;
  bool hasSolids_ = false;
  GpuBuffer solid_;
  std::array<GpuBuffer, 2> scratch_;
  std::array<GpuBuffer, 2> coefficients_;  // bspline: the species' spline coefficients; bfecc: the backward step
  void prefilter();
  std::array<double, ARDSolver<D>::kStages> stageSeconds_{};
  std::unique_ptr<class GpuStageTimer> timer_;
};

}  // namespace morphoflow
