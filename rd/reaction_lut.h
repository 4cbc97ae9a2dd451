// Precomputed implicit reaction step (Kim & Lin sec. 3.2): for a two-species
// model with uniform parameters and a fixed dt, the map x0 -> x^ solving
// x^ = x0 + dt R(x^) is tabulated on an n x n lattice over [lo, hi]^2 and
// read back bilinearly; states outside the table fall back to Newton.
#pragma once

#include <algorithm>
#include <vector>

#include "rd/reaction_model.h"

namespace morphoflow {

class ReactionLUT {
 public:
  ReactionLUT() = default;
  // Builds the table; false (and an empty table) if the model is not a
  // two-species model.
  bool build(const ReactionModel& m, const double* p, double dt, double lo, double hi, int n);
  bool valid() const { return !table_.empty(); }
  double dt() const { return dt_; }
  // Looks x0 up; false if it lies outside the table. A state within 1e-6
  // of a spacing outside (a diffusion solve's round-off around a species'
  // floor, e.g. -1e-17 where the table starts at 0) reads the edge: that
  // moves x0 by far less than the bilinear error.
  bool lookup(const double* x0, double* x) const {
    constexpr double kMargin = 1e-6;
    double g0 = (x0[0] - lo_) * inv_, g1 = (x0[1] - lo_) * inv_;
    if (!(g0 >= -kMargin && g1 >= -kMargin && g0 <= n_ - 1 + kMargin && g1 <= n_ - 1 + kMargin)) return false;
    g0 = std::clamp(g0, 0.0, double(n_ - 1));
    g1 = std::clamp(g1, 0.0, double(n_ - 1));
    int i = std::min(int(g0), n_ - 2), j = std::min(int(g1), n_ - 2);
    double t = g0 - i, u = g1 - j;
    const double* a = &table_[2 * (size_t(j) * size_t(n_) + size_t(i))];
    const double* b = a + 2 * size_t(n_);
    for (int s = 0; s < 2; ++s) {
      double lo = a[s] + t * (a[2 + s] - a[s]), hi = b[s] + t * (b[2 + s] - b[s]);
      x[s] = lo + u * (hi - lo);
    }
    return true;
  }

 private:
  std::vector<double> table_;
  double lo_ = 0, inv_ = 1, dt_ = 0;
  int n_ = 0;
};

}  // namespace morphoflow
