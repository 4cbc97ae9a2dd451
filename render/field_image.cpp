#include "render/field_image.h"

#include <algorithm>
#include <cmath>

#include "core/parallel.h"

namespace morphoflow {

namespace {

// First cell of the shown slice (0 in 2D).
template <int D>
size_t sliceOffset(const Grid<float, D>& f, int slice) {
  if constexpr (D == 3) {
    int z = slice >= 0 ? std::min(slice, f.dim(2) - 1) : f.dim(2) / 2;
    return size_t(z) * size_t(f.dim(0)) * size_t(f.dim(1));
  }
  return 0;
}

// Fills RGB rows top to bottom (y up) with colour(cell index).
template <typename Colour>
std::vector<uint8_t> paint(int nx, int ny, size_t offset, Colour colour) {
  std::vector<uint8_t> rgb(size_t(nx) * size_t(ny) * 3);
  parallelFor(size_t(ny), [&](size_t row) {
    size_t y = size_t(ny) - 1 - row;
    for (size_t x = 0; x < size_t(nx); ++x) {
      Rgb8 c = colour(offset + y * size_t(nx) + x);
      std::copy(c.begin(), c.end(), &rgb[(row * size_t(nx) + x) * 3]);
    }
  });
  return rgb;
}

}  // namespace

// The value range mapped to [0, 1]: fixed, or the finite min..max of the slice.
size_t countOutside(const float* values, size_t n, double lo, double hi) {
  size_t out = 0;
  for (size_t i = 0; i < n; ++i) out += (values[i] < lo || values[i] > hi) ? 1 : 0;
  return out;
}

std::array<double, 2> valueRange(const float* v, size_t n, const FieldImageOptions& o) {
  if (!o.autoRange) return {o.range[0], o.range[1]};
  double lo = 1e300, hi = -1e300;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) continue;
    lo = std::min(lo, double(v[i]));
    hi = std::max(hi, double(v[i]));
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
  return {lo, hi};
}

template <int D>
std::vector<uint8_t> fieldToRgb(const Grid<float, D>& f, const FieldImageOptions& o, int* width, int* height) {
  const int nx = f.dim(0), ny = f.dim(1);
  const size_t offset = sliceOffset(f, o.slice);
  const std::array<double, 2> range = valueRange(&f[offset], size_t(nx) * size_t(ny), o);
  const double lo = range[0], hi = range[1];
  *width = nx;
  *height = ny;
  return paint(nx, ny, offset, [&](size_t i) { return o.palette((f[i] - lo) / (hi - lo)); });
}

template <int D>
std::vector<uint8_t> twoFieldsToRgb(const Grid<float, D>& red, const Grid<float, D>& green,
                                    const FieldImageOptions& o, int* width, int* height) {
  const int nx = red.dim(0), ny = red.dim(1);
  const size_t offset = sliceOffset(red, o.slice), n = size_t(nx) * size_t(ny);
  const std::array<double, 2> r = valueRange(&red[offset], n, o), g = valueRange(&green[offset], n, o);
  const double rlo = r[0], rhi = r[1], glo = g[0], ghi = g[1];
  auto byte = [](double t) { return uint8_t(std::lround(255.0 * std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0))); };
  *width = nx;
  *height = ny;
  return paint(nx, ny, offset, [&](size_t i) {
    return Rgb8{byte((red[i] - rlo) / (rhi - rlo)), byte((green[i] - glo) / (ghi - glo)), 0};
  });
}

std::vector<uint8_t> upscaleToWidth(const std::vector<uint8_t>& rgb, int* width, int* height, int minWidth) {
  const int k = std::max(1, (minWidth + *width - 1) / *width);
  if (k == 1) return rgb;
  const int w = *width * k, h = *height * k;
  std::vector<uint8_t> out(size_t(w) * size_t(h) * 3);
  parallelFor(size_t(h), [&](size_t row) {
    const uint8_t* src = &rgb[(row / size_t(k)) * size_t(*width) * 3];
    uint8_t* dst = &out[row * size_t(w) * 3];
    for (size_t x = 0; x < size_t(w); ++x) std::copy_n(src + (x / size_t(k)) * 3, 3, dst + x * 3);
  });
  *width = w;
  *height = h;
  return out;
}

template std::vector<uint8_t> fieldToRgb<2>(const Grid<float, 2>&, const FieldImageOptions&, int*, int*);
template std::vector<uint8_t> fieldToRgb<3>(const Grid<float, 3>&, const FieldImageOptions&, int*, int*);
template std::vector<uint8_t> twoFieldsToRgb<2>(const Grid<float, 2>&, const Grid<float, 2>&,
                                                const FieldImageOptions&, int*, int*);
template std::vector<uint8_t> twoFieldsToRgb<3>(const Grid<float, 3>&, const Grid<float, 3>&,
                                                const FieldImageOptions&, int*, int*);

}  // namespace morphoflow
