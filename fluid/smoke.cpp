#include "fluid/smoke.h"

#include <algorithm>
#include <cmath>

#include "core/expression.h"
#include "core/parallel.h"

namespace morphoflow {

namespace {

// Flat neighbours of cell k along axis a: wrapped on periodic axes, the
// cell itself past a wall (so differences there are one-sided), and the
// distance between them in cells.
template <int D>
struct Neighbours {
  size_t lo, hi;
  int span;
};
template <int D>
Neighbours<D> neighbours(const IVec<D>& k, size_t i, int a, const IVec<D>& n, const std::array<size_t, D>& stride,
                         const std::array<bool, D>& periodic) {
  const size_t s = stride[size_t(a)], last = size_t(n[a] - 1);
  if (periodic[size_t(a)])
    return {k[a] == 0 ? i + last * s : i - s, size_t(k[a]) == last ? i - last * s : i + s, 2};
  const size_t lo = k[a] == 0 ? i : i - s, hi = size_t(k[a]) == last ? i : i + s;
  return {lo, hi, (k[a] == 0 ? 0 : 1) + (size_t(k[a]) == last ? 0 : 1)};
}

// A cell-centred force added to the faces: each face takes the mean of the
// two cells it separates (the one cell at a wall).
template <int D>
void addToFaces(const std::array<Grid<float, D>, D>& f, double dt, MacVelocity<D>* u) {
  const IVec<D>& n = u->cells();
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    const Grid<float, D>& fa = f[size_t(a)];
    const size_t s = fa.stride(a);
    const bool wrap = u->periodic()[size_t(a)];
    const float half = float(0.5 * dt);
    forEachCell<D>(g.dims(), [&](const IVec<D>& k, size_t i) {
      IVec<D> c = k;
      c[a] = std::min(k[a], n[a] - 1);
      const size_t hiCell = fa.index(c);
      size_t lo = k[a] == 0 ? (wrap ? hiCell + size_t(n[a] - 1) * s : hiCell) : hiCell - (k[a] == n[a] ? 0 : s);
      size_t hi = k[a] == n[a] ? (wrap ? hiCell - size_t(n[a] - 1) * s : hiCell) : hiCell;
      g[i] += half * (fa[lo] + fa[hi]);
    });
  }
}

// The work grids of the forces, lent from the fluid's pool for the stage:
// the force at the cells, the centre velocities, omega and |omega|. Every
// sample is written before it is read, so none is cleared.
template <int D>
struct SmokeWork {
  static constexpr int W = D == 2 ? 1 : 3;  // components of omega
  std::array<Grid<float, D>, D> f, uc;
  std::array<Grid<float, D>, W> w;
  Grid<float, D> mag;
  template <class Fn>
  void each(Fn&& fn, bool confinement) {
    for (auto& g : f) fn(g);
    if (!confinement) return;
    for (auto& g : uc) fn(g);
    for (auto& g : w) fn(g);
    fn(mag);
  }
};

// omega = curl u at the cell centres and |omega| (Fedkiw et al. eq. 11's
// first half), from the centre velocities by central differences
// (one-sided at walls).
template <int D>
void vorticity(const MacVelocity<D>& u, SmokeWork<D>* work) {
  const IVec<D>& n = u.cells();
  const double h = u.h();
  const std::array<bool, D>& per = u.periodic();
  std::array<Grid<float, D>, D>& uc = work->uc;
  std::array<size_t, D> st;
  for (int a = 0; a < D; ++a) st[size_t(a)] = uc[0].stride(a);
  forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
    for (int a = 0; a < D; ++a) {
      const Grid<float, D>& g = u[a];
      const size_t j = g.index(k);
      uc[size_t(a)][i] = 0.5f * (g[j] + g[j + g.stride(a)]);
    }
  });
  forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
    Neighbours<D> nb[D];
    for (int a = 0; a < D; ++a) nb[a] = neighbours<D>(k, i, a, n, st, per);
    // d u_comp / d x_axis by central differences (one-sided at walls).
    auto d = [&](int comp, int axis) {
      const Neighbours<D>& q = nb[axis];
      return q.span == 0 ? 0.0 : (double(uc[size_t(comp)][q.hi]) - uc[size_t(comp)][q.lo]) / (q.span * h);
    };
    if constexpr (D == 2) {
      const double o = d(1, 0) - d(0, 1);
      work->w[0][i] = float(o);
      work->mag[i] = float(std::abs(o));
    } else {
      const double o0 = d(2, 1) - d(1, 2), o1 = d(0, 2) - d(2, 0), o2 = d(1, 0) - d(0, 1);
      work->w[0][i] = float(o0), work->w[1][i] = float(o1), work->w[2][i] = float(o2);
      work->mag[i] = float(std::sqrt(o0 * o0 + o1 * o1 + o2 * o2));
    }
  });
}

