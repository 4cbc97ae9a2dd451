// The fluid's grid on the GPU (fluid/velocity_constraints.h's, on the
// device): the MAC velocity as one buffer (component a at offset(a) floats)
// and its scratch, the constraints' fixed flags and prescribed values, the
// solid cells and, with cut obstacles, the faces' open fractions (a moving
// obstacle's also its flux); the
// programs of the stage shaders that read them (shaders/fluid_faces.glsl).
#pragma once

#include <array>
#include <string>

#include "core/backend.h"
#include "fluid/velocity_constraints.h"
#include "gpu/gpu_buffer.h"
#include "gpu/kernel_modes.h"

namespace morphoflow {

class ComputeProgram;

// The pressure's solution phi is double in either precision: its float
// rounding alone would leave a relative residual of eps_float times the
// system's condition (4.5e-4 in the 220 x 41 channel), while the solve's
// other vectors in float still reach 1e-6 (docs/gpu.md, "Precision"). The
// stage shaders declare it (XREAL).
inline constexpr GpuPrecision kPhiPrecision = GpuPrecision::Double;

template <int D>
struct GpuMacGrid {
  explicit GpuMacGrid(const VelocityConstraints<D>& vc);
  // The constraints changed (a moving obstacle), not the grid: their flags,
  // values, fractions and solid flux again (only for the faces of the cells [lo, hi)).
  void refresh(const VelocityConstraints<D>& vc);
  void refresh(const VelocityConstraints<D>& vc, const IVec<D>& lo, const IVec<D>& hi);

  size_t faces(int a) const;                   // the faces of component a
  std::array<int, 3> velocityOffsets() const;  // the components' offsets in the velocity buffer (uniform velOff)
  // The stage shader of `mode` (with `more` defines), made current: REAL is
  // `real`, XREAL phi's; its uniforms are the caller's.
  const ComputeProgram& stage(FluidOp mode, GpuPrecision real, const std::string& more = "") const;
  // The constraints on `vel`: prescribed faces take their values, periodic sides their copies.
  void constrain(const GpuBuffer& vel, GpuPrecision real) const;

  std::array<int, 3> cells{1, 1, 1}, periodic{};
  std::array<size_t, 3> off{};
  size_t cellCount = 0, faceCount = 0, maxGrid = 0;
  double h = 1.0;
  bool cut = false;  // cut or moving obstacles (open fractions between 0 and 1)
  GpuBuffer vel, velScratch, fixed, value, solid, open;
  GpuBuffer solidFlux;  // a moving obstacle's: VelocityConstraints::solidFlux in double (else none)
};

}  // namespace morphoflow
