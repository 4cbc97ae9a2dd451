// The smoke's stages on the GPU (fluid/smoke.h; Fedkiw, Stam & Jensen 2001):
// the sources' emission and injection, buoyancy and vorticity confinement as
// cell-centred forces taken onto the faces, dissipation and cooling
// (shaders/smoke.comp, the formulas kernels/smoke_physics.inc's). The smoke
// density is the fluid's dye; the temperature is held here.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "core/grid.h"
#include "fluid/fluid_settings.h"
#include "gpu/fluid/gpu_mac_grid.h"

namespace morphoflow {

template <int D>
class GpuSmoke {
 public:
  GpuSmoke(const FluidSettings& settings, const VelocityConstraints<D>& vc, const GpuMacGrid<D>* grid,
           GpuPrecision real);
  // Each source over the part of [time, time + dt] inside its window, where it is at mid-step.
  void emit(double time, double dt, GpuBuffer* dye);
  // The solid cells now (a moving obstacle's), which a moving source's cover leaves out.
  void setSolid(const Grid<uint8_t, D>& solid) { solid_ = solid; }
  // Buoyancy and confinement onto the faces of grid.vel.
  void forces(double dt, const GpuBuffer& dye);
  void decay(double dt, GpuBuffer* dye);
  GpuBuffer& temperature() { return temp_; }
  const GpuBuffer& temperature() const { return temp_; }
  GpuBuffer& temperatureScratch() { return tempScratch_; }

 private:
  void run(SmokeOp mode, size_t n, int axis, const GpuBuffer& dye,
           const std::function<void(const ComputeProgram&)>& uniforms);
  const SmokeSettings& smoke() const { return settings_.smoke; }
  FluidSettings settings_;
  const GpuMacGrid<D>& grid_;
  GpuPrecision real_;
  GpuBuffer temp_, tempScratch_, force_, centre_, omega_;  // the temperature; the forces' work vectors
  std::vector<GpuBuffer> cover_;                           // each source's cover of the cells
  Grid<uint8_t, D> solid_;                                 // for a moving source's cover
};

}  // namespace morphoflow