// The force at the cells in one pass: the buoyancy b up, plus (epsilon != 0)
// the vorticity confinement f = epsilon h (N x omega), N = grad|omega| /
// |grad|omega|| (Fedkiw et al. eq. 11), on the omega of `work`.
template <int D>
void cellForces(const SmokeSettings& s, const std::array<double, 3>& up, bool buoyant, const Grid<float, D>& density,
                const Grid<float, D>& temperature, const MacVelocity<D>& u, SmokeWork<D>* work) {
  const IVec<D>& n = u.cells();
  const double h = u.h();
  const std::array<bool, D>& per = u.periodic();
  std::array<Grid<float, D>, D>& f = work->f;
  const Grid<float, D>& mag = work->mag;
  std::array<size_t, D> st;
  for (int a = 0; a < D; ++a) st[size_t(a)] = f[0].stride(a);
  const double epsilon = s.vorticity;
  const auto& w = work->w;
  forEachCell<D>(n, [&](const IVec<D>& k, size_t i) {
    const double b = buoyant ? smokeBuoyancy(density[i], temperature[i], s.weight, s.heat, s.ambient) : 0.0;
    for (int a = 0; a < D; ++a) f[size_t(a)][i] = float(b * up[size_t(a)]);
    if (epsilon == 0.0) return;
    double eta[3] = {0, 0, 0}, len2 = 0;
    for (int a = 0; a < D; ++a) {
      const Neighbours<D> q = neighbours<D>(k, i, a, n, st, per);
      eta[a] = q.span == 0 ? 0.0 : (double(mag[q.hi]) - mag[q.lo]) / (q.span * h);
      len2 += eta[a] * eta[a];
    }
    if (!(len2 > 1e-300)) return;
    const double inv = 1.0 / std::sqrt(len2), sc = epsilon * h;
    const double N[3] = {eta[0] * inv, eta[1] * inv, eta[2] * inv};
    if constexpr (D == 2) {
      f[0][i] += float(confinementTerm(sc, N[1], w[0][i], 0.0, 0.0));
      f[1][i] += float(confinementTerm(sc, 0.0, 0.0, N[0], w[0][i]));
    } else {
      f[0][i] += float(confinementTerm(sc, N[1], w[2][i], N[2], w[1][i]));
      f[1][i] += float(confinementTerm(sc, N[2], w[0][i], N[0], w[2][i]));
      f[2][i] += float(confinementTerm(sc, N[0], w[1][i], N[1], w[0][i]));
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
        if (w > 0.0) g[i] = float(coverBlend(g[i], w, v));
      });
    }
  }
}

template <int D>
void applySmokeForces(const SmokeSettings& s, const std::array<double, 3>& up, const Grid<float, D>& density,
                      const Grid<float, D>& temperature, double dt, MacVelocity<D>* u, WorkPool* pool) {
  const bool buoyant = (s.weight != 0.0 || s.heat != 0.0);
  const bool confined = s.vorticity != 0.0;
  if (!buoyant && !confined) return;
  SmokeWork<D> work;
  work.each([&](Grid<float, D>& g) {
    pool->lend(&g.values());
    g.reshape(u->cells());
  }, confined);
  if (confined) vorticity<D>(*u, &work);
  cellForces<D>(s, up, buoyant, density, temperature, *u, &work);
  addToFaces<D>(work.f, dt, u);
  work.each([&](Grid<float, D>& g) { pool->give(&g.values()); }, confined);
}

template <int D>
void decaySmoke(const SmokeSettings& s, double dt, Grid<float, D>* density, Grid<float, D>* temperature) {
  if (s.dissipation > 0.0) {
    const double k = std::exp(-s.dissipation * dt);
    parallelFor(density->size(), [&](size_t i) { (*density)[i] = float(decayed((*density)[i], k, 0.0)); }, 4096);
  }
  if (s.cooling > 0.0) {
    const double k = std::exp(-s.cooling * dt);
    parallelFor(temperature->size(), [&](size_t i) { (*temperature)[i] = float(decayed((*temperature)[i], k, s.ambient)); },
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
  template void applySmokeForces<D>(const SmokeSettings&, const std::array<double, 3>&, const Grid<float, D>&,       \
                                    const Grid<float, D>&, double, MacVelocity<D>*, WorkPool*);                     \
  template void decaySmoke<D>(const SmokeSettings&, double, Grid<float, D>*, Grid<float, D>*);
MORPHOFLOW_SMOKE(2)
MORPHOFLOW_SMOKE(3)
#undef MORPHOFLOW_SMOKE

}  // namespace morphoflow
