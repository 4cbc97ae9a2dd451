// The smoke's forces (fluid/smoke.h): buoyancy (Fedkiw, Stam & Jensen 2001
// eq. 8) and vorticity confinement (eq. 11), as three passes over rows:
//   1. omega = curl u and |omega| at the cell centres, from the faces;
//   2. f = b up + epsilon h (N x omega) at the cell centres;
//   3. each face takes the mean of its two cells' f.
// Each pass has an interior loop (every neighbour a plain offset) that the
// compiler vectorises, with an eight-lane AVX2 variant (core/simd_dispatch.h):
// the lanes do the scalar arithmetic in its order, so every variant gives
// bitwise the same velocity.
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"
#include "core/simd_dispatch.h"
#include "fluid/smoke.h"

namespace morphoflow {

namespace {

// The neighbours of coordinate k along an axis of n cells: wrapped on a
// periodic axis, k itself past a wall (one-sided differences there); den is
// the distance a central difference divides by, span h (1 where the span is
// 0: then lo = hi and the difference is 0).
struct Across {
  int lo, hi;
  double den;
};
inline Across across(int k, int n, bool periodic, double h) {
  if (periodic) return {k == 0 ? n - 1 : k - 1, k == n - 1 ? 0 : k + 1, 2 * h};
  const int span = (k == 0 ? 0 : 1) + (k == n - 1 ? 0 : 1);
  return {k == 0 ? k : k - 1, k == n - 1 ? k : k + 1, span == 0 ? 1.0 : span * h};
}

// The first sample of the row through coordinates c (c[0] ignored) of a
// grid of dims `dims`.
template <int D>
size_t rowStart(const IVec<D>& dims, IVec<D> c) {
  c[0] = 0;
  return latticeIndex<D>(dims, c);
}

// The rows a cell pass reads around one row: slot 0 the row itself, slots
// 2b - 1 and 2b its low and high neighbours along axis b >= 1.
template <int D>
struct RowSlots {
  static constexpr int S = 2 * D - 1;
  size_t at[S];
  double den[D];  // den[b], b >= 1: the difference's divisor along b
  RowSlots(const IVec<D>& dims, const IVec<D>& n, const IVec<D>& k, const std::array<bool, D>& periodic, double h) {
    at[0] = rowStart<D>(dims, k);
    for (int b = 1; b < D; ++b) {
      const Across q = across(k[b], n[b], periodic[size_t(b)], h);
      IVec<D> c = k;
      c[b] = q.lo;
      at[2 * b - 1] = rowStart<D>(dims, c);
      c[b] = q.hi;
      at[2 * b] = rowStart<D>(dims, c);
      den[b] = q.den;
    }
  }
};

// Pass 1 on one row: the centre velocities from the faces (the mean of a
// cell's two faces), their central differences, omega and |omega|.
template <int D>
struct CurlRow {
  static constexpr int S = 2 * D - 1, W = D == 2 ? 1 : 3;
  const float* u[D][S];  // component c's face grid, at the row of slot s
  size_t up[D];          // a cell's upper face along c, from its lower one
  double den[D];
  float *w[W], *mag;
};

MF_INLINE float centre(const float* p, size_t up, int x) { return faceMean(p[x], p[size_t(x) + up]); }

template <int D>
MF_INLINE void curlCell(const CurlRow<D>& r, int x, int xl, int xh, double denx) {
  // d u_c / d x_axis by central differences (one-sided at walls)
  auto d = [&](int c, int axis) {
    if (axis == 0) return smokeDifference(centre(r.u[c][0], r.up[c], xl), centre(r.u[c][0], r.up[c], xh), denx);
    return smokeDifference(centre(r.u[c][2 * axis - 1], r.up[c], x), centre(r.u[c][2 * axis], r.up[c], x), r.den[axis]);
  };
  if constexpr (D == 2) {
    const double o = d(1, 0) - d(0, 1);
    r.w[0][x] = float(o);
    r.mag[x] = float(std::abs(o));
  } else {
    const double o0 = d(2, 1) - d(1, 2), o1 = d(0, 2) - d(2, 0), o2 = d(1, 0) - d(0, 1);
    r.w[0][x] = float(o0), r.w[1][x] = float(o1), r.w[2][x] = float(o2);
    r.mag[x] = float(vectorLength(o0, o1, o2));
  }
}

// c ? a : b by masks: the compiler keeps it a blend (no branch), which
// the loops need to vectorise.
MF_INLINE float pick(bool c, float a, float b) {
  const uint32_t m = 0u - uint32_t(c);
  return std::bit_cast<float>((std::bit_cast<uint32_t>(a) & m) | (std::bit_cast<uint32_t>(b) & ~m));
}

// Pass 2 on one row: the buoyancy b up (Buoyant), plus (Confine) epsilon h (N x omega)
// with N = grad|omega| / |grad|omega||, where |grad|omega|| is not 0.
template <int D>
struct ForceRow {
  static constexpr int S = 2 * D - 1, W = D == 2 ? 1 : 3;
  const float *rho, *t;
  const float* mag[S];
  const float* w[W];
  float* f[D];
  double den[D];
  double up[3], alpha, beta, ambient, sc;
};

template <int D, bool Buoyant, bool Confine>
MF_INLINE void forceCell(const ForceRow<D>& r, int x, int xl, int xh, double denx) {
  const double b = Buoyant ? smokeBuoyancy(r.rho[x], r.t[x], r.alpha, r.beta, r.ambient) : 0.0;
  float f[D];
  for (int a = 0; a < D; ++a) f[a] = float(b * r.up[a]);
  if constexpr (Confine) {
    double eta[3] = {0, 0, 0}, len2 = 0;
    eta[0] = smokeDifference(r.mag[0][xl], r.mag[0][xh], denx);
    for (int a = 1; a < D; ++a) eta[a] = smokeDifference(r.mag[2 * a - 1][x], r.mag[2 * a][x], r.den[a]);
    for (int a = 0; a < D; ++a) len2 += eta[a] * eta[a];
    const double inv = inverseLength(len2);
    const double N[3] = {eta[0] * inv, eta[1] * inv, eta[2] * inv};
    float g[D];
    if constexpr (D == 2) {
      const float w = r.w[0][x];
      g[0] = f[0] + float(confinementTerm(r.sc, N[1], w, 0.0, 0.0));
      g[1] = f[1] + float(confinementTerm(r.sc, 0.0, 0.0, N[0], w));
    } else {
      const float w0 = r.w[0][x], w1 = r.w[1][x], w2 = r.w[2][x];
      g[0] = f[0] + float(confinementTerm(r.sc, N[1], w2, N[2], w1));
      g[1] = f[1] + float(confinementTerm(r.sc, N[2], w0, N[0], w2));
      g[2] = f[2] + float(confinementTerm(r.sc, N[0], w1, N[1], w0));
    }
    const bool some = len2 > 1e-300;  // else N is undefined and f is the buoyancy
    for (int a = 0; a < D; ++a) f[a] = pick(some, g[a], f[a]);
  }
  for (int a = 0; a < D; ++a) r.f[a][x] = f[a];
}

// A pass's row: its cells x = 0 and n - 1 through the general neighbours,
// those between through the interior loop (vectorised; AVX2 when the CPU
// has it).
template <class Row, void (*Cell)(const Row&, int, int, int, double)>
struct RowPass {
  static void interior(const Row& r, int nx, double den) {
#pragma GCC ivdep
    for (int x = 1; x < nx - 1; ++x) Cell(r, x, x - 1, x + 1, den);
  }
#if MORPHOFLOW_AVX2_KERNELS
  __attribute__((target("avx2"))) static void interiorAvx2(const Row& r, int nx, double den) {
#pragma GCC ivdep
    for (int x = 1; x < nx - 1; ++x) Cell(r, x, x - 1, x + 1, den);
  }
#endif
  static void run(const Row& r, int nx, bool periodic, double h, bool wide) {
    const double den = 2 * h;  // the interior's span
#if MORPHOFLOW_AVX2_KERNELS
    if (wide)
      interiorAvx2(r, nx, den);
    else
#endif
      interior(r, nx, den);
    for (int x : {0, nx - 1}) {
      const Across q = across(x, nx, periodic, h);
      Cell(r, x, q.lo, q.hi, q.den);
      if (nx == 1) break;
    }
  }
};

// The work grids of the forces, lent from the fluid's pool for the stage:
// the force at the cells, omega and |omega|. Every sample is written before
// it is read, so none is cleared.
template <int D>
struct SmokeWork {
  static constexpr int W = D == 2 ? 1 : 3;  // components of omega
  std::array<Grid<float, D>, D> f;
  std::array<Grid<float, D>, W> w;
  Grid<float, D> mag;
  template <class Fn>
  void each(Fn&& fn, bool confinement) {
    for (auto& g : f) fn(g);
    if (!confinement) return;
    for (auto& g : w) fn(g);
    fn(mag);
  }
};

// omega = curl u at the cell centres and |omega| (Fedkiw et al. eq. 11's
// first half), from the centre velocities by central differences.
template <int D>
void vorticity(const MacVelocity<D>& u, SmokeWork<D>* work, bool wide) {
  const IVec<D>& n = u.cells();
  const double h = u.h();
  forEachRow<D>(n, [&](size_t row, const IVec<D>& k) {
    CurlRow<D> r;
    for (int c = 0; c < D; ++c) {
      const RowSlots<D> s(u[c].dims(), n, k, u.periodic(), h);
      for (int q = 0; q < RowSlots<D>::S; ++q) r.u[c][q] = u[c].values().data() + s.at[q];
      for (int b = 1; b < D; ++b) r.den[b] = s.den[b];
      r.up[c] = u[c].stride(c);
    }
    const size_t base = row * size_t(n[0]);
    for (int q = 0; q < CurlRow<D>::W; ++q) r.w[q] = work->w[size_t(q)].values().data() + base;
    r.mag = work->mag.values().data() + base;
    RowPass<CurlRow<D>, curlCell<D>>::run(r, n[0], u.periodic()[0], h, wide);
  });
}

// The force at the cells in one pass: the buoyancy b up, plus (epsilon != 0)
// the vorticity confinement on the omega of `work`.
template <int D>
void cellForces(const SmokeSettings& s, const std::array<double, 3>& up, bool buoyant, const Grid<float, D>& density,
                const Grid<float, D>& temperature, const MacVelocity<D>& u, SmokeWork<D>* work, bool wide) {
  const IVec<D>& n = u.cells();
  const double h = u.h();
  forEachRow<D>(n, [&](size_t row, const IVec<D>& k) {
    ForceRow<D> r;
    const size_t base = row * size_t(n[0]);
    r.rho = density.values().data() + base;
    r.t = temperature.values().data() + base;
    for (int a = 0; a < D; ++a) r.f[a] = work->f[size_t(a)].values().data() + base;
    const bool confine = s.vorticity != 0.0;
    if (confine) {
      const RowSlots<D> sl(n, n, k, u.periodic(), h);
      for (int q = 0; q < RowSlots<D>::S; ++q) r.mag[q] = work->mag.values().data() + sl.at[q];
      for (int b = 1; b < D; ++b) r.den[b] = sl.den[b];
      for (int q = 0; q < ForceRow<D>::W; ++q) r.w[q] = work->w[size_t(q)].values().data() + base;
    }
    for (int a = 0; a < 3; ++a) r.up[a] = up[size_t(a)];
    r.alpha = s.weight, r.beta = s.heat, r.ambient = s.ambient, r.sc = s.vorticity * h;
    const bool per = u.periodic()[0];
    if (buoyant && confine)
      RowPass<ForceRow<D>, forceCell<D, true, true>>::run(r, n[0], per, h, wide);
    else if (buoyant)
      RowPass<ForceRow<D>, forceCell<D, true, false>>::run(r, n[0], per, h, wide);
    else
      RowPass<ForceRow<D>, forceCell<D, false, true>>::run(r, n[0], per, h, wide);
  });
}

// A cell-centred force added to the faces: each face takes the mean of the
// two cells it separates (the one cell at a wall), u += dt f.
template <int D>
void addToFaces(const std::array<Grid<float, D>, D>& f, double dt, MacVelocity<D>* u) {
  const IVec<D>& n = u->cells();
  const float half = float(0.5 * dt);
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& g = (*u)[a];
    const float* fa = f[size_t(a)].values().data();
    const bool wrap = u->periodic()[size_t(a)];
    // The cells below and above face k along a (k = 0 .. n).
    auto below = [&](int k) { return k == 0 ? (wrap ? n[a] - 1 : 0) : k - 1; };
    auto above = [&](int k) { return k == n[a] ? (wrap ? 0 : n[a] - 1) : k; };
    forEachRow<D>(g.dims(), [&](size_t row, const IVec<D>& k) {
      float* out = g.values().data() + row * size_t(g.dims()[0]);
      if (a == 0) {
        const float* c = fa + rowStart<D>(n, k);
        for (int x = 1; x < n[0]; ++x) out[x] += faceForce(half, c[x - 1], c[x]);
        out[0] += faceForce(half, c[below(0)], c[0]);
        out[n[0]] += faceForce(half, c[n[0] - 1], c[above(n[0])]);
        return;
      }
      IVec<D> lo = k, hi = k;
      lo[a] = below(k[a]), hi[a] = above(k[a]);
      const float *cl = fa + rowStart<D>(n, lo), *ch = fa + rowStart<D>(n, hi);
      for (int x = 0; x < n[0]; ++x) out[x] += faceForce(half, cl[x], ch[x]);
    });
  }
}

}  // namespace

