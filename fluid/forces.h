// External forces: a constant body acceleration and dye buoyancy
// (Fedkiw, Stam & Jensen 2001: f = beta * dye * up), added as u += dt f.
#pragma once

#include "core/mac_velocity.h"
#include "fluid/fluid_settings.h"

namespace morphoflow {

template <int D>
void applyForces(const FluidSettings& settings, const Grid<float, D>* dye, double dt, MacVelocity<D>* u);

}  // namespace morphoflow
