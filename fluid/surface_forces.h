// The force the fluid exerts on the cut obstacles, integrated on their
// surface rather than on a staircase: the traction -p n + mu du/dn
// (u relative to the wall; a no-slip rigid wall: the normal derivative is the whole velocity
// gradient's), at one point per cut cell, weighted by the cell's piece of
// the surface as the open fractions give it (the fluid part of the cell is
// closed, so its surface's area vector is the sum of its faces' open area
// vectors). p is extrapolated linearly to the surface and du/dn taken from
// the quadratic through the wall's zero velocity, from samples at 2h and 3h
// along the normal, where the interpolation stencils lie in the fluid.
#pragma once

#include <array>
#include <vector>

#include "core/mac_velocity.h"
#include "fluid/velocity_constraints.h"

namespace morphoflow {

struct SurfaceElement {
  std::array<double, 3> x{};     // a point on the surface
  std::array<double, 3> area{};  // the outward (into the fluid) normal times the area
};

// One element per cell that a cut obstacle crosses.
template <int D>
std::vector<SurfaceElement> cutSurfaceElements(const VelocityConstraints<D>& vc);

// The force on the surface `elements` from the velocity u, the pressure p
// (cell-centred) and the dynamic viscosity mu; on a moving body the shear
// is the fluid's velocity relative to the body's (`bodies`, when given).
template <int D>
std::array<double, 3> surfaceForce(const std::vector<SurfaceElement>& elements, const MacVelocity<D>& u,
                                   const Grid<float, D>& p, double mu, const CutSurface* bodies = nullptr);

}  // namespace morphoflow
