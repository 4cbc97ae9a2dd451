#include "rd/variogram.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"

namespace morphoflow {

Variogram variogram(const std::vector<double>& t, int nx, int ny, const VariogramOptions& o) {
  Variogram out;
  const int maxLag = o.maxLag > 0 ? o.maxLag : std::max(1, std::min(nx, ny) / 4);
  const size_t n = size_t(nx) * size_t(ny);
  double mean = 0.0;
  for (double x : t) mean += x;
  mean /= double(n);
  double var = 0.0;
  for (double x : t) var += (x - mean) * (x - mean);
  out.variance = var / double(n);
  out.v.assign(size_t(maxLag), {});
  static constexpr int dir[Variogram::kDirections][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  // Eq. 4 per spacing vector; each (lag, direction) is one task, summed in a fixed order.
  parallelFor(size_t(maxLag) * Variogram::kDirections, [&](size_t task) {
    const int lag = int(task / Variogram::kDirections) + 1, d = int(task % Variogram::kDirections);
    const int dx = dir[d][0] * lag, dy = dir[d][1] * lag;
    double sum = 0.0;
    long pairs = 0;
    for (int y = 0; y < ny; ++y) {
      int y2 = y + dy;
      if (o.periodic) y2 = ((y2 % ny) + ny) % ny;
      else if (y2 < 0 || y2 >= ny) continue;
      for (int x = 0; x < nx; ++x) {
        int x2 = x + dx;
        if (o.periodic) x2 %= nx;
        else if (x2 >= nx) break;
        const double diff = t[size_t(y) * size_t(nx) + size_t(x)] - t[size_t(y2) * size_t(nx) + size_t(x2)];
        sum += diff * diff;
        ++pairs;
      }
    }
    out.v[size_t(lag - 1)][size_t(d)] = pairs > 0 && out.variance > 0 ? sum / double(pairs) / out.variance : 0.0;
  }, 1);
  // Eq. 5.
  for (int lag = 1; lag <= maxLag; ++lag)
    for (int d = 0; d < Variogram::kDirections; ++d)
      if (out.v[size_t(lag - 1)][size_t(d)] > out.reg) {
        out.reg = out.v[size_t(lag - 1)][size_t(d)];
        out.regLag = lag;
        out.regDirection = d;
      }
  return out;
}

}  // namespace morphoflow
