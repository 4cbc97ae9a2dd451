// The pattern on the smoke: a layer that reacts only where there is smoke.
// Each backend applies the same two operations after its coupled step:
//   blend: species x towards a source's chemicals v by its cover c of the
//          cell, x = (1 - c) x + c v (kernels/smoke_physics.inc coverBlend);
//   mask:  where the smoke, linearly interpolated at the layer cell's centre,
//          is at most the threshold, the species take their rest values.
// The mask's interpolation taps are separable (each axis' depends on the
// cell's coordinate along that axis alone), so they are computed once here
// and both backends read the same ones.
#pragma once

#include <array>
#include <vector>

#include "core/grid.h"
#include "core/sampling.h"
#include "rd/rd_solver.h"

namespace morphoflow {

// Along each axis, for layer cell k: the smoke samples i0, i1 and the weight t of i1.
template <int D>
struct SmokeTaps {
  std::array<std::vector<int>, D> i0, i1;
  std::array<std::vector<float>, D> t;
};

// The taps of the smoke grid (`smoke`: the fluid's cell layout, `smokeCells`
// its cells) at the centres of the layer's cells (`cells`, spacing h).
template <int D>
SmokeTaps<D> smokeTaps(const Layout<D>& smoke, const IVec<D>& smokeCells, const IVec<D>& cells, double h);

// blend, on every species of `rd`.
template <int D>
void blendLayer(RDSolver<D>* rd, const Grid<float, D>& cover, const std::vector<double>& values);

// mask, on every species of `rd`, of the smoke `smoke`.
template <int D>
void maskLayer(RDSolver<D>* rd, const Grid<float, D>& smoke, const SmokeTaps<D>& taps, double threshold,
               const std::vector<double>& rest);

}  // namespace morphoflow
