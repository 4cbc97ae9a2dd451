#include "render/field_image.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"
#include "render/colormap.h"

namespace morphoflow {

template <int D>
std::vector<uint8_t> fieldToRgb(const Grid<float, D>& f, const FieldImageOptions& o, int* width, int* height) {
  const int nx = f.dim(0), ny = f.dim(1);
  size_t offset = 0;
  if constexpr (D == 3) {
    int z = o.slice >= 0 ? std::min(o.slice, f.dim(2) - 1) : f.dim(2) / 2;
    offset = size_t(z) * size_t(nx) * size_t(ny);
  }
  const size_t n = size_t(nx) * size_t(ny);
  double lo = o.range[0], hi = o.range[1];
  if (o.autoRange) {
    lo = 1e300;
    hi = -1e300;
    for (size_t i = 0; i < n; ++i) {
      double v = f[offset + i];
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (o.symmetric) {
      double m = std::max(std::abs(lo), std::abs(hi));
      lo = -m;
      hi = m;
    }
    if (!(hi > lo)) {
      lo = lo > 1e299 ? 0.0 : lo;
      hi = lo + 1.0;
    }
  }
  std::vector<uint8_t> rgb(n * 3);
  parallelFor(size_t(ny), [&](size_t row) {
    size_t y = size_t(ny) - 1 - row;  // y up
    for (size_t x = 0; x < size_t(nx); ++x) {
      auto c = colormap(o.colormap, (f[offset + y * size_t(nx) + x] - lo) / (hi - lo));
      std::copy(c.begin(), c.end(), &rgb[(row * size_t(nx) + x) * 3]);
    }
  });
  *width = nx;
  *height = ny;
  return rgb;
}

template std::vector<uint8_t> fieldToRgb<2>(const Grid<float, 2>&, const FieldImageOptions&, int*, int*);
template std::vector<uint8_t> fieldToRgb<3>(const Grid<float, 3>&, const FieldImageOptions&, int*, int*);

}  // namespace morphoflow
