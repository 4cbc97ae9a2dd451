// The 3D previews' fixed view: a three-quarter camera looking at the box's
// centre, y up, in the units of a grid's cells (cell i spans [i, i + 1]),
// with the ray's clip to the box, trilinear sampling between cell centres
// and the box's edges drawn over an image.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/grid.h"

namespace morphoflow {

using V3 = std::array<double, 3>;

inline V3 add(V3 a, V3 b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline V3 scale(V3 a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(V3 a, V3 b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline V3 unit(V3 a) { return scale(a, 1.0 / std::sqrt(dot(a, a))); }

// 40 degrees round the vertical (y) axis from +z towards +x, 25 degrees
// above the horizontal, a 30 degree field of view that holds the box's
// bounding sphere.
struct VolumeCamera {
  V3 eye, forward, right, up, towardEye;
  double tanHalf;
  explicit VolumeCamera(const IVec<3>& n);
  // The ray through pixel (px, py) of a size x size image.
  V3 ray(int px, int py, int size) const;
  // Where a point lands in the image (pixels), and whether it is in front.
  bool project(V3 p, int size, double* x, double* y) const;
};

// Entry and exit of the ray o + t d through the box [0, n].
bool clipToBox(const V3& o, const V3& d, const IVec<3>& n, double* t0, double* t1);

// The corners of trilinear interpolation at p between the centres of a grid
// of n cells (cell i's centre at i + 1/2), clamped to the outermost centres:
// tap(cell, weight) for each corner of nonzero weight.
template <class Tap>
void trilinearTaps(const IVec<3>& n, const V3& p, Tap&& tap) {
  int i0[3];
  double w[3];
  for (int a = 0; a < 3; ++a) {
    const double x = std::clamp(p[size_t(a)] - 0.5, 0.0, double(n[a] - 1));
    i0[a] = std::min(int(x), n[a] - 2 < 0 ? 0 : n[a] - 2);
    w[a] = n[a] > 1 ? x - i0[a] : 0.0;
  }
  for (int c = 0; c < 8; ++c) {
    IVec<3> k;
    double wt = 1;
    for (int a = 0; a < 3; ++a) {
      const int bit = (c >> a) & 1;
      k[a] = std::min(i0[a] + bit, n[a] - 1);
      wt *= bit ? w[a] : 1.0 - w[a];
    }
    if (wt != 0) tap(k, wt);
  }
}

// Trilinear interpolation of f at p (trilinearTaps).
float sampleCells(const Grid<float, 3>& f, const V3& p);

// The box's twelve edges, faintly over a size x size RGB image.
void drawBoxEdges(const VolumeCamera& cam, const IVec<3>& n, int size, std::vector<uint8_t>* rgb);

}  // namespace morphoflow
