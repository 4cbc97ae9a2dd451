// The smoke's sources and decay (fluid/smoke.h); its forces are in
// fluid/smoke_forces.cpp.
#include "fluid/smoke.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.h"
#include "core/expression.h"
#include "core/parallel.h"

namespace morphoflow {

template <int D>
Grid<float, D> sourceCover(const SmokeSource& src, double t, const IVec<D>& cells, double h,
                           const Grid<uint8_t, D>& solid) {
  constexpr int kSub = 4;  // samples per cell and axis
  ObstacleSpec region = src.region;
  for (size_t a = 0; a < src.motion.size(); ++a) {
    region.center[a] = Expression(src.motion[a], {"t"}).evaluate(&t);
    if (!std::isfinite(region.center[a]))
      throw NonFiniteError(fmt::format("a source's motion \"{}\" gives the centre {} at t = {:g}", src.motion[a],
                                       std::isnan(region.center[a]) ? "NaN" : fmt::format("{:g}", region.center[a]), t),
                           "give sources.N.motion expressions finite over the source's window (start to end)");
  }
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = cells[a] * h;
  // The cells an analytic region can reach (images and sdfs: all of them).
  IVec<D> lo(0), hi = cells - IVec<D>(1);
  const bool round = region.shape == ObstacleShape::Circle || region.shape == ObstacleShape::Sphere;
  if (round || region.shape == ObstacleShape::Box)
    for (int a = 0; a < D; ++a) {
      const double reach = round ? region.radius : region.halfSize[size_t(a)];
      if (region.shape == ObstacleShape::Circle && a == 2) continue;  // a cylinder along z
      // Clamped as doubles: a centre far outside is no int.
      auto cell = [&](double x) { return int(std::clamp(std::floor(x / h), -1.0, double(cells[a]))); };
      lo[a] = std::clamp(cell(region.center[size_t(a)] - reach) - 1, 0, cells[a] - 1);
      hi[a] = std::clamp(cell(region.center[size_t(a)] + reach) + 1, 0, cells[a] - 1);
    }
  Grid<float, D> c(cells, 0.0f);
  int total = 1;
  for (int a = 0; a < D; ++a) total *= kSub;
  forEachCell<D>(cells, [&](const IVec<D>& k, size_t i) {
    for (int a = 0; a < D; ++a)
      if (k[a] < lo[a] || k[a] > hi[a]) return;
    if (solid[i]) return;
    int inside = 0;
    for (int s = 0; s < total; ++s) {
      double x[3] = {0, 0, 0};
      for (int a = 0, r = s; a < D; ++a, r /= kSub) x[a] = (k[a] + (r % kSub + 0.5) / kSub) * h;
      if (obstacleDistance(region, x, D, size) < 0) ++inside;
    }
    c[i] = float(double(inside) / total);
  });
  return c;
}

template <int D>
std::vector<Grid<float, D>> sourceCoverage(const std::vector<SmokeSource>& sources, const IVec<D>& cells, double h,
                                           const Grid<uint8_t, D>& solid) {
  std::vector<Grid<float, D>> cover;
  // A moving source's cover is computed each step it emits (emitSmoke).
  for (const SmokeSource& src : sources)
    cover.push_back(src.motion.empty() ? sourceCover<D>(src, 0.0, cells, h, solid) : Grid<float, D>(cells, 0.0f));
  return cover;
}

template <int D>
void emitSmoke(const SmokeSettings& s, const std::vector<Grid<float, D>>& coverage, const Grid<uint8_t, D>& solid,
               double t, double dt, Grid<float, D>* density, Grid<float, D>* temperature, MacVelocity<D>* u) {
  for (size_t q = 0; q < s.sources.size(); ++q) {
    const SmokeSource& src = s.sources[q];
    const double on = std::min(t + dt, src.end) - std::max(t, src.start);  // the step's time inside the window
    if (!(on > 0.0)) continue;
    const Grid<float, D> moved =
        src.motion.empty() ? Grid<float, D>() : sourceCover<D>(src, t + 0.5 * dt, density->dims(), u->h(), solid);
    const Grid<float, D>& c = src.motion.empty() ? coverage[q] : moved;
    const double dRho = src.density * on, dT = src.temperature * on;
    parallelFor(c.size(), [&](size_t i) {
      if (c[i] == 0.0f) return;
      if (dRho != 0.0) (*density)[i] = float((*density)[i] + dRho * c[i]);
      if (dT != 0.0) (*temperature)[i] = float((*temperature)[i] + dT * c[i]);
    }, 4096);
    if (!src.inject) continue;
    const IVec<D>& n = u->cells();
    for (int a = 0; a < D; ++a) {
      Grid<float, D>& g = (*u)[a];
      const double v = src.velocity[size_t(a)];
      forEachCell<D>(g.dims(), [&](const IVec<D>& k, size_t i) {
        IVec<D> lo = k - unitVector<D>(a), hi = k;
        const double cl = lo[a] >= 0 ? c(lo) : 0.0, ch = hi[a] < n[a] ? c(hi) : 0.0;
        const double w = 0.5 * (cl + ch);
        if (w > 0.0) g[i] = float(coverBlend(g[i], w, v));
      });
    }
  }
}

template <int D>
void decaySmoke(const SmokeSettings& s, double dt, Grid<float, D>* density, Grid<float, D>* temperature) {
  if (s.dissipation > 0.0) {
    const double k = std::exp(-s.dissipation * dt);
    parallelFor(density->size(), [&](size_t i) { (*density)[i] = float(decayed((*density)[i], k, 0.0)); }, 4096);
  }
  if (s.cooling > 0.0) {
    const double k = std::exp(-s.cooling * dt);
    parallelFor(
        temperature->size(), [&](size_t i) { (*temperature)[i] = float(decayed((*temperature)[i], k, s.ambient)); },
        4096);
  }
}

#define MORPHOFLOW_SMOKE(D)                                                                                          \
  template Grid<float, D> sourceCover<D>(const SmokeSource&, double, const IVec<D>&, double, const Grid<uint8_t, D>&); \
  template std::vector<Grid<float, D>> sourceCoverage<D>(const std::vector<SmokeSource>&, const IVec<D>&, double,   \
                                                         const Grid<uint8_t, D>&);                                  \
  template void emitSmoke<D>(const SmokeSettings&, const std::vector<Grid<float, D>>&, const Grid<uint8_t, D>&,      \
                             double, double,                                                                      \
                             Grid<float, D>*, Grid<float, D>*, MacVelocity<D>*);                                    \
  template void decaySmoke<D>(const SmokeSettings&, double, Grid<float, D>*, Grid<float, D>*);
MORPHOFLOW_SMOKE(2)
MORPHOFLOW_SMOKE(3)
#undef MORPHOFLOW_SMOKE

}  // namespace morphoflow
