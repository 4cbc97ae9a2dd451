// Advection on the GPU (fluid/advection.h): one grid carried through the
// velocity by the scene's scheme, semi-Lagrangian with the midpoint
// back-trace (shaders/advect.comp), MacCormack or BFECC with the CPU's
// limiter (shaders/advection_correction.comp).
#pragma once

#include <array>

#include "fluid/fluid_settings.h"
#include "gpu/fluid/gpu_mac_grid.h"

namespace morphoflow {

template <int D>
class GpuAdvection {
 public:
  GpuAdvection(const GpuMacGrid<D>& grid, AdvectionScheme scheme, GpuPrecision real);
  // src (its samples from srcOff, dims `dims`, sample k at (k + offset) h)
  // through grid.vel over dt into dst (from dstOff).
  void advect(const GpuBuffer& src, size_t srcOff, const std::array<int, 3>& dims, const std::array<float, 3>& offset,
              double dt, GpuBuffer* dst, size_t dstOff);

 private:
  const GpuMacGrid<D>& grid_;
  AdvectionScheme scheme_;
  GpuPrecision real_;
  GpuBuffer lo_, hi_, back_, fwd_;  // the second-order schemes' scratch
};

}  // namespace morphoflow
