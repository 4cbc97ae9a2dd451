#include "render/normal_map.h"

#include <algorithm>
#include <cmath>

namespace morphoflow {

namespace {

// dh along `axis` at cell c, per cell.
double slope(const Grid<float, 2>& h, IVec<2> c, int axis, bool periodic) {
  const int n = h.dim(axis);
  IVec<2> lo = c, hi = c;
  lo[axis] -= 1;
  hi[axis] += 1;
  double span = 2.0;
  if (periodic) {
    lo[axis] = (lo[axis] + n) % n;
    hi[axis] %= n;
  } else {
    if (lo[axis] < 0) lo[axis] = 0, span = 1.0;
    if (hi[axis] >= n) hi[axis] = n - 1, span = 1.0;
    if (n == 1) return 0.0;
  }
  return (double(h(hi)) - double(h(lo))) / span;
}

}  // namespace

std::vector<float> surfaceNormals(const Grid<float, 2>& height, const NormalMapOptions& o) {
  std::vector<float> n(3 * height.size());
  for (int y = 0; y < height.dim(1); ++y)
    for (int x = 0; x < height.dim(0); ++x) {
      const IVec<2> c(x, y);
      const double nx = -o.strength * slope(height, c, 0, o.periodic),
                   ny = -o.strength * slope(height, c, 1, o.periodic);
      const double len = std::sqrt(nx * nx + ny * ny + 1.0);
      const size_t i = 3 * height.index(c);
      n[i] = float(nx / len), n[i + 1] = float(ny / len), n[i + 2] = float(1.0 / len);
    }
  return n;
}

std::vector<uint8_t> normalMapRgb(const Grid<float, 2>& height, const NormalMapOptions& o) {
  const std::vector<float> n = surfaceNormals(height, o);
  const int w = height.dim(0), hgt = height.dim(1);
  std::vector<uint8_t> rgb(n.size());
  for (int y = 0; y < hgt; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t src = 3 * (size_t(y) * size_t(w) + size_t(x)),
                   dst = 3 * (size_t(hgt - 1 - y) * size_t(w) + size_t(x));
      for (int k = 0; k < 3; ++k)
        rgb[dst + size_t(k)] = uint8_t(std::lround(std::clamp(0.5 * (n[src + size_t(k)] + 1.0), 0.0, 1.0) * 255.0));
    }
  return rgb;
}

}  // namespace morphoflow
