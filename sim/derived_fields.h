// The catalogue's derived fields (FieldSource::Derived,
// scenes/field_catalogue.h), computed from a simulation's own fields:
//   density               output.vdb_density: a field, or its expression of
//                         fields per cell on the chemicals' grid when it
//                         names a species (the fluid's fields sampled at
//                         their centres), else on the fluid's;
//   color                 the frames' palette applied to the shown field, as
//                         linear RGB in [0, 1] (Blender's Principled Volume
//                         reads a grid named `color`);
//   height                the shown field mapped to [0, 1] by the frames'
//                         range (a normal map's height field, seed 000 fig. 7);
//   active                1 where the smoke exceeds output.vdb_tolerance (1
//                         everywhere with output.vdb_sparse = false);
//   active_chemicals      the same on the chemicals' grid, the smoke sampled
//                         at their centres.
#pragma once

#include <string>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

template <int D>
class Simulation;

template <int D>
std::vector<Grid<float, D>> derivedField(const Simulation<D>& sim, const std::string& name);

}  // namespace morphoflow
