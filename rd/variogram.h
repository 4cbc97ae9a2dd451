// The variogram and its regularity measure REG (Manian & Vasquez, seed 003
// eq. 4-5): V(d) = E[(t(q) - t(q + d))^2] over all pairs of cells a spacing
// vector d apart, here for d = lag * (1,0), (0,1), (1,1) and (1,-1), lag =
// 1..maxLag, and REG = max_i V(d_i).
//
// V is divided by the field's variance, so REG does not depend on the
// intensity scale: uncorrelated noise gives V = 2 at every lag, a texture is
// more regular the more it anticorrelates with itself at some spacing, and a
// pure sinusoid reaches the upper bound 4 at half its period.
//
//   Variogram v = variogram(values, nx, ny, {.maxLag = 64});
//   double reg = v.reg;
#pragma once

#include <array>
#include <vector>

namespace morphoflow {

struct VariogramOptions {
  int maxLag = 0;        // 0: a quarter of the smaller side
  bool periodic = false; // pairs wrap around (tiles of periodic runs); else interior pairs only
};

struct Variogram {
  static constexpr int kDirections = 4;  // (1,0), (0,1), (1,1), (1,-1)
  std::vector<std::array<double, kDirections>> v;  // v[lag - 1][direction], normalised by the variance
  double variance = 0.0;
  double reg = 0.0;        // seed 003 eq. 5
  int regLag = 0;          // where the maximum is
  int regDirection = 0;
};

// `t` is an nx x ny field, x fastest. A constant field has variance 0: V and REG are then 0.
Variogram variogram(const std::vector<double>& t, int nx, int ny, const VariogramOptions& options = {});

}  // namespace morphoflow
