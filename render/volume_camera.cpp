#include "render/volume_camera.h"

#include <algorithm>

namespace morphoflow {

VolumeCamera::VolumeCamera(const IVec<3>& n) {
  const V3 centre{0.5 * n[0], 0.5 * n[1], 0.5 * n[2]};
  const double radius = 0.5 * std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
  const double az = 40.0 * M_PI / 180.0, el = 25.0 * M_PI / 180.0, halfFov = 15.0 * M_PI / 180.0;
  towardEye = {std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
  eye = add(centre, scale(towardEye, 1.02 * radius / std::sin(halfFov)));
  forward = scale(towardEye, -1.0);
  right = unit(cross(forward, V3{0, 1, 0}));
  up = cross(right, forward);
  tanHalf = std::tan(halfFov);
}

V3 VolumeCamera::ray(int px, int py, int size) const {
  const double u = (2.0 * (px + 0.5) / size - 1.0) * tanHalf, v = (1.0 - 2.0 * (py + 0.5) / size) * tanHalf;
  return unit(add(forward, add(scale(right, u), scale(up, v))));
}

bool VolumeCamera::project(V3 p, int size, double* x, double* y) const {
  const V3 d = add(p, scale(eye, -1.0));
  const double z = dot(d, forward);
  if (z <= 0) return false;
  *x = (dot(d, right) / (z * tanHalf) + 1.0) * 0.5 * size - 0.5;
  *y = (1.0 - dot(d, up) / (z * tanHalf)) * 0.5 * size - 0.5;
  return true;
}

bool clipToBox(const V3& o, const V3& d, const IVec<3>& n, double* t0, double* t1) {
  *t0 = 0;
  *t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[size_t(a)]) < 1e-12) {
      if (o[size_t(a)] < 0 || o[size_t(a)] > n[a]) return false;
      continue;
    }
    double ta = (0 - o[size_t(a)]) / d[size_t(a)], tb = (n[a] - o[size_t(a)]) / d[size_t(a)];
    if (ta > tb) std::swap(ta, tb);
    *t0 = std::max(*t0, ta);
    *t1 = std::min(*t1, tb);
  }
  return *t1 > *t0;
}

float sampleCells(const Grid<float, 3>& f, const V3& p) {
  double v = 0;
  trilinearTaps(f.dims(), p, [&](const IVec<3>& k, double w) { v += w * f(k); });
  return float(v);
}

void drawBoxEdges(const VolumeCamera& cam, const IVec<3>& n, int size, std::vector<uint8_t>* rgb) {
  const V3 corner[8] = {{0, 0, 0},
                        {double(n[0]), 0, 0},
                        {0, double(n[1]), 0},
                        {double(n[0]), double(n[1]), 0},
                        {0, 0, double(n[2])},
                        {double(n[0]), 0, double(n[2])},
                        {0, double(n[1]), double(n[2])},
                        {double(n[0]), double(n[1]), double(n[2])}};
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b) {
      const int diff = a ^ b;
      if (diff != 1 && diff != 2 && diff != 4) continue;
      double xa, ya, xb, yb;
      if (!cam.project(corner[a], size, &xa, &ya) || !cam.project(corner[b], size, &xb, &yb)) continue;
      const int steps = int(std::ceil(std::max(std::abs(xb - xa), std::abs(yb - ya)))) + 1;
      for (int s = 0; s <= steps; ++s) {
        const int x = int(std::lround(xa + (xb - xa) * s / steps)), y = int(std::lround(ya + (yb - ya) * s / steps));
        if (x < 0 || y < 0 || x >= size || y >= size) continue;
        uint8_t* p = &(*rgb)[(size_t(y) * size_t(size) + size_t(x)) * 3];
        for (int k = 0; k < 3; ++k) p[k] = uint8_t(std::lround(0.7 * p[k] + 0.3 * 180.0));
      }
    }
}

}  // namespace morphoflow
