#include "render/polar_plot.h"

#include <algorithm>
#include <cmath>

namespace morphoflow {

namespace {

struct Canvas {
  int n;
  std::vector<uint8_t> rgb;
  void dot(double x, double y, double radius, const uint8_t c[3]) {  // x, y in pixels, y up
    const int x0 = int(std::floor(x - radius)), x1 = int(std::ceil(x + radius));
    const int y0 = int(std::floor(y - radius)), y1 = int(std::ceil(y + radius));
    for (int py = std::max(0, y0); py <= std::min(n - 1, y1); ++py)
      for (int px = std::max(0, x0); px <= std::min(n - 1, x1); ++px) {
        if (std::hypot(px - x, py - y) > radius) continue;
        uint8_t* p = &rgb[3 * (size_t(n - 1 - py) * size_t(n) + size_t(px))];
        p[0] = c[0], p[1] = c[1], p[2] = c[2];
      }
  }
  void line(double xa, double ya, double xb, double yb, double width, const uint8_t c[3]) {
    const int steps = std::max(1, int(std::ceil(std::hypot(xb - xa, yb - ya) * 2)));
    for (int k = 0; k <= steps; ++k) {
      const double t = double(k) / steps;
      dot(xa + t * (xb - xa), ya + t * (yb - ya), width, c);
    }
  }
};

}  // namespace

std::vector<uint8_t> polarPlotRgb(const std::vector<double>& radius, int size) {
  Canvas cv{size, std::vector<uint8_t>(3 * size_t(size) * size_t(size), 255)};
  const double c = 0.5 * (size - 1), R = 0.45 * size;
  const uint8_t grey[3] = {205, 205, 205}, ink[3] = {33, 72, 160};
  cv.line(c - R, c, c + R, c, 0.6, grey);
  cv.line(c, c - R, c, c + R, 0.6, grey);
  for (int k = 0; k < 720; ++k) {
    const double a = 2 * M_PI * k / 720;
    cv.dot(c + R * std::cos(a), c + R * std::sin(a), 0.6, grey);
  }
  double top = 0;
  for (double r : radius) top = std::max(top, r);
  if (!(top > 0) || radius.empty()) return cv.rgb;
  const size_t n = radius.size();
  auto at = [&](size_t k) {
    const double a = 2 * M_PI * double(k % n) / double(n), r = R * std::max(0.0, radius[k % n]) / top;
    return std::pair<double, double>(c + r * std::cos(a), c + r * std::sin(a));
  };
  for (size_t k = 0; k < n; ++k) {
    const auto [xa, ya] = at(k);
    const auto [xb, yb] = at(k + 1);
    cv.line(xa, ya, xb, yb, std::max(1.0, size / 300.0), ink);
  }
  return cv.rgb;
}

}  // namespace morphoflow
