// GpuCoupledStepper<D>: the coupled step (coupling/coupled_stepper.h) on the GPU:
// the fluid's step, then the ARD step through the velocity the fluid
// advected through (velocity n with step n + 1's forces), the CPU's serial
// order (coupling/cpu_coupled_stepper.h) with no copy of the velocity.
// The fluid (GpuFluid), the layer (GpuRDLayer) and the chemicals' advection
// (GpuARDSolver) stay on the device.
#pragma once

#include <map>

#include "coupling/coupled_stepper.h"
#include "gpu/gpu_ard_solver.h"
#include "gpu/gpu_counts.h"
#include "gpu/gpu_fluid.h"
#include "gpu/gpu_rd_layer.h"

namespace morphoflow {

template <int D>
class GpuCoupledStepper final : public CoupledStepper<D> {
 public:
  // From the hosts' current state; `rd` must outlive this (gpu_rd_layer.h).
  GpuCoupledStepper(const FluidSolver<D>& fluid, const RDSolver<D>& rd, const ChemicalDomain<D>& domain,
                    ChemicalInterpolation interpolation, CouplingMode mode, double rdTimeScale, GpuPrecision real);

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
  void blendLayer(int id, const Grid<float, D>& cover, const std::vector<double>& values) override;
  void maskLayer(const SmokeTaps<D>& taps, double threshold, const std::vector<double>& rest) override;

 private:
  GpuFluid<D> fluid_;
  GpuRDLayer<D> layer_;
  GpuARDSolver<D> ard_;
  std::array<double, 3> seconds_{};
  // The pattern on the smoke: the sources' covers by id (-1: the last
  // moving one), the mask's taps (uploaded by its first step), and a buffer
  // for the binding a mode does not read.
  std::map<int, GpuBuffer> covers_;
  StepCounts counts_;
  GpuBuffer taps_, none_;
  double rdH_;
  std::array<int, 3> rdCells_{1, 1, 1}, fluidCells_{1, 1, 1}, tapOff_{};
  void moveSolids(double dt);
  void layerKernel(bool blend, const GpuBuffer& cover, const std::vector<double>& values, double threshold);
};

}  // namespace morphoflow
