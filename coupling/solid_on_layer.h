// The fluid's solid cells seen by the chemicals' grid: an RD cell is solid
// when the fluid cell holding its centre is. A moving obstacle's cells
// follow it every step: those it uncovers take their fluid neighbours'
// mean, those it covers the solid values (fluid/extrapolation.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/grid.h"
#include "core/parallel.h"
#include "fluid/extrapolation.h"

namespace morphoflow {

template <int D>
Grid<uint8_t, D> solidOnLayer(const Grid<uint8_t, D>& fluidSolid, double fluidH, const IVec<D>& cells, double h) {
  Grid<uint8_t, D> mask(cells, 0);
  const IVec<D>& n = fluidSolid.dims();
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    IVec<D> f;
    for (int a = 0; a < D; ++a) f[a] = std::clamp(int(std::floor((k[a] + 0.5) * h / fluidH)), 0, n[a] - 1);
    mask[i] = fluidSolid(f);
  });
  return mask;
}

// The species after the solid moved from `was` to `now` (RD cells).
template <int D>
void followSolid(const std::vector<Grid<double, D>*>& species, const std::vector<double>& solidValues,
                 const Grid<uint8_t, D>& was, const Grid<uint8_t, D>& now) {
  const FillPlan plan = fillPlan<D>(was, now);
  for (size_t s = 0; s < species.size(); ++s)
    applyFill<double>(plan, species[s]->data(), s < solidValues.size() ? solidValues[s] : 0.0);
}

}  // namespace morphoflow
