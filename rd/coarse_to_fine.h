// Coarse-to-fine pattern acceleration (Lawlor, seed 002 "Multigrid"; McGraw,
// seed 000 sec. 6: 64 -> 128 -> 256): a pattern is grown on a grid 2^L times
// coarser over the same domain, then carried to each finer grid by
// prolongation and grown on. Only the coarse-to-fine direction is used (seed
// 002: "no reverse restriction is required").
#pragma once

#include "core/grid.h"

namespace morphoflow {

// Cell-centred multilinear prolongation onto a grid of twice the cells per
// axis: fine cell i sits at coarse position i/2 - 1/4, weights 3/4 and 1/4.
// Periodic grids wrap; otherwise the edge value is held (zero-gradient).
template <int D>
void prolongate(const Grid<double, D>& coarse, Grid<double, D>* fine, bool periodic);

}  // namespace morphoflow
