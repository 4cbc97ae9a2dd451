// The compulsory memory traffic of whole steps, for the suites' roofline
// fractions. Every kernel pass of a step moves at least the bytes the
// roofline suite counts for it (its vectors read and written once,
// roofline_bench.cpp), so a step's bytes are the sum over its passes, from
// the iteration counts its solvers report; bytes / time over STREAM's triad
// bandwidth is then the fraction of memory speed the step reaches. A lower
// bound of the traffic, so the fraction is one too: a step that sweeps its
// vectors more often than its kernels must reads more than it is credited.
#pragma once

#include <array>

#include "fluid/fluid_solver.h"

namespace morphoflow {

// GB/s of STREAM's triad (a = b + s c, 3 x 128 MiB) with `threads` threads:
// the median of repeats over at least minSeconds (roofline_bench.cpp).
double triadBandwidth(int threads, double minSeconds);
// The triad with 1 and 2 threads (indexed by the thread count), printed on
// one line: what a suite's fractions divide by.
std::array<double, 3> suiteTriads(double minSeconds);

template <int D>
double cellCount(const IVec<D>& n) {
  double c = 1.0;
  for (int a = 0; a < D; ++a) c *= n[a];
  return c;
}

// A multigrid-preconditioned CG iteration a cell (double vectors): the
// operator (read p, write q: 16), the V-cycle (read r, write z, the finest
// coefficients once: 16 + 4 (D + 2)), the updates of x, r and p (3 x 24) and
// two inner products (2 x 16).
template <int D>
constexpr double kPcgIterationBytes = 16.0 + (16.0 + 4.0 * (D + 2)) + 3 * 24.0 + 2 * 16.0;

// One fluid step over `cells` cells: the advection reads and writes the D
// float components (8 D); the viscosity forms its right-hand sides and
// writes the result (8 D), plus 16 a Chebyshev cell update (two float
// iterates and g read, one written; a cyclic step updates half the cells)
// or a CG iteration's bytes; the
// projection's divergence and gradient (read u, write b, read phi, update
// u: 12 D + 16) and its MGPCG iterations.
template <int D>
double fluidStepBytes(double cells, const FluidStepStats& s) {
  const double perCell = 8.0 * D + 8.0 * D + 12.0 * D + 16.0 + s.pressure.iterations * kPcgIterationBytes<D>;
  return cells * perCell + s.viscosityCellUpdates * (s.viscosityUsedCG ? kPcgIterationBytes<D> : 16.0);
}

// One Kim & Lin step of `species` double species over `cells` cells: the
// Newton reaction reads and writes them (16 a species); each species'
// diffusion solve forms its warm start from the right-hand side and last
// increment and writes the result and the new increment (8 + 2 + 8 + 2),
// then its Chebyshev steps (16 a cell each, on the half of the cells a
// cyclic step updates: the benchmarks' grids are two-coloured;
// `diffusionSteps` the most of any species).
inline double kimLinStepBytes(double cells, int species, double diffusionSteps) {
  return cells * species * (16.0 + 20.0 + 8.0 * diffusionSteps);
}

// One ARD step: a Kim & Lin step, then the advection writes and reads the D
// float feet (8 D) and reads and writes each species (16).
inline double ardStepBytes(int D, double cells, int species, double diffusionSteps) {
  return kimLinStepBytes(cells, species, diffusionSteps) + cells * (8.0 * D + 16.0 * species);
}

}  // namespace morphoflow
