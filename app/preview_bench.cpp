#include "app/preview_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/parallel.h"
#include "render/lit_volume.h"
#include "render/volume_preview.h"

namespace morphoflow {

namespace {

// A column of smoke up the box's middle, its radius a sixth of the width,
// cut by the gyroid sin x cos y + sin y cos z + sin z cos x > 0 of period a
// twelfth of the width: a labyrinth on the element's surface.
Grid<float, 3> element(int n) {
  Grid<float, 3> g(IVec<3>{n, n, n}, 0.0f);
  const double k = 2 * M_PI * 12.0 / n;
  forEachCell<3>(g.dims(), [&](const IVec<3>& c, size_t i) {
    const double x = c[0] + 0.5 - 0.5 * n, z = c[2] + 0.5 - 0.5 * n;
    const double r = std::sqrt(x * x + z * z), smoke = std::clamp(n / 6.0 - r, 0.0, 1.0);
    const double gy = std::sin(k * c[0]) * std::cos(k * c[1]) + std::sin(k * c[1]) * std::cos(k * c[2]) +
                      std::sin(k * c[2]) * std::cos(k * c[0]);
    g[i] = float(smoke * std::clamp(2.0 * gy, 0.0, 1.0));
  });
  return g;
}

template <class Fn>
double seconds(Fn&& fn) {
  const auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

bool runPreviewBench(const BenchOptions& o) {
  const std::vector<int> sizes = o.size > 0 ? std::vector<int>{o.size} : std::vector<int>{128, 256};
  nlohmann::json all = nlohmann::json::array();
  fmt::print("preview: {} thread(s); one 512 x 512 frame of a synthetic element (medians of interleaved runs)\n",
             hardwareThreads());
  fmt::print("{:>6} {:>12} {:>22} {:>12}\n", "size", "lit ms", "emission-absorption ms", "lit/voxel ns");
  for (const int n : sizes) {
    const Grid<float, 3> rho = element(n);
    LitVolume v;
    v.density = &rho;
    v.shown = &rho;
    v.options.palette = namedPalette("magma");
    std::vector<double> lit, plain;
    int w = 0, h = 0;
    for (int round = 0; round < 3 || (round < 20 && median(lit) * round < o.minSeconds); ++round) {
      lit.push_back(seconds([&] { renderLitVolume(v, 512); }));
      plain.push_back(seconds([&] { volumeToRgb(rho, v.options, 512, &w, &h); }));
    }
    const double l = median(lit), p = median(plain);
    fmt::print("{:>6} {:>12.0f} {:>22.0f} {:>12.1f}\n", n, 1e3 * l, 1e3 * p, 1e9 * l / double(rho.size()));
    all.push_back({{"size", n}, {"lit_seconds", l}, {"emission_absorption_seconds", p}, {"rounds", lit.size()}});
  }
  if (!o.json.empty()) std::ofstream(o.json) << nlohmann::json{{"preview", all}}.dump(2) << "\n";
  return true;
}

}  // namespace morphoflow
