// Explicit reaction-diffusion in one pass per step: the species stored as
// floats (8 bytes a cell for two species, against 16 in RDSolver's doubles),
// and each cell's Laplacian (the 5-/7-point stencil, periodic or zero-flux),
// the model's own rates and the Euler update x' = x + dt (R(x) + d lap x)
// (seed 000 eq. 27) computed together from the float neighbours to the float
// result: eight float lanes under AVX2 (four double lanes for models whose
// rates compare), sixteen under AVX-512 for the 5 x 5 kernel. Every lane does
// the scalar code's operations in its order and without FMA, and every row
// reads only the previous state, so the result does not depend on the
// lanes, the rows' tiling or the thread count.
//
// It covers what a plain explicit layer needs: uniform parameters, the
// model's clamped species, and McGraw's 5 x 5 generalized kernel in place of
// the Laplacian. Maps, tensors, lobes, fixed cells and Dirichlet walls stay
// with RDSolver.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

template <int D>
class FusedExplicitRD {
 public:
  // The engine for `model` (null for a model without fixed-size rates).
  static std::unique_ptr<FusedExplicitRD> create(const std::string& model, const IVec<D>& cells, double h,
                                                 bool periodic, const std::vector<double>& diffusion,
                                                 const std::vector<double>& parameters);
  virtual ~FusedExplicitRD() = default;

  // McGraw's generalized diffusion (seed 000 eq. 37): the species (empty:
  // all) diffuse by d K * x, K the 5 x 5 kernel in physical units
  // (weights[dy + 2][dx + 2]), in place of the Laplacian. Periodic 2D only.
  virtual void setKernel(const std::array<std::array<double, 5>, 5>& kernel, const std::vector<int>& species) = 0;
  // `steps` explicit steps of dt.
  virtual void step(double dt, int steps = 1) = 0;
  // Rows per task of a single step: any value gives bitwise the same fields (tests vary it).
  void setRowsPerTask(size_t rows) { rowsPerTask_ = rows; }
  // Temporal blocking: `steps` steps per pass over slabs of `slices` outer
  // slices (rows in 2D, planes in 3D) per task; 0 for the automatic choice,
  // steps = 1 for none. Any values give bitwise the same fields.
  void setTemporalBlocking(int steps, size_t slices) { stepsPerPass_ = steps, slicesPerTask_ = slices; }
  // The steps one pass takes (1: no blocking): step(dt, steps) gains where
  // `steps` is a multiple of it.
  virtual int stepsPerPass() const = 0;
  int species() const { return int(x_.size()); }
  std::vector<float>& field(int s) { return x_[size_t(s)]; }
  const std::vector<float>& field(int s) const { return x_[size_t(s)]; }
  const IVec<D>& cells() const { return cells_; }

 protected:
  IVec<D> cells_;
  std::vector<std::vector<float>> x_, next_;
  size_t rowsPerTask_ = 0;  // 0: the parallel loop's own grain
  int stepsPerPass_ = 0;     // 0: automatic
  size_t slicesPerTask_ = 0;  // 0: automatic
};

}  // namespace morphoflow
