#include "fluid/smoke.h"

#include <algorithm>
#include <cmath>

#include "core/expression.h"
#include "core/parallel.h"

namespace morphoflow {

namespace {

// The neighbour of k one cell along axis a (dir = +-1): wrapped on periodic
// axes, the cell itself past a wall (so differences there are one-sided).
template <int D>
IVec<D> step(IVec<D> k, int a, int dir, const IVec<D>& n, const std::array<bool, D>& periodic) {
  k[a] += dir;
  if (periodic[size_t(a)]) k[a] = (k[a] + n[a]) % n[a];
  k[a] = std::clamp(k[a], 0, n[a] - 1);
  return k;
}

// d g / d x_a at cell k by central differences (one-sided at walls).
template <int D, class G>
double derivative(const G& g, const IVec<D>& k, int a, const IVec<D>& n, const std::array<bool, D>& periodic, double h) {
  const IVec<D> lo = step<D>(k, a, -1, n, periodic), hi = step<D>(k, a, +1, n, periodic);
  const int span = periodic[size_t(a)] ? 2 : hi[a] - lo[a];
  return span == 0 ? 0.0 : (g(hi) - g(lo)) / (span * h);
}

// A cell-centred force added to the faces: each face takes the mean of the
// two cells it separates (the one cell at a wall).
template <int D>
void addToFaces(const std::array<Grid<double, D>, D>& f, double dt, MacVelocity<D>* u) {
  const IVec<D>& n = u->cells();
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    forEachCell<D>(g.dims(), [&](const IVec<D>& k, size_t i) {
      IVec<D> lo = k - unitVector<D>(a), hi = k;
      if (lo[a] < 0) lo = u->periodic()[size_t(a)] ? lo + unitVector<D>(a) * n[a] : hi;
      if (hi[a] >= n[a]) hi = u->periodic()[size_t(a)] ? hi - unitVector<D>(a) * n[a] : lo;
      g[i] += float(dt * 0.5 * (f[size_t(a)](lo) + f[size_t(a)](hi)));
    });
  }
}

// Vorticity confinement, Fedkiw et al. eq. 11: omega = curl u at the cell
// centres, N = grad|omega| / |grad|omega||, f = epsilon h (N x omega).
template <int D>
void addConfinement(double epsilon, std::array<Grid<double, D>, D>* f, const MacVelocity<D>& u) {
  const IVec<D>& n = u.cells();
  const double h = u.h();
  const std::array<bool, D>& per = u.periodic();
  std::array<Grid<double, D>, D> uc;
  for (auto& g : uc) g = Grid<double, D>(n, 0.0);
  forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
    const Vec<D> v = u.atCell(k);
    for (int a = 0; a < D; ++a) uc[size_t(a)][i] = v[a];
  });
  constexpr int W = D == 2 ? 1 : 3;  // components of omega
  std::array<Grid<double, D>, W> w;
  for (auto& g : w) g = Grid<double, D>(n, 0.0);
  Grid<double, D> mag(n, 0.0);
  forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
    auto d = [&](int comp, int axis) {
      return derivative<D>([&](const IVec<D>& c) { return uc[size_t(comp)](c); }, k, axis, n, per, h);
    };
    if constexpr (D == 2) {
      w[0][i] = d(1, 0) - d(0, 1);
      mag[i] = std::abs(w[0][i]);
    } else {
      w[0][i] = d(2, 1) - d(1, 2);
      w[1][i] = d(0, 2) - d(2, 0);
      w[2][i] = d(1, 0) - d(0, 1);
      mag[i] = std::sqrt(w[0][i] * w[0][i] + w[1][i] * w[1][i] + w[2][i] * w[2][i]);
    }
  });
  forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
    double eta[3] = {0, 0, 0}, len2 = 0;
    for (int a = 0; a < D; ++a) {
      eta[a] = derivative<D>([&](const IVec<D>& c) { return mag(c); }, k, a, n, per, h);
      len2 += eta[a] * eta[a];
    }
    if (!(len2 > 1e-300)) return;
    const double inv = 1.0 / std::sqrt(len2), s = epsilon * h;
    const double N[3] = {eta[0] * inv, eta[1] * inv, eta[2] * inv};
    if constexpr (D == 2) {
      (*f)[0][i] += s * N[1] * w[0][i];
      (*f)[1][i] -= s * N[0] * w[0][i];
    } else {
      (*f)[0][i] += s * (N[1] * w[2][i] - N[2] * w[1][i]);
      (*f)[1][i] += s * (N[2] * w[0][i] - N[0] * w[2][i]);
      (*f)[2][i] += s * (N[0] * w[1][i] - N[1] * w[0][i]);
    }
  });
}

}  // namespace

