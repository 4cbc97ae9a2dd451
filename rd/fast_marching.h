// Fast marching (Sethian 1996) with extension values (Adalsteinsson & Sethian
// 1999), the machinery of Kim & Lin's painting interface (seed 001 sec. 6):
// from seed cells of known distance and values, it computes every cell's
// distance to the seeds (first-order upwind eikonal |grad d| = 1, a binary
// heap over the narrow band) and carries the values outwards along the
// characteristics, so that grad d . grad v = 0 holds discretely: each cell
// takes the mean of its upwind neighbours' values weighted by d - d_nb.
#pragma once

#include <vector>

#include "core/grid.h"

namespace morphoflow {

struct MarchingSeeds {
  std::vector<size_t> cells;                // flat cell indices (x fastest)
  std::vector<double> distance;             // per seed, domain units
  std::vector<std::vector<double>> values;  // [channel][seed], the values to extend
};

struct MarchingResult {
  std::vector<double> distance;             // per cell, domain units (infinite where no seed is reached)
  std::vector<std::vector<double>> values;  // [channel][cell]
};

// `h` is the cell size (cells are cubes); periodic grids march across the wrap.
// Deterministic: ties in the heap are broken by cell index.
template <int D>
MarchingResult fastMarch(const IVec<D>& cells, double h, bool periodic, const MarchingSeeds& seeds);

}  // namespace morphoflow
