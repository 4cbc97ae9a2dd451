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

template <int D>
struct LinearSampler {
  const float* data = nullptr;
  int n[D];             // samples along each axis
  size_t stride[D];     // flat-array distance between neighbours
  float offset[D];      // sample k sits at k + offset (cell units)
  bool periodic[D];
  int period[D];

  LinearSampler(const Grid<float, D>& g, const Layout<D>& l) : data(g.data()) {
    size_t s = 1;
    for (int a = 0; a < D; ++a) {
      n[a] = g.dim(a);
      stride[a] = s;
      s *= size_t(n[a]);
      offset[a] = float(l.offset[a]);
      periodic[a] = l.periodic[a];
      period[a] = l.period[a];
    }
  }

  // Lower sample index (times stride), upper offset and weight along one axis.
  void axis(int a, float p, size_t* i0, size_t* i1, float* t) const {
    float g = p - offset[a];
    int i;
    if (!periodic[a]) {
      g = std::clamp(g, 0.0f, float(n[a] - 1));
      i = std::min(int(g), std::max(n[a] - 2, 0));
      *t = g - float(i);
      *i0 = size_t(i) * stride[a];
      *i1 = size_t(std::min(i + 1, n[a] - 1)) * stride[a];
      return;
    }
    float f = std::floor(g);
    *t = g - f;
    i = int(f) % period[a];
    if (i < 0) i += period[a];
    int j = i + 1;
    if (j == period[a]) j = n[a] > period[a] ? period[a] : 0;
    *i0 = size_t(i) * stride[a];
    *i1 = size_t(j) * stride[a];
  }

  // Value at p; lo/hi (both or neither) receive the stencil's min and max.
  float operator()(const float* p, float* lo = nullptr, float* hi = nullptr) const {
    size_t i0[D], i1[D];
    float t[D];
    for (int a = 0; a < D; ++a) axis(a, p[a], &i0[a], &i1[a], &t[a]);
    if constexpr (D == 2) {
      const float* r0 = data + i0[1];
      const float* r1 = data + i1[1];
      float v00 = r0[i0[0]], v10 = r0[i1[0]], v01 = r1[i0[0]], v11 = r1[i1[0]];
      float a0 = v00 + t[0] * (v10 - v00), a1 = v01 + t[0] * (v11 - v01);
      if (lo) {
        *lo = std::min(std::min(v00, v10), std::min(v01, v11));
        *hi = std::max(std::max(v00, v10), std::max(v01, v11));
      }
      return a0 + t[1] * (a1 - a0);
    } else {
      const float* r00 = data + i0[1] + i0[2];
      const float* r10 = data + i1[1] + i0[2];
      const float* r01 = data + i0[1] + i1[2];
      const float* r11 = data + i1[1] + i1[2];
      float v[8] = {r00[i0[0]], r00[i1[0]], r10[i0[0]], r10[i1[0]],
                    r01[i0[0]], r01[i1[0]], r11[i0[0]], r11[i1[0]]};
      float x00 = v[0] + t[0] * (v[1] - v[0]), x10 = v[2] + t[0] * (v[3] - v[2]);
      float x01 = v[4] + t[0] * (v[5] - v[4]), x11 = v[6] + t[0] * (v[7] - v[6]);
      float y0 = x00 + t[1] * (x10 - x00), y1 = x01 + t[1] * (x11 - x01);
      if (lo) {
        float mn = v[0], mx = v[0];
        for (int k = 1; k < 8; ++k) {
          mn = std::min(mn, v[k]);
          mx = std::max(mx, v[k]);
        }
        *lo = mn;
        *hi = mx;
      }
      return y0 + t[2] * (y1 - y0);
    }
  }
};

}  // namespace morphoflow
