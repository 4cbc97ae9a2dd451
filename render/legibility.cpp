#include "render/legibility.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace morphoflow {

namespace {

using Rgb8 = std::array<uint8_t, 3>;

Rgb8 pixel(const std::vector<uint8_t>& rgb, size_t i) { return {rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]}; }

// The commonest colour of the border pixels (the smallest colour on a tie).
Rgb8 background(const std::vector<uint8_t>& rgb, int w, int h) {
  std::map<Rgb8, size_t> count;
  for (int x = 0; x < w; ++x) {
    ++count[pixel(rgb, size_t(x))];
    ++count[pixel(rgb, size_t(h - 1) * size_t(w) + size_t(x))];
  }
  for (int y = 1; y + 1 < h; ++y) {
    ++count[pixel(rgb, size_t(y) * size_t(w))];
    ++count[pixel(rgb, size_t(y) * size_t(w) + size_t(w - 1))];
  }
  return std::max_element(count.begin(), count.end(), [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

// A (2r + 1)^2 box mean, edges clamped, as two 1D passes.
std::vector<double> boxBlur(const std::vector<double>& v, int w, int h, int r) {
  std::vector<double> rows(v.size()), out(v.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0;
      for (int d = -r; d <= r; ++d) s += v[size_t(y) * size_t(w) + size_t(std::clamp(x + d, 0, w - 1))];
      rows[size_t(y) * size_t(w) + size_t(x)] = s / (2 * r + 1);
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0;
      for (int d = -r; d <= r; ++d) s += rows[size_t(std::clamp(y + d, 0, h - 1)) * size_t(w) + size_t(x)];
      out[size_t(y) * size_t(w) + size_t(x)] = s / (2 * r + 1);
    }
  return out;
}

}  // namespace

Legibility measureLegibility(const std::vector<uint8_t>& rgb, int w, int h) {
  const size_t n = size_t(w) * size_t(h);
  const Rgb8 bg = background(rgb, w, h);
  std::vector<double> lum(n);
  std::vector<size_t> plume;
  for (size_t i = 0; i < n; ++i) {
    const Rgb8 c = pixel(rgb, i);
    lum[i] = (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) / 255.0;
    bool differs = false;
    for (int k = 0; k < 3; ++k) differs = differs || std::abs(int(c[size_t(k)]) - int(bg[size_t(k)])) > kPlumeStep;
    if (differs) plume.push_back(i);
  }
  Legibility m;
  m.plumePixels = plume.size();
  m.plumeFraction = n ? double(plume.size()) / double(n) : 0.0;
  if (plume.empty()) return m;
  std::vector<double> seen;
  for (size_t i : plume) seen.push_back(lum[i]);
  std::sort(seen.begin(), seen.end());
  const size_t half = seen.size() / 2;
  m.medianLuminance = seen.size() % 2 ? seen[half] : 0.5 * (seen[half - 1] + seen[half]);
  const std::vector<double> fine = boxBlur(lum, w, h, 1), coarse = boxBlur(lum, w, h, 6);
  double mean = 0, bandMean = 0;
  for (size_t i : plume) {
    mean += lum[i];
    bandMean += fine[i] - coarse[i];
  }
  mean /= double(plume.size());
  bandMean /= double(plume.size());
  double var = 0;
  for (size_t i : plume) var += (fine[i] - coarse[i] - bandMean) * (fine[i] - coarse[i] - bandMean);
  m.bandContrast = mean > 0 ? std::sqrt(var / double(plume.size())) / mean : 0.0;
  return m;
}

}  // namespace morphoflow