template <int D>
Grid<float, D> sourceCover(const SmokeSource& src, double t, const IVec<D>& cells, double h, const Grid<uint8_t, D>& solid) {
  constexpr int kSub = 4;  // samples per cell and axis
  ObstacleSpec region = src.region;
  for (size_t a = 0; a < src.motion.size(); ++a) region.center[a] = Expression(src.motion[a], {"t"}).evaluate(&t);
  double size[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) size[a] = cells[a] * h;
  // The cells an analytic region can reach (images and sdfs: all of them).
  IVec<D> lo(0), hi = cells - IVec<D>(1);
  const bool round = region.shape == ObstacleShape::Circle || region.shape == ObstacleShape::Sphere;
  if (round || region.shape == ObstacleShape::Box)
    for (int a = 0; a < D; ++a) {
      const double reach = round ? region.radius : region.halfSize[size_t(a)];
      if (region.shape == ObstacleShape::Circle && a == 2) continue;  // a cylinder along z
      lo[a] = std::clamp(int(std::floor((region.center[size_t(a)] - reach) / h)) - 1, 0, cells[a] - 1);
      hi[a] = std::clamp(int(std::floor((region.center[size_t(a)] + reach) / h)) + 1, 0, cells[a] - 1);
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
  for (const SmokeSource& src : sources) cover.push_back(sourceCover<D>(src, 0.0, cells, h, solid));
  return cover;
}

template <int D>
void emitSmoke(const SmokeSettings& s, const std::vector<Grid<float, D>>& coverage, const Grid<uint8_t, D>& solid, double t,
               double dt, Grid<float, D>* density, Grid<float, D>* temperature, MacVelocity<D>* u) {
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
        if (w > 0.0) g[i] = float((1.0 - w) * g[i] + w * v);
      });
    }
  }
}

template <int D>
void applySmokeForces(const SmokeSettings& s, const std::array<double, 3>& up, const Grid<float, D>& density,
                      const Grid<float, D>& temperature, double dt, MacVelocity<D>* u) {
  const bool buoyant = (s.weight != 0.0 || s.heat != 0.0);
  if (!buoyant && s.vorticity == 0.0) return;
  const IVec<D>& n = u->cells();
  std::array<Grid<double, D>, D> f;
  for (auto& g : f) g = Grid<double, D>(n, 0.0);
  if (buoyant)
    parallelFor(density.size(), [&](size_t i) {
      const double b = -s.weight * density[i] + s.heat * (double(temperature[i]) - s.ambient);  // eq. 8
      for (int a = 0; a < D; ++a) f[size_t(a)][i] = b * up[size_t(a)];
    }, 4096);
  if (s.vorticity != 0.0) addConfinement<D>(s.vorticity, &f, *u);
  addToFaces<D>(f, dt, u);
}

template <int D>
void decaySmoke(const SmokeSettings& s, double dt, Grid<float, D>* density, Grid<float, D>* temperature) {
  if (s.dissipation > 0.0) {
    const double k = std::exp(-s.dissipation * dt);
    parallelFor(density->size(), [&](size_t i) { (*density)[i] = float((*density)[i] * k); }, 4096);
  }
  if (s.cooling > 0.0) {
    const double k = std::exp(-s.cooling * dt);
    parallelFor(temperature->size(), [&](size_t i) {
      (*temperature)[i] = float(s.ambient + (double((*temperature)[i]) - s.ambient) * k);
    }, 4096);
  }
}

#define MORPHOFLOW_SMOKE(D)                                                                                          \
  template Grid<float, D> sourceCover<D>(const SmokeSource&, double, const IVec<D>&, double, const Grid<uint8_t, D>&); \
  template std::vector<Grid<float, D>> sourceCoverage<D>(const std::vector<SmokeSource>&, const IVec<D>&, double,   \
                                                         const Grid<uint8_t, D>&);                                  \
  template void emitSmoke<D>(const SmokeSettings&, const std::vector<Grid<float, D>>&, const Grid<uint8_t, D>&,      \
                             double, double,                                                                      \
                             Grid<float, D>*, Grid<float, D>*, MacVelocity<D>*);                                    \
  template void applySmokeForces<D>(const SmokeSettings&, const std::array<double, 3>&, const Grid<float, D>&,       \
                                    const Grid<float, D>&, double, MacVelocity<D>*);                                \
  template void decaySmoke<D>(const SmokeSettings&, double, Grid<float, D>*, Grid<float, D>*);
MORPHOFLOW_SMOKE(2)
MORPHOFLOW_SMOKE(3)
#undef MORPHOFLOW_SMOKE

}  // namespace morphoflow
