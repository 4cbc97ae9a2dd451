#include "render/volume_preview.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/parallel.h"

namespace morphoflow {

namespace {

using V3 = std::array<double, 3>;

V3 add(V3 a, V3 b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 scale(V3 a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(V3 a, V3 b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
V3 unit(V3 a) { return scale(a, 1.0 / std::sqrt(dot(a, a))); }

// The fixed camera: 40 degrees round the vertical (y) axis from +z towards
// +x, 25 degrees above the horizontal, a 30 degree field of view that holds
// the box's bounding sphere. Units are cells.
struct Camera {
  V3 eye, forward, right, up;
  double tanHalf;
  explicit Camera(const IVec<3>& n) {
    const V3 centre{0.5 * n[0], 0.5 * n[1], 0.5 * n[2]};
    const double radius = 0.5 * std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    const double az = 40.0 * M_PI / 180.0, el = 25.0 * M_PI / 180.0, halfFov = 15.0 * M_PI / 180.0;
    const V3 towardEye{std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
    eye = add(centre, scale(towardEye, 1.02 * radius / std::sin(halfFov)));
    forward = scale(towardEye, -1.0);
    right = unit(cross(forward, V3{0, 1, 0}));
    up = cross(right, forward);
    tanHalf = std::tan(halfFov);
  }
  // The ray through pixel (px, py) of a size x size image.
  V3 ray(int px, int py, int size) const {
    const double u = (2.0 * (px + 0.5) / size - 1.0) * tanHalf, v = (1.0 - 2.0 * (py + 0.5) / size) * tanHalf;
    return unit(add(forward, add(scale(right, u), scale(up, v))));
  }
  // Where a point lands in the image (pixels), and whether it is in front.
  bool project(V3 p, int size, double* x, double* y) const {
    const V3 d = add(p, scale(eye, -1.0));
    const double z = dot(d, forward);
    if (z <= 0) return false;
    *x = (dot(d, right) / (z * tanHalf) + 1.0) * 0.5 * size - 0.5;
    *y = (1.0 - dot(d, up) / (z * tanHalf)) * 0.5 * size - 0.5;
    return true;
  }
};

// Trilinear interpolation between cell centres (cell i's centre at i + 1/2).
float sample(const Grid<float, 3>& f, const V3& p) {
  int i0[3];
  double w[3];
  for (int a = 0; a < 3; ++a) {
    const double x = std::clamp(p[size_t(a)] - 0.5, 0.0, double(f.dim(a) - 1));
    i0[a] = std::min(int(x), f.dim(a) - 2 < 0 ? 0 : f.dim(a) - 2);
    w[a] = f.dim(a) > 1 ? x - i0[a] : 0.0;
  }
  double v = 0;
  for (int c = 0; c < 8; ++c) {
    IVec<3> k;
    double wt = 1;
    for (int a = 0; a < 3; ++a) {
      const int bit = (c >> a) & 1;
      k[a] = std::min(i0[a] + bit, f.dim(a) - 1);
      wt *= bit ? w[a] : 1.0 - w[a];
    }
    if (wt != 0) v += wt * f(k);
  }
  return float(v);
}

// Entry and exit of the ray through the box [0, n].
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

constexpr std::array<double, 3> kBackground{0.06, 0.06, 0.075};

// Ray marching with colourAndOpacity(position) -> {r, g, b, t in [0, 1]}.
template <class Sample>
std::vector<uint8_t> march(const IVec<3>& n, int size, Sample sampleAt) {
  const Camera cam(n);
  const double radius = 0.5 * std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
  // Optical depth 6 across the bounding sphere at the top of the range.
  const double kappa = 3.0 / radius, ds = 0.5;
  std::vector<uint8_t> rgb(size_t(size) * size_t(size) * 3);
  parallelFor(size_t(size), [&](size_t py) {
    for (int px = 0; px < size; ++px) {
      const V3 d = cam.ray(px, int(py), size);
      double c[3] = {0, 0, 0}, T = 1.0, t0, t1;
      if (clipToBox(cam.eye, d, n, &t0, &t1)) {
        for (double t = t0 + 0.5 * ds; t < t1 && T > 0.004; t += ds) {
          const std::array<double, 4> s = sampleAt(add(cam.eye, scale(d, t)));
          const double a = 1.0 - std::exp(-kappa * s[3] * ds);
          for (int k = 0; k < 3; ++k) c[k] += T * a * s[size_t(k)];
          T *= 1.0 - a;
        }
      }
      uint8_t* out = &rgb[(py * size_t(size) + size_t(px)) * 3];
      for (int k = 0; k < 3; ++k)
        out[k] = uint8_t(std::lround(255.0 * std::clamp(c[k] + T * kBackground[size_t(k)], 0.0, 1.0)));
    }
  });
  // The box's twelve edges, faintly over the picture.
  const V3 corner[8] = {{0, 0, 0}, {double(n[0]), 0, 0}, {0, double(n[1]), 0}, {double(n[0]), double(n[1]), 0},
                        {0, 0, double(n[2])}, {double(n[0]), 0, double(n[2])}, {0, double(n[1]), double(n[2])},
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
        uint8_t* p = &rgb[(size_t(y) * size_t(size) + size_t(x)) * 3];
        for (int k = 0; k < 3; ++k) p[k] = uint8_t(std::lround(0.7 * p[k] + 0.3 * 180.0));
      }
    }
  return rgb;
}

double normalised(float v, const std::array<double, 2>& r) {
  const double t = (double(v) - r[0]) / (r[1] - r[0]);
  return std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
}

}  // namespace

std::vector<uint8_t> volumeToRgb(const Grid<float, 3>& f, const FieldImageOptions& o, int size, int* width,
                                 int* height) {
  const std::array<double, 2> range = valueRange(f.data(), f.size(), o);
  *width = *height = size;
  return march(f.dims(), size, [&](const V3& p) {
    const double t = normalised(sample(f, p), range);
    const Rgb8 c = o.palette(t);
    // A signed field (symmetric range) is opaque by its distance from 0.
    const double opacity = o.symmetric ? std::abs(2.0 * t - 1.0) : t;
    return std::array<double, 4>{c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, opacity};
  });
}

std::vector<uint8_t> volumeTwoToRgb(const Grid<float, 3>& red, const Grid<float, 3>& green,
                                    const FieldImageOptions& o, int size, int* width, int* height) {
  const std::array<double, 2> rr = valueRange(red.data(), red.size(), o),
                              gr = valueRange(green.data(), green.size(), o);
  *width = *height = size;
  return march(red.dims(), size, [&](const V3& p) {
    const double r = normalised(sample(red, p), rr), g = normalised(sample(green, p), gr);
    return std::array<double, 4>{r, g, 0.0, std::max(r, g)};
  });
}

}  // namespace morphoflow
