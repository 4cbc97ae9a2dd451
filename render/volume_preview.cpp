#include "render/volume_preview.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/parallel.h"
#include "render/volume_camera.h"

namespace morphoflow {

namespace {

constexpr std::array<double, 3> kBackground{0.06, 0.06, 0.075};

// Ray marching with colourAndOpacity(position) -> {r, g, b, t in [0, 1]}.
template <class Sample>
std::vector<uint8_t> march(const IVec<3>& n, int size, Sample sampleAt) {
  const VolumeCamera cam(n);
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
  drawBoxEdges(cam, n, size, &rgb);
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
    const double t = normalised(sampleCells(f, p), range);
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
    const double r = normalised(sampleCells(red, p), rr), g = normalised(sampleCells(green, p), gr);
    return std::array<double, 4>{r, g, 0.0, std::max(r, g)};
  });
}

}  // namespace morphoflow