template <int D>
void applySmokeForces(const SmokeSettings& s, const std::array<double, 3>& up, const Grid<float, D>& density,
                      const Grid<float, D>& temperature, double dt, MacVelocity<D>* u, WorkPool* pool) {
  const bool buoyant = (s.weight != 0.0 || s.heat != 0.0);
  const bool confined = s.vorticity != 0.0;
  if (!buoyant && !confined) return;
  const bool wide = useAvx2();
  SmokeWork<D> work;
  work.each([&](Grid<float, D>& g) {
    pool->lend(&g.values());
    g.reshape(u->cells());
  }, confined);
  if (confined) vorticity<D>(*u, &work, wide);
  cellForces<D>(s, up, buoyant, density, temperature, *u, &work, wide);
  addToFaces<D>(work.f, dt, u);
  work.each([&](Grid<float, D>& g) { pool->give(&g.values()); }, confined);
}

template void applySmokeForces<2>(const SmokeSettings&, const std::array<double, 3>&, const Grid<float, 2>&,
                                  const Grid<float, 2>&, double, MacVelocity<2>*, WorkPool*);
template void applySmokeForces<3>(const SmokeSettings&, const std::array<double, 3>&, const Grid<float, 3>&,
                                  const Grid<float, 3>&, double, MacVelocity<3>*, WorkPool*);

}  // namespace morphoflow
