// LinearSampler<D>: the hot-loop form of sampleLinear (sampling.h) for float
// grids. Positions are in cell units (world / h, 0 at the domain's low
// corner), arithmetic is single precision, and the per-axis layout facts are
// unpacked once, so a bi-/trilinear sample costs a few loads and FMAs. Same
// boundary rules as sampleLinear: non-periodic axes clamp to the outermost
// samples, periodic axes wrap (face grids carry one duplicate sample).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/sampling.h"

namespace morphoflow {

// The two samples that bracket a position along one axis, and the weight of
// the upper one.
struct AxisTap {
  int lo, hi;
  float t;
};

// How samples are laid out along one axis.
struct AxisSamples {
  int n = 1;            // samples along the axis
  int period = 1;       // cells along the axis (the wrap period)
  bool periodic = false;
  float offset = 0.5f;  // sample k sits at k + offset (cell units)

  AxisSamples() = default;
  AxisSamples(int samples, int cells, bool wrap, float off) : n(samples), period(cells), periodic(wrap), offset(off) {}

  AxisTap at(float p) const {
    float g = float(boundedCoordinate(p - offset));
    if (!periodic) {
      g = std::clamp(g, 0.0f, float(n - 1));
      int i = std::min(int(g), std::max(n - 2, 0));
      return {i, std::min(i + 1, n - 1), g - float(i)};
    }
    float f = std::floor(g);
    int i = int(f) % period;
    if (i < 0) i += period;
    int j = i + 1;
    if (j == period) j = n > period ? period : 0;
    return {i, j, g - f};
  }
};

// Bi-/trilinear interpolation of `data` (strides s) between the taps; lo/hi
// (both or neither) receive the stencil's min and max.
template <int D>
inline float interpolate(const float* data, const size_t* s, const AxisTap* tap, float* lo = nullptr,
                         float* hi = nullptr) {
  const float* b = data + size_t(tap[0].lo);
  const ptrdiff_t dx = ptrdiff_t(tap[0].hi) - ptrdiff_t(tap[0].lo);  // < 0 across a wrap
  const float tx = tap[0].t;
  if constexpr (D == 2) {
    const float* r0 = b + size_t(tap[1].lo) * s[1];
    const float* r1 = b + size_t(tap[1].hi) * s[1];
    float v00 = r0[0], v10 = r0[dx], v01 = r1[0], v11 = r1[dx];
    if (lo) {
      *lo = std::min(std::min(v00, v10), std::min(v01, v11));
      *hi = std::max(std::max(v00, v10), std::max(v01, v11));
    }
    return bilinear(v00, v10, v01, v11, tx, tap[1].t);
  } else {
    const size_t y0 = size_t(tap[1].lo) * s[1], y1 = size_t(tap[1].hi) * s[1];
    const size_t z0 = size_t(tap[2].lo) * s[2], z1 = size_t(tap[2].hi) * s[2];
    const float *r00 = b + y0 + z0, *r10 = b + y1 + z0, *r01 = b + y0 + z1, *r11 = b + y1 + z1;
    float v[8] = {r00[0], r00[dx], r10[0], r10[dx], r01[0], r01[dx], r11[0], r11[dx]};
    if (lo) {
      float mn = v[0], mx = v[0];
      for (int k = 1; k < 8; ++k) {
        mn = std::min(mn, v[k]);
        mx = std::max(mx, v[k]);
      }
      *lo = mn;
      *hi = mx;
    }
    return trilinear(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], tx, tap[1].t, tap[2].t);
  }
}

template <int D>
struct LinearSampler {
  const float* data = nullptr;
  size_t stride[D];  // flat-array distance between neighbours
  AxisSamples axis[D];

  LinearSampler(const Grid<float, D>& g, const Layout<D>& l) : data(g.data()) {
    size_t s = 1;
    for (int a = 0; a < D; ++a) {
      stride[a] = s;
      s *= size_t(g.dim(a));
      axis[a] = AxisSamples(g.dim(a), l.period[a], l.periodic[a], float(l.offset[a]));
    }
  }

  // Value at p; lo/hi (both or neither) receive the stencil's min and max.
  float operator()(const float* p, float* lo = nullptr, float* hi = nullptr) const {
    AxisTap t[D];
    for (int a = 0; a < D; ++a) t[a] = axis[a].at(p[a]);
    return interpolate<D>(data, stride, t, lo, hi);
  }
};

}  // namespace morphoflow
