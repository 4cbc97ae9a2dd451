// GpuCoupledSteps<D>: the coupled step (coupling/coupled_steps.h) on the GPU:
// the ARD step reads velocity n, then the fluid writes n + 1, the CPU's
// serial order (coupling/coupled_stepper.h) with no copy of the velocity.
// The fluid (GpuFluid), the layer (GpuRDLayer) and the chemicals' advection
// (GpuARDSolver) stay on the device.
#pragma once

#include "coupling/coupled_steps.h"
#include "gpu/gpu_ard_solver.h"
#include "gpu/gpu_fluid.h"
#include "gpu/gpu_rd_layer.h"

namespace morphoflow {

template <int D>
class GpuCoupledSteps final : public CoupledSteps<D> {
 public:
  // From the hosts' current state; `rd` must outlive this (gpu_rd_layer.h).
  GpuCoupledSteps(const FluidSolver<D>& fluid, const RDSolver<D>& rd, const ChemicalDomain<D>& domain,
                  ChemicalInterpolation interpolation, CouplingMode mode, double rdTimeScale);

  void step(double dt) override;
  const FluidStepper<D>& fluid() const override { return fluid_; }
  const RDStepStats& layerStats() const override { return layer_.lastStats(); }
  std::array<double, 3> seconds() const override { return seconds_; }
  bool overlapped() const override { return false; }
  void toHost(FluidSolver<D>* fluid, RDSolver<D>* rd) const override;
  void fromHost(const FluidSolver<D>& fluid, const RDSolver<D>& rd) override;
  void save(StateWriter* out) const override;
  void load(const StateReader& in) override;
  void report(nlohmann::json* run) const override;

 private:
  GpuFluid<D> fluid_;
  GpuRDLayer<D> layer_;
  GpuARDSolver<D> ard_;
  std::array<double, 3> seconds_{};
};

}  // namespace morphoflow
