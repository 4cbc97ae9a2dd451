#include "rd/reaction_lut.h"

#include <algorithm>

#include "core/parallel.h"

namespace morphoflow {

bool ReactionLUT::build(const ReactionModel& m, const double* p, double dt, double lo, double hi, int n) {
  table_.clear();
  if (m.species() != 2 || n < 2 || !(hi > lo)) return false;
  n_ = n;
  lo_ = lo;
  inv_ = double(n - 1) / (hi - lo);
  dt_ = dt;
  table_.assign(2 * size_t(n) * size_t(n), 0.0);
  const double step = (hi - lo) / double(n - 1);
  parallelFor(size_t(n), [&](size_t j) {
    for (int i = 0; i < n; ++i) {
      double x0[2] = {lo + i * step, lo + double(j) * step}, x[2];
      newtonSolve(m, x0, p, dt, x, nullptr, nullptr);
      m.project(x);
      table_[2 * (j * size_t(n) + size_t(i))] = x[0];
      table_[2 * (j * size_t(n) + size_t(i)) + 1] = x[1];
    }
  });
  return true;
}

}  // namespace morphoflow
