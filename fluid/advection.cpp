#include "fluid/advection.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <optional>
#include <cmath>
#include <cstring>

#include "core/linear_sampler.h"
#include "core/multilinear.h"
#include "core/parallel.h"
#include "core/simd4.h"
#include "core/simd_dispatch.h"

namespace morphoflow {

namespace {

// Four samples at once (core/simd4.h), or eight in the AVX2 variant and
// sixteen in the AVX-512 one (core/simd_dispatch.h): the helpers below take
// the vector type V (vf4, vf8 or vf16) and are always inlined, so inside a
// wide row kernel they compile for its target too. Used where every axis
// clamps (walls, inflow, outflow); periodic domains take the scalar path.
// The arithmetic is the scalar path's, operation for operation, so every
// path gives bitwise the same fields.
// vf8 by value is a different psABI with and without AVX; these helpers are
// internal and always inlined, so no call ever passes one.
#pragma GCC diagnostic ignored "-Wpsabi"

template <class V>
struct Lanes;
template <>
struct Lanes<vf4> {
  using I = vi4;
  static constexpr int n = 4;
};
template <>
struct Lanes<vf8> {
  using I = vi8;
  static constexpr int n = 8;
};
template <>
struct Lanes<vf16> {
  using I = vi16;
  static constexpr int n = 16;
};
template <class V>
using IntLanes = typename Lanes<V>::I;

template <class V>
MF_INLINE V vload(const float* p) {  // unaligned
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class V>
MF_INLINE void vstore(float* p, V v) {
  std::memcpy(p, &v, sizeof v);
}
template <class V>
MF_INLINE V vsplat(float v) {
  return V{} + v;
}
// Lane by lane: faster than the AVX2 gather instruction here (measured).
template <class V>
MF_INLINE V gather(const float* d, const IntLanes<V>& idx) {
  V r;
  for (int k = 0; k < Lanes<V>::n; ++k) r[k] = d[idx[k]];
  return r;
}
template <class V>
MF_INLINE V vmin(V a, V b) {
  return a < b ? a : b;
}
template <class V>
MF_INLINE V vmax(V a, V b) {
  return a > b ? a : b;
}

template <class V>
struct VTap {
  IntLanes<V> lo;  // upper sample = lo + 1 (clamped axes with n >= 2)
  V t;
};
// AxisSamples::at on a vector of positions (non-periodic axis, n >= 2); a
// NaN position clamps to sample 0 instead of indexing out of bounds.
template <class V>
MF_INLINE VTap<V> vtap(const AxisSamples& ax, V p) {
  V g = p - ax.offset;
  g = g > 0.0f ? g : vsplat<V>(0.0f);
  g = vmin(g, vsplat<V>(float(ax.n - 1)));
  IntLanes<V> i = __builtin_convertvector(vmin(g, vsplat<V>(float(ax.n - 2))), IntLanes<V>);
  return {i, g - __builtin_convertvector(i, V)};
}

// Bi-/trilinear blend of the 2^D corner values at(offset) (offsets 0, 1,
// sy, sy + 1, then + sz), x first, as the scalar interpolate<D>; lo/hi
// receive the corners' min and max.
template <int D, class V, class At>
MF_INLINE V blendCorners(At&& at, size_t sy, size_t sz, const V* t, V* lo = nullptr, V* hi = nullptr) {
  const V t0 = t[0], t1 = t[1];
  if constexpr (D == 2) {
    V v00 = at(0), v10 = at(1), v01 = at(sy), v11 = at(sy + 1);
    if (lo) {
      *lo = vmin(vmin(v00, v10), vmin(v01, v11));
      *hi = vmax(vmax(v00, v10), vmax(v01, v11));
    }
    return bilinear(v00, v10, v01, v11, t0, t1);
  } else {
    V v0 = at(0), v1 = at(1), v2 = at(sy), v3 = at(sy + 1);
    V v4 = at(sz), v5 = at(sz + 1), v6 = at(sz + sy), v7 = at(sz + sy + 1);
    if (lo) {
      *lo = vmin(vmin(vmin(v0, v1), vmin(v2, v3)), vmin(vmin(v4, v5), vmin(v6, v7)));
      *hi = vmax(vmax(vmax(v0, v1), vmax(v2, v3)), vmax(vmax(v4, v5), vmax(v6, v7)));
    }
    return trilinear(v0, v1, v2, v3, v4, v5, v6, v7, t0, t1, t[2]);
  }
}

// Whether every lane of a comparison's result (-1 or 0 a lane) is set.
template <class I>
MF_INLINE bool allLanes(I m) {
  constexpr int n = sizeof(I) / sizeof(int);
  long long q[n / 2];
  std::memcpy(q, &m, sizeof m);
  long long all = q[0];
  for (int k = 1; k < n / 2; ++k) all &= q[k];
  return all == -1;
}

// interpolate<D> on a vector of positions; lo/hi receive the stencil's min
// and max. `size`: the samples in data.
template <int D, class V>
MF_INLINE V vinterpolate(const float* data, const size_t* s, size_t size, const VTap<V>* tap, V* lo = nullptr,
                         V* hi = nullptr) {
  constexpr int n = Lanes<V>::n;
  using I = IntLanes<V>;
  I idx = tap[0].lo + tap[1].lo * int(s[1]);
  if constexpr (D == 3) idx += tap[2].lo * int(s[2]);
  V t[D];
  for (int a = 0; a < D; ++a) t[a] = tap[a].t;
  const size_t sy = s[1], sz = D == 3 ? s[D - 1] : 0;
  // Where the lanes' stencils are consecutive cells of one row (a smooth
  // flow moves neighbours alike), every corner is one contiguous load; where
  // they are two such runs (the lanes cross a cell boundary, or a row), two
  // loads and a blend.
  I lane;
  for (int k = 0; k < n; ++k) lane[k] = k;
  const I run = idx - lane, first = I{} + run[0], last = I{} + run[n - 1];
  const I inFirst = run == first;
  if (allLanes(inFirst)) {
    const float* d = data + run[0];
    return blendCorners<D, V>([d](size_t off) __attribute__((always_inline)) { return vload<V>(d + off); }, sy, sz,
                              t, lo, hi);
  }
  // Each run's loads read all n lanes from its start, so both must lie
  // inside the data for every corner.
  const long long lowest = std::min(run[0], run[n - 1]), highest = std::max(run[0], run[n - 1]);
  if (lowest >= 0 && size_t(highest) + sz + sy + 1 + n <= size && allLanes(inFirst | (run == last))) {
    const float *d0 = data + run[0], *d1 = data + run[n - 1];
    return blendCorners<D, V>(
        [ d0, d1, inFirst ](size_t off)
            __attribute__((always_inline)) { return inFirst ? vload<V>(d0 + off) : vload<V>(d1 + off); },
        sy, sz, t, lo, hi);
  }
  return blendCorners<D, V>(
      [ data, idx ](size_t off) __attribute__((always_inline)) { return gather<V>(data + off, idx); }, sy, sz, t, lo,
      hi);
}

// MacSampler on a vector of positions.
template <int D, class V>
MF_INLINE void vvelocity(const MacSampler<D>& vel, const V* p, V* v) {
  VTap<V> f[D], c[D];
  for (int b = 0; b < D; ++b) {
    f[b] = vtap(vel.face[b], p[b]);
    c[b] = vtap(vel.centre[b], p[b]);
  }
  for (int a = 0; a < D; ++a) {
    VTap<V> t[D];
    for (int b = 0; b < D; ++b) t[b] = b == a ? f[b] : c[b];
    const int nz = (a == D - 1 ? vel.face[D - 1] : vel.centre[D - 1]).n;  // samples along the last axis
    v[a] = vinterpolate<D, V>(vel.data[a], vel.stride[a], vel.stride[a][D - 1] * size_t(nz), t);
  }
}

// u at the samples of one row of a grid (all axes but x fixed) needs no
// gathers: along y and z every sample of the row shares its taps, and along x
// sample x reads the velocity samples x + shift and x + shift + 1 with one
// weight wherever neither clamp binds. RowVelocity holds those taps per
// component; at() interpolates consecutive samples from contiguous loads,
// blended as vinterpolate blends (blendCorners); the taps are the ones vtap
// gives, as the positions are small integers plus 0 or 1/2, exact in float.
template <int D>
struct RowVelocity {
  const float* base[D];  // component a's sample (shift, y tap, z tap)
  size_t s1[D], s2[D];   // its strides along y and z
  float t[D][D];         // t[a][b]: component a's weight along b
  int begin = 0, end = 0;  // x range of the row where every component's x taps are shifted copies

  RowVelocity(const MacSampler<D>& vel, const float* p, float xOffset, int dimX) {
    begin = 0;
    end = dimX;
    for (int a = 0; a < D; ++a) {
      const AxisSamples& ax = a == 0 ? vel.face[0] : vel.centre[0];
      const float d = xOffset - ax.offset;  // -1/2, 0 or 1/2
      const int shift = int(std::floor(d));
      t[a][0] = d - float(shift);
      begin = std::max(begin, -shift);  // g = x + d >= 0
      end = std::min(end, ax.n - 1 - shift);  // floor(g) <= n - 2
      ptrdiff_t offset = shift;  // (may be -1: base[a] + x is in range for x >= begin)
      for (int b = 1; b < D; ++b) {
        const AxisTap tb = (b == a ? vel.face[b] : vel.centre[b]).at(p[b]);
        t[a][b] = tb.t;
        offset += ptrdiff_t(tb.lo) * ptrdiff_t(vel.stride[a][b]);
      }
      base[a] = vel.data[a] + offset;
      s1[a] = vel.stride[a][1];
      s2[a] = D == 3 ? vel.stride[a][D - 1] : 0;
    }
  }

  template <class V>
  MF_INLINE void at(int x, V* v) const {
    for (int a = 0; a < D; ++a) {
      const float* b = base[a] + x;
      V ta[D];
      for (int c = 0; c < D; ++c) ta[c] = vsplat<V>(t[a][c]);
      v[a] = blendCorners<D, V>([b](size_t off) __attribute__((always_inline)) { return vload<V>(b + off); }, s1[a],
                                s2[a], ta);
    }
  }
};

template <int D>
bool allClamped(const LinearSampler<D>& field, const MacSampler<D>& vel) {
  for (int a = 0; a < D; ++a)
    if (field.axis[a].periodic || vel.face[a].periodic || field.axis[a].n < 2 || vel.centre[a].n < 2) return false;
  return true;
}

// u(p) at the samples of one grid, kept by a scheme's first pass for the
// later passes from the same samples through the same u.
template <int D>
struct StartVelocity {
  std::array<Grid<float, D>, D>* v = nullptr;
  bool reuse = false;  // false: compute and store; true: read
};

// The vector part of one row of a semi-Lagrangian pass: samples x, x + 1,
// .. in groups of V's lanes while a whole group fits; returns the first
// sample left to the scalar loop.
template <int D>
struct SimdRow {
  const LinearSampler<D>& field;
  const MacSampler<D>& vel;
  const RowVelocity<D>& row;
  const float* p;  // the row's position along axes 1..
  float c;         // dt / h
  int nx;
  size_t base;     // index of the row's first sample
  StartVelocity<D> start;
  float *dst, *lo, *hi;  // the pass's samples and (if lo) its stencils' bounds
};

template <int D, class V>
MF_INLINE int simdRow(const SimdRow<D>& j, int x) {
  constexpr int n = Lanes<V>::n;
  V vp[D], vm[D], vfoot[D], vv[D];
  for (int a = 1; a < D; ++a) vp[a] = vsplat<V>(j.p[a]);
  V lane;
  for (int k = 0; k < n; ++k) lane[k] = float(k);
  const size_t fieldSize = j.field.stride[D - 1] * size_t(j.field.axis[D - 1].n);
  for (; x + n <= j.nx; x += n) {
    vp[0] = (vsplat<V>(float(x)) + lane) + j.field.axis[0].offset;
    const size_t i = j.base + size_t(x);
    if (j.start.reuse) {
      for (int a = 0; a < D; ++a) vv[a] = vload<V>(&(*j.start.v)[a][i]);
    } else {
      if (x >= j.row.begin && x + n <= j.row.end)
        j.row.at(x, vv);
      else
        vvelocity<D, V>(j.vel, vp, vv);
      if (j.start.v)
        for (int a = 0; a < D; ++a) vstore(&(*j.start.v)[a][i], vv[a]);
    }
    for (int a = 0; a < D; ++a) vm[a] = vp[a] - (0.5f * j.c) * vv[a];
    vvelocity<D, V>(j.vel, vm, vv);
    for (int a = 0; a < D; ++a) vfoot[a] = vp[a] - j.c * vv[a];
    VTap<V> t[D];
    for (int a = 0; a < D; ++a) t[a] = vtap(j.field.axis[a], vfoot[a]);
    V r;
    if (j.lo) {
      V l, h;
      r = vinterpolate<D, V>(j.field.data, j.field.stride, fieldSize, t, &l, &h);
      vstore(j.lo + i, l);
      vstore(j.hi + i, h);
    } else {
      r = vinterpolate<D, V>(j.field.data, j.field.stride, fieldSize, t);
    }
    vstore(j.dst + i, r);
  }
  return x;
}

template <int D>
int simdRow4(const SimdRow<D>& j, int x) {
  return simdRow<D, vf4>(j, x);
}
#if MORPHOFLOW_AVX2_KERNELS
template <int D>
__attribute__((target("avx2"))) int simdRow8(const SimdRow<D>& j, int x) {
  return simdRow<D, vf8>(j, x);
}
template <int D>
__attribute__((target("avx2,avx512f,avx512vl"))) int simdRow16(const SimdRow<D>& j, int x) {
  return simdRow<D, vf16>(j, x);
}
#endif

// The feet of one row of another grid's cell centres (cell size r fluid
// cells; centre x at (x + 1/2) r): samples x, x + 1, .. in groups of V's
// lanes while a whole group fits; returns the first sample left.
template <int D>
struct FeetRow {
  const MacSampler<D>& vel;
  const RowVelocity<D>* row;  // when r = 1: the gather-free first velocity
  const float* p;             // the row's position along axes 1.. (fluid cell units)
  float r, c;                 // cell size ratio, dt / h (fluid)
  int nx;
  size_t base;
  float* out[D];              // feet in the grid's cell coordinates
};

template <int D, class V>
MF_INLINE int feetRow(const FeetRow<D>& j, int x) {
  constexpr int n = Lanes<V>::n;
  V vp[D], vm[D], vv[D];
  for (int a = 1; a < D; ++a) vp[a] = vsplat<V>(j.p[a]);
  V lane;
  for (int k = 0; k < n; ++k) lane[k] = float(k);
  const float invR = 1.0f / j.r;
  for (; x + n <= j.nx; x += n) {
    vp[0] = ((vsplat<V>(float(x)) + lane) + 0.5f) * j.r;
    if (j.row && x >= j.row->begin && x + n <= j.row->end)
      j.row->at(x, vv);
    else
      vvelocity<D, V>(j.vel, vp, vv);
    for (int a = 0; a < D; ++a) vm[a] = vp[a] - (0.5f * j.c) * vv[a];
    vvelocity<D, V>(j.vel, vm, vv);
    for (int a = 0; a < D; ++a) vstore(j.out[a] + j.base + size_t(x), (vp[a] - j.c * vv[a]) * invR - 0.5f);
  }
  return x;
}

template <int D>
int feetRow4(const FeetRow<D>& j, int x) {
  return feetRow<D, vf4>(j, x);
}
#if MORPHOFLOW_AVX2_KERNELS
template <int D>
__attribute__((target("avx2"))) int feetRow8(const FeetRow<D>& j, int x) {
  return feetRow<D, vf8>(j, x);
}
template <int D>
__attribute__((target("avx2,avx512f,avx512vl"))) int feetRow16(const FeetRow<D>& j, int x) {
  return feetRow<D, vf16>(j, x);
}
#endif

// The rows of a grid a pass writes without tracing: skip[r] where every row
// within `reach` of row r (along y and z; a trace can end anywhere along
// x) holds one finite value, bitwise, in all its samples. There the
// interpolation of any stencil gives value + 0 (v + t (v - v)) and the
// stencil's min and max are the value; `bounds`: the pass writes those too.
struct UniformRows {
  std::vector<uint8_t> skip;
  std::vector<float> value;
  bool bounds = true;
};

// UniformRows from each row's flatness (flat[r]: every sample's bits are
// bits[r]); nullopt where no row is flat.
template <int D>
std::optional<UniformRows> uniformRows(const IVec<D>& dims, const std::vector<uint8_t>& flat,
                                       const std::vector<uint32_t>& bits, const std::array<int, D>& reach) {
  if (std::find(flat.begin(), flat.end(), uint8_t(1)) == flat.end()) return std::nullopt;
  const size_t rows = flat.size(), ny = size_t(dims[1]);
  // Separably: rows whose window along y is flat and equal to them, then
  // rows whose window along z holds such rows only (the same condition as
  // the whole window's, at 2 (ry + rz) + 2 looks a row).
  const int nz = D == 3 ? dims[D - 1] : 1;
  auto along = [&](const std::vector<uint8_t>& in, int reachRows, bool alongZ) {
    std::vector<uint8_t> out(rows, 0);
    parallelFor(rows, [&](size_t r) {
      if (!in[r]) return;
      const int k = alongZ ? int(r / ny) : int(r % ny), n = alongZ ? nz : int(ny);
      const size_t step = alongZ ? ny : 1;
      for (int j = std::max(k - reachRows, 0); j <= std::min(k + reachRows, n - 1); ++j) {
        const size_t q = r + (ptrdiff_t(j) - k) * ptrdiff_t(step);
        if (!in[q] || bits[q] != bits[r]) return;
      }
      out[r] = 1;
    }, 256);
    return out;
  };
  std::vector<uint8_t> skip = along(flat, reach[1], false);
  if (D == 3) skip = along(skip, reach[D - 1], true);
  UniformRows u{std::move(skip), std::vector<float>(rows)};
  for (size_t r = 0; r < rows; ++r)
    if (u.skip[r]) u.value[r] = std::bit_cast<float>(bits[r]);
  return u;
}

// ... of a grid, from its samples.
template <int D>
std::optional<UniformRows> uniformRows(const Grid<float, D>& g, const std::array<int, D>& reach) {
  const size_t nx = size_t(g.dims()[0]), rows = g.size() / nx;
  std::vector<uint8_t> flat(rows);
  std::vector<uint32_t> bits(rows);
  parallelFor(rows, [&](size_t r) {
    const float* p = g.data() + r * nx;
    const uint32_t b = std::bit_cast<uint32_t>(p[0]);
    bool same = std::isfinite(p[0]);
    for (size_t x = 1; x < nx; ++x) same &= std::bit_cast<uint32_t>(p[x]) == b;
    flat[r] = same;
    bits[r] = b;
  }, rowGrain<D>(g.dims()));
  return uniformRows<D>(g.dims(), flat, bits, reach);
}

// ... of what a pass wrote from `before`: its skipped rows are flat (value
// + 0); the others are taken as not flat (skipping less is still exact).
template <int D>
std::optional<UniformRows> uniformRows(const IVec<D>& dims, const UniformRows& before,
                                       const std::array<int, D>& reach) {
  std::vector<uint32_t> bits(before.value.size());
  for (size_t r = 0; r < bits.size(); ++r) bits[r] = std::bit_cast<uint32_t>(before.value[r] + 0.0f);
  return uniformRows<D>(dims, before.skip, bits, reach);
}

// One semi-Lagrangian pass; optionally records the min/max of each stencil.
// Works in cell units: p = k + offset, foot = p - (dt/h) u(p - (dt/2h) u(p)).
template <int D>
size_t semiLagrangian(const Grid<float, D>& src, const Layout<D>& layout, const MacVelocity<D>& u, double dt,
                      float* dst, float* lo, float* hi, StartVelocity<D> start = {},
                      const UniformRows* uniform = nullptr) {
  const LinearSampler<D> field(src, layout);
  const MacSampler<D> vel(u);
  const float c = float(dt / u.h());
  const IVec<D> dims = src.dims();
  const bool simd = allClamped<D>(field, vel);
  [[maybe_unused]] const bool wide = useAvx2(), wider = useAvx512();
  parallelForRows<D>(dims, [&](size_t row) {
    const size_t base = row * size_t(dims[0]);
    if (uniform && uniform->skip[row]) {
      const float c = uniform->value[row];
      std::fill_n(dst + base, dims[0], c + 0.0f);
      if (lo && uniform->bounds) {
        std::fill_n(lo + base, dims[0], c);
        std::fill_n(hi + base, dims[0], c);
      }
      return;
    }
    float p[D], m[D], f[D], v[D];
    size_t rest = row;
    for (int a = 1; a < D; ++a) {
      p[a] = float(int(rest % size_t(dims[a]))) + field.axis[a].offset;
      rest /= size_t(dims[a]);
    }
    int x = 0;
    if (simd) {
      const RowVelocity<D> rv(vel, p, field.axis[0].offset, dims[0]);
      const SimdRow<D> job{field, vel, rv, p, c, dims[0], base, start, dst, lo, hi};
#if MORPHOFLOW_AVX2_KERNELS
      if (wider) x = simdRow16<D>(job, x);
      if (wide) x = simdRow8<D>(job, x);
#endif
      x = simdRow4<D>(job, x);
    }
    for (; x < dims[0]; ++x) {
      p[0] = float(x) + field.axis[0].offset;
      const size_t i = base + size_t(x);
      if (start.reuse) {
        for (int a = 0; a < D; ++a) v[a] = (*start.v)[a][i];
      } else {
        vel(p, v);
        if (start.v)
          for (int a = 0; a < D; ++a) (*start.v)[a][i] = v[a];
      }
      for (int a = 0; a < D; ++a) m[a] = p[a] - 0.5f * c * v[a];
      vel(m, v);
      for (int a = 0; a < D; ++a) f[a] = p[a] - c * v[a];
      dst[i] = lo ? field(f, lo + i, hi + i) : field(f);
    }
  });
  size_t rows = src.size() / size_t(dims[0]);
  if (uniform) rows -= size_t(std::count(uniform->skip.begin(), uniform->skip.end(), uint8_t(1)));
  return rows;
}

}  // namespace

template <int D>
size_t advectField(const Grid<float, D>& src, const Layout<D>& layout, const MacVelocity<D>& u,
                 double dt, AdvectionScheme scheme, Grid<float, D>* dst, AdvectionScratch<D>* scratch,
                 const std::array<int, D>* reach) {
  // The rows of g a pass from g writes without tracing.
  std::optional<UniformRows> map;
  auto uniform = [&](const Grid<float, D>& g) -> const UniformRows* {
    if (reach) map = uniformRows<D>(g, *reach);
    return map ? &*map : nullptr;
  };
  if (scheme == AdvectionScheme::SemiLagrangian) {
    return semiLagrangian<D>(src, layout, u, dt, dst->data(), nullptr, nullptr, {}, uniform(src));
  }
  WorkPool own;
  AdvectionScratch<D> local;
  if (!scratch) local.borrow(&own, scheme, src.size());
  AdvectionScratch<D>& s = scratch ? *scratch : local;
  float *lo = s.lo(), *hi = s.hi(), *back = s.back();
  if (scheme == AdvectionScheme::MacCormack) {
    // phi^ = A(phi); phi~ = A^-1(phi^); phi = phi^ + (phi - phi~) / 2, limited.
    Grid<float, D>& fwd = *dst;
    std::optional<UniformRows> first = reach ? uniformRows<D>(src, *reach) : std::nullopt, second;
    if (first) first->bounds = false;  // lo = hi = the row's value there
    size_t traced = semiLagrangian<D>(src, layout, u, dt, fwd.data(), lo, hi, {}, first ? &*first : nullptr);
    if (first) second = uniformRows<D>(src.dims(), *first, *reach);
    traced += semiLagrangian<D>(fwd, layout, u, -dt, back, nullptr, nullptr, {}, second ? &*second : nullptr);
    const size_t nx = size_t(src.dims()[0]);
    parallelForRows<D>(src.dims(), [&](size_t row) {
      const bool flat = first && first->skip[row];
      // Both passes skipped: phi^ = phi~ = phi + 0, so phi^ stands.
      if (flat && second && second->skip[row]) return;
      const float c = flat ? first->value[row] : 0.0f;
      for (size_t i = row * nx; i < (row + 1) * nx; ++i) {
        float v = fwd[i] + 0.5f * (src[i] - back[i]);
        // Revert to first order where the correction leaves the stencil's range.
        if (v >= (flat ? c : lo[i]) && v <= (flat ? c : hi[i])) fwd[i] = v;
      }
    });
    return traced;
  }
  // BFECC: phi_bar = phi + (phi - A^-1 A phi) / 2, then A(phi_bar), limited.
  Grid<float, D>& fwd = s.fwd;
  fwd.reshape(src.dims());
  size_t traced = semiLagrangian<D>(src, layout, u, dt, fwd.data(), nullptr, nullptr, {}, uniform(src));
  traced += semiLagrangian<D>(fwd, layout, u, -dt, back, nullptr, nullptr, {}, uniform(fwd));
  Grid<float, D>& corrected = fwd;  // fwd is no longer needed
  parallelFor(src.size(), [&](size_t i) { corrected[i] = src[i] + 0.5f * (src[i] - back[i]); }, 4096);
  traced += semiLagrangian<D>(corrected, layout, u, dt, dst->data(), nullptr, nullptr, {}, uniform(corrected));
  traced += semiLagrangian<D>(src, layout, u, dt, back, lo, hi, {}, uniform(src));  // first-order fallback
  parallelFor(src.size(), [&](size_t i) {
    if ((*dst)[i] < lo[i] || (*dst)[i] > hi[i]) (*dst)[i] = back[i];
  }, 4096);
  return traced;
}

template <int D>
std::optional<std::array<int, D>> traceReach(const MacVelocity<D>& u, double dt) {
  std::array<int, D> reach;
  for (int a = 0; a < D; ++a) {
    if (u.periodic()[size_t(a)]) return std::nullopt;
    const Grid<float, D>& g = u[a];
    const double m = deterministicMax(g.size(), [&](size_t i) {  // infinite where u is not finite
      return std::isfinite(g[i]) ? std::abs(double(g[i])) : HUGE_VAL;
    });
    // |foot - p| <= |dt| / h max|u_a| (the traces interpolate u); the
    // stencil adds a row, and one more covers the positions' rounding.
    const double cells = std::abs(dt) / u.h() * m;
    if (!(cells < 1e6)) return std::nullopt;
    reach[size_t(a)] = int(std::ceil(cells)) + 2;
  }
  return reach;
}

template <int D>
void advectVelocity(const MacVelocity<D>& u, double dt, AdvectionScheme scheme, MacVelocity<D>* dst,
                    AdvectionScratch<D>* scratch) {
  for (int a = 0; a < D; ++a) advectField<D>(u[a], u.layout(a), u, dt, scheme, &(*dst)[a], scratch);
}

template size_t advectField<2>(const Grid<float, 2>&, const Layout<2>&, const MacVelocity<2>&, double,
                             AdvectionScheme, Grid<float, 2>*, AdvectionScratch<2>*, const std::array<int, 2>*);
template size_t advectField<3>(const Grid<float, 3>&, const Layout<3>&, const MacVelocity<3>&, double,
                             AdvectionScheme, Grid<float, 3>*, AdvectionScratch<3>*, const std::array<int, 3>*);
template std::optional<std::array<int, 2>> traceReach<2>(const MacVelocity<2>&, double);
template std::optional<std::array<int, 3>> traceReach<3>(const MacVelocity<3>&, double);
template void advectVelocity<2>(const MacVelocity<2>&, double, AdvectionScheme, MacVelocity<2>*, AdvectionScratch<2>*);
template void advectVelocity<3>(const MacVelocity<3>&, double, AdvectionScheme, MacVelocity<3>*, AdvectionScratch<3>*);

template <int D>
bool traceCellFeet(const MacVelocity<D>& u, double dt, const IVec<D>& cells, double h,
                   const std::array<float*, D>& feet) {
  const MacSampler<D> vel(u);
  for (int a = 0; a < D; ++a)
    if (vel.face[a].periodic || vel.centre[a].n < 2) return false;
  const float r = float(h / u.h()), c = float(dt / u.h());
  // On the velocity's own cells the first velocity needs no gathers.
  bool same = true;
  for (int a = 0; a < D; ++a) same = same && cells[a] == u.cells()[a];
  [[maybe_unused]] const bool wide = useAvx2(), wider = useAvx512();
  parallelForRows<D>(cells, [&](size_t row) {
    float p[D], m[D], v[D];
    size_t rest = row;
    for (int a = 1; a < D; ++a) {
      p[a] = (float(int(rest % size_t(cells[a]))) + 0.5f) * r;
      rest /= size_t(cells[a]);
    }
    const size_t base = row * size_t(cells[0]);
    std::optional<RowVelocity<D>> rv;
    if (same) rv.emplace(vel, p, 0.5f, cells[0]);
    FeetRow<D> job{vel, rv ? &*rv : nullptr, p, r, c, cells[0], base, {}};
    for (int a = 0; a < D; ++a) job.out[a] = feet[size_t(a)];
    int x = 0;
#if MORPHOFLOW_AVX2_KERNELS
    if (wider) x = feetRow16<D>(job, x);
    if (wide) x = feetRow8<D>(job, x);
#endif
    x = feetRow4<D>(job, x);
    for (; x < cells[0]; ++x) {  // the row's last samples, one lane's arithmetic
      p[0] = (float(x) + 0.5f) * r;
      vel(p, v);
      for (int a = 0; a < D; ++a) m[a] = p[a] - 0.5f * c * v[a];
      vel(m, v);
      for (int a = 0; a < D; ++a) feet[size_t(a)][base + size_t(x)] = (p[a] - c * v[a]) * (1.0f / r) - 0.5f;
    }
  });
  return true;
}

template bool traceCellFeet<2>(const MacVelocity<2>&, double, const IVec<2>&, double, const std::array<float*, 2>&);
template bool traceCellFeet<3>(const MacVelocity<3>&, double, const IVec<3>&, double, const std::array<float*, 3>&);

}  // namespace morphoflow
