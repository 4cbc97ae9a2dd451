#include "core/laplace_system.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <type_traits>

#include "core/parallel.h"
#include "core/row_stencil.h"
#include "core/simd4.h"
#include "core/simd_dispatch.h"

#if MORPHOFLOW_AVX2_KERNELS
#include <immintrin.h>
#endif

namespace morphoflow {

namespace {

// w x on a uniform span, whose faces all weigh wu: skipped where wu = 1
// (1 x = x exactly), so both forms give the general sums' values.
template <bool Weighted, class V, class W>
inline V times(W wu, V x) {
  if constexpr (Weighted)
    return wu * x;
  else
    return x;
}
// The same on a uniform row's interior (every face weighs wu: the same sums).
template <int D, bool Weighted, class T>
inline T neighbourSumUniform(const RowStencil<D, T>& s, const T* xr, size_t i, T wu) {
  T sum = times<Weighted>(wu, xr[i + 1]) + times<Weighted>(wu, xr[i - 1]);
  for (int a = 1; a < D; ++a) sum += times<Weighted>(wu, s.xhi[a][i]) + times<Weighted>(wu, s.xlo[a][i]);
  return sum;
}

// Four cells of one colour of a uniform single-precision span at a time:
// cells i, i + 2, i + 4, i + 6 (all < end), each with the scalar loop's
// arithmetic ((b inv + ((w x_r + w x_l) + (w hi + w lo) ...)) r0), so the result is
// bitwise that of the scalar loop. The other colour's lanes are written back
// unchanged, unless `shared`: another task may then be reading this row's
// other colour and writing this colour in the rows beyond the last axis's
// neighbours, so only the colour's cells are stored here and only the
// other colour's cells are loaded there. Returns the next cell of the colour.
inline vf4 evens(const float* p) { return MF_SHUFFLE(load4(p), load4(p + 4), 0, 2, 4, 6); }
inline vf4 evensOnly(const float* p) { return vf4{p[0], p[2], p[4], p[6]}; }

template <int D, bool Weighted>
size_t sweepUniform4(const RowStencil<D, float>& s, const float* br, float* xr, size_t i, size_t end, float inv,
                     float r0, float wu, bool shared) {
  // x_{i-1} comes from the previous block's registers, not from memory just
  // stored (an overlapping load would stall store-to-load forwarding).
  vf4 before = {0.0f, 0.0f, 0.0f, i + 7 <= end ? xr[i - 1] : 0.0f};
  for (; i + 7 <= end; i += 8) {  // updates i .. i + 6 < end, reads x up to i + 7 <= end < nx
    const vf4 here = load4(xr + i), next = load4(xr + i + 4);
    const vf4 right = MF_SHUFFLE(here, next, 1, 3, 5, 7);
    const vf4 left = MF_SHUFFLE(before, right, 3, 4, 5, 6);
    before = right;
    vf4 sum = times<Weighted>(wu, right) + times<Weighted>(wu, left);
    for (int a = 1; a < D; ++a) {
      const bool only = shared && a == D - 1;
      const vf4 hi = only ? evensOnly(s.xhi[a] + i) : evens(s.xhi[a] + i);
      const vf4 lo = only ? evensOnly(s.xlo[a] + i) : evens(s.xlo[a] + i);
      sum += times<Weighted>(wu, hi) + times<Weighted>(wu, lo);
    }
    const vf4 r = (evens(br + i) * inv + sum) * r0;
    if (shared) {
      for (int k = 0; k < 4; ++k) xr[i + 2 * size_t(k)] = r[k];
    } else {
      store4(xr + i, MF_SHUFFLE(r, here, 0, 5, 1, 7));
      store4(xr + i + 4, MF_SHUFFLE(r, next, 2, 5, 3, 7));
    }
  }
  return i;
}

#if MORPHOFLOW_AVX2_KERNELS
// The same eight cells of one colour at a time (cells i, i + 2, .., i + 14,
// all < end) on AVX2. The lanes hold the cells in the order that the
// in-lane shuffles give (i + 0, 2, 8, 10 | 4, 6, 12, 14), the same for every
// operand, and unpacking with the other colour restores memory order; each
// lane's arithmetic is sweepUniform4's.
__attribute__((target("avx2"), always_inline)) inline __m256 evens8(const float* p) {
  return _mm256_shuffle_ps(_mm256_loadu_ps(p), _mm256_loadu_ps(p + 8), 0x88);
}
// The same lanes from the even cells alone (`shared`, as sweepUniform4).
__attribute__((target("avx2"), always_inline)) inline __m256 evensOnly8(const float* p) {
  return _mm256_setr_ps(p[0], p[2], p[8], p[10], p[4], p[6], p[12], p[14]);
}

__attribute__((target("avx2"), always_inline)) inline __m256 times8(bool weighted, __m256 wu, __m256 x) {
  return weighted ? _mm256_mul_ps(wu, x) : x;
}

template <int D, bool Weighted>
__attribute__((target("avx2"))) size_t sweepUniform8(const RowStencil<D, float>& s, const float* br, float* xr,
                                                     size_t i, size_t end, float inv, float r0, float wu,
                                                     bool shared) {
  if (i + 15 > end) return i;
  const __m256 vinv = _mm256_set1_ps(inv), vr0 = _mm256_set1_ps(r0), vw = _mm256_set1_ps(wu);
  // The odd cells (i + 1, 3, 9, 11 | 5, 7, 13, 15) rotated onto the even
  // cells' left neighbours (i + 15, 1, 7, 9 | 3, 5, 11, 13): lane 0 is taken
  // from the previous block's rotation (its i + 15 is this block's i - 1).
  const __m256i rotate = _mm256_setr_epi32(7, 0, 5, 2, 1, 4, 3, 6);
  __m256 before = _mm256_set1_ps(xr[i - 1]);
  for (; i + 15 <= end; i += 16) {
    const __m256 here = _mm256_loadu_ps(xr + i), next = _mm256_loadu_ps(xr + i + 8);
    const __m256 right = _mm256_shuffle_ps(here, next, 0xDD);
    const __m256 rotated = _mm256_permutevar8x32_ps(right, rotate);
    const __m256 left = _mm256_blend_ps(rotated, before, 0x01);
    before = rotated;
    __m256 sum = _mm256_add_ps(times8(Weighted, vw, right), times8(Weighted, vw, left));
    for (int a = 1; a < D; ++a) {
      const bool only = shared && a == D - 1;
      const __m256 hi = only ? evensOnly8(s.xhi[a] + i) : evens8(s.xhi[a] + i);
      const __m256 lo = only ? evensOnly8(s.xlo[a] + i) : evens8(s.xlo[a] + i);
      sum = _mm256_add_ps(sum, _mm256_add_ps(times8(Weighted, vw, hi), times8(Weighted, vw, lo)));
    }
    const __m256 r = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(evens8(br + i), vinv), sum), vr0);
    if (shared) {  // the even lanes only: the colour's cells
      const __m256i even = _mm256_setr_epi32(-1, 0, -1, 0, -1, 0, -1, 0);
      _mm256_maskstore_ps(xr + i, even, _mm256_unpacklo_ps(r, right));
      _mm256_maskstore_ps(xr + i + 8, even, _mm256_unpackhi_ps(r, right));
    } else {
      _mm256_storeu_ps(xr + i, _mm256_unpacklo_ps(r, right));
      _mm256_storeu_ps(xr + i + 8, _mm256_unpackhi_ps(r, right));
    }
  }
  return i;
}
#endif

// Face sum sum_f w_f (x_i - x_j(f)): with the c term this is A x, written so
// that every face's two contributions cancel to round-off (mass conservation
// does not rest on a float diagonal matching its weights).
template <int D, class T>
inline T faceSum(const RowStencil<D, T>& s, const float* const* wa, const T* xr, size_t i, size_t il, size_t ih,
                 float wl) {
  const T xi = xr[i];
  T sum = T(wa[0][i]) * (xi - xr[ih]) + T(wl) * (xi - xr[il]);
  for (int a = 1; a < D; ++a) sum += T(wa[a][i]) * (xi - s.xhi[a][i]) + T(s.wlo[a][i]) * (xi - s.xlo[a][i]);
  return sum;
}
template <int D, bool Weighted, class T>
inline T faceSumUniform(const RowStencil<D, T>& s, const T* xr, size_t i, T wu) {
  const T xi = xr[i];
  T sum = times<Weighted>(wu, xi - xr[i + 1]) + times<Weighted>(wu, xi - xr[i - 1]);
  for (int a = 1; a < D; ++a) sum += times<Weighted>(wu, xi - s.xhi[a][i]) + times<Weighted>(wu, xi - s.xlo[a][i]);
  return sum;
}

#if MORPHOFLOW_AVX2_KERNELS
// y = sc (c0 x + faceSumUniform) (b - y where b is given) on a uniform span,
// one 256-bit vector of cells at a time (eight floats or four doubles), each
// lane with the scalar loop's arithmetic. Returns the first cell not done.
template <class T>
struct Wide {  // a 256-bit vector of T; in a target("avx2") function its operators are AVX
  typedef T V __attribute__((vector_size(32)));
  static constexpr size_t kLanes = 32 / sizeof(T);
};
template <class T>
__attribute__((target("avx2"), always_inline)) inline typename Wide<T>::V loadWide(const T* p) {
  typename Wide<T>::V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}

template <int D, bool Weighted, class T>
__attribute__((target("avx2"))) size_t applyUniformAvx(const RowStencil<D, T>& s, const T* xr, T* yr, const T* br,
                                                       size_t i, size_t end, T sc, T c0, T wu) {
  using V = typename Wide<T>::V;
  for (; i + Wide<T>::kLanes <= end; i += Wide<T>::kLanes) {
    const V xi = loadWide(xr + i);
    V d[2 * D] = {xi - loadWide(xr + i + 1), xi - loadWide(xr + i - 1)};
    for (int a = 1; a < D; ++a) {
      d[2 * a] = xi - loadWide(s.xhi[a] + i);
      d[2 * a + 1] = xi - loadWide(s.xlo[a] + i);
    }
    if constexpr (Weighted)
      for (V& v : d) v = wu * v;
    V sum = d[0] + d[1];
    for (int a = 1; a < D; ++a) sum = sum + (d[2 * a] + d[2 * a + 1]);
    V y = sc * (c0 * xi + sum);
    if (br) y = loadWide(br + i) - y;  // b - A x for a defect
    __builtin_memcpy(yr + i, &y, sizeof y);
  }
  return i;
}
#endif

}  // namespace

template <int D>
LaplaceSystem<D>::LaplaceSystem(const IVec<D>& d, const std::array<bool, D>& p, double s)
    : dims(d), periodic(p), scale(s), c(d, 0.0f) {
  for (int a = 0; a < D; ++a) w[a] = RowField<D>(d, 0.0f);
  zerosX_.assign(size_t(d[0]), 0.0);
  zerosW_.assign(size_t(d[0]), 0.0f);
}

template <int D>
template <class T>
const T* LaplaceSystem<D>::zeros() const {
  if constexpr (std::is_same_v<T, double>)
    return zerosX_.data();
  else
    return zerosW_.data();
}

template <int D>
void LaplaceSystem<D>::finalize() {
  // Zero the couplings that would wrap across a non-periodic edge: the last
  // cell of every row along x, the whole last rows along y (and z).
  const size_t nx = size_t(dims[0]);
  const size_t rows = size() / nx;
  if (nx > UINT16_MAX) throw std::length_error("LaplaceSystem: a row of more than 65535 cells (its counts are 16-bit)");
  parallelForRows<D>(dims, [&](size_t row) {
    if (!periodic[0] && w[0].dense()) w[0].at(row * nx + nx - 1) = 0.0f;
    size_t rest = row;
    for (int a = 1; a < D; ++a) {
      const bool last = int(rest % size_t(dims[a])) == dims[a] - 1;
      rest /= size_t(dims[a]);
      if (last && !periodic[a] && w[a].dense()) std::fill_n(w[a].mutableRow(row), nx, 0.0f);
    }
  });
  // Rows alike in c and their weights (a box's, whatever its size) share one
  // computed row.
  c.compact();
  for (int a = 0; a < D; ++a) w[a].compact();
  diag = RowField<D>::template fromSources<2 * D>(
      dims,
      [&](size_t row) {
        const RowStencil<D, double> s = stencil(row);
        std::array<const float*, 2 * D> src{c.row(row), w[0].row(row)};
        for (int a = 1; a < D; ++a) src[size_t(2 * a)] = w[a].row(row), src[size_t(2 * a + 1)] = s.wlo[a];
        return src;
      },
      [&](size_t row, float* d) { diagRow(row, d); });
  // Rows alike in their stored rows and domain edges (a box's, whatever its
  // size) share one computed span.
  std::vector<size_t> all(rows);
  for (size_t row = 0; row < rows; ++row) all[row] = row;
  uniformSpan_.resize(rows);
  sweepSpan_.resize(rows);
  findSpans(all);
  // The active cells and the positive c, counted once per stored row.
  auto positives = [&](const RowField<D>& f, std::vector<uint16_t>* perRow) {
    std::map<const float*, uint16_t> counted;
    perRow->resize(rows);
    for (size_t row = 0; row < rows; ++row) {
      const float* r = f.row(row);
      auto [it, added] = counted.emplace(r, 0);
      if (added) it->second = positiveCount(r);
      (*perRow)[row] = it->second;
    }
  };
  positives(diag, &activeOf_);
  positives(c, &positiveCOf_);
  countActive();
}

template <int D>
void LaplaceSystem<D>::finalizeRows(const IVec<D>& lo, const IVec<D>& hi) {
  bool compact = !c.dense() && !diag.dense() && !activeOf_.empty();
  for (int a = 0; a < D; ++a) compact = compact && !w[a].dense();
  if (!compact) return finalize();  // (written in place: the edges' zeros and the compaction are finalize's)
  const std::vector<size_t> rows = rowsReading(lo, hi);
  rewriteRows<D, 1>({&diag}, rows, [&](size_t row, const std::array<float*, 1>& d) { diagRow(row, d[0]); });
  findSpans(rows);
  parallelFor(rows.size(), [&](size_t k) {
    activeOf_[rows[k]] = positiveCount(diag.row(rows[k]));
    positiveCOf_[rows[k]] = positiveCount(c.row(rows[k]));
  });
  countActive();
}

template <int D>
std::vector<size_t> LaplaceSystem<D>::rowsReading(const IVec<D>& lo, const IVec<D>& hi) const {
  std::vector<size_t> rows = rowsOf<D>(dims, lo, hi);
  const size_t own = rows.size();
  size_t stride = 1;  // rows between neighbours along axis a
  for (int a = 1; a < D; ++a) {
    for (size_t k = 0; k < own; ++k) {
      const int at = int((rows[k] / stride) % size_t(dims[a]));
      if (at + 1 < dims[a]) rows.push_back(rows[k] + stride);
      else if (periodic[a]) rows.push_back(rows[k] - size_t(dims[a] - 1) * stride);
    }
    stride *= size_t(dims[a]);
  }
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  return rows;
}

template <int D>
RowStencil<D, double> LaplaceSystem<D>::stencil(size_t row) const {
  return rowStencil<D>(*this, zerosX_.data(), zerosX_.data(), zerosW_.data(), row);
}

// diag_i = c_i + sum over the 2D faces of w (the low faces' weights are the
// row's own for x, the neighbour rows' for y and z; wrapped, or 0 beyond a
// non-periodic edge: finalize zeroed those).
template <int D>
void LaplaceSystem<D>::diagRow(size_t row, float* d) const {
  const size_t nx = size_t(dims[0]);
  const RowStencil<D, double> s = stencil(row);
  const float* cr = c.row(row);
  const float* w0 = w[0].row(row);
  for (size_t i = 0; i < nx; ++i) {
    float v = cr[i];
    v += w0[i] + w0[i == 0 ? nx - 1 : i - 1];
    for (int a = 1; a < D; ++a) v += w[a].row(row)[i] + s.wlo[a][i];
    d[i] = v;
  }
}

// The longest run of interior cells of a row that are uniform among
// themselves (one weight wu > 0 on every face, one c, hence one diagonal).
template <int D>
typename LaplaceSystem<D>::Span LaplaceSystem<D>::longestSpan(size_t row, bool edges) const {
  const size_t nx = size_t(dims[0]);
  if (nx < 3) return Span{};
  const RowStencil<D, double> s = stencil(row);
  const float* cr = c.row(row);
  const float* w0 = w[0].row(row);
  // The smoother also takes a face across a non-periodic domain edge:
  // there the general sum adds 0 * 0 from the row of zeros, and the
  // uniform one wu times that row's 0 (bitwise the same; not so A x, whose
  // face sum would add 0 (x_i - 0) against wu (x_i - 0)).
  bool edgeLo[D] = {}, edgeHi[D] = {};
  const int k[3] = {0, int(row % size_t(dims[1])), D == 3 ? int(row / size_t(dims[1])) : 0};
  for (int a = 1; a < D; ++a) {
    edgeLo[a] = k[a] == 0 && !periodic[a];
    edgeHi[a] = k[a] == dims[a] - 1 && !periodic[a];
  }
  // Every face of cell i weighs wu (with `edges`, a face across a
  // non-periodic domain edge may weigh 0 instead).
  auto uniform = [&](size_t i, float wu) {
    if (w0[i] != wu || w0[i - 1] != wu) return false;
    for (int a = 1; a < D; ++a) {
      const float hi = w[a].row(row)[i];
      if (!(hi == wu || (edges && edgeHi[a] && hi == 0.0f)) || !(s.wlo[a][i] == wu || (edges && edgeLo[a])))
        return false;
    }
    return true;
  };
  Span best;
  for (size_t i = 1; i + 1 < nx;) {
    const float wu = w0[i];
    if (!(wu > 0.0f) || !uniform(i, wu)) {
      ++i;
      continue;
    }
    size_t e = i + 1;
    while (e + 1 < nx && uniform(e, wu) && cr[e] == cr[i]) ++e;
    if (e - i > best.hi - best.lo) best = {uint32_t(i), uint32_t(e), wu};
    i = e;
  }
  return best;
}

// The spans of `rows` (ascending): once per set of rows alike in their
// stored rows and domain edges.
template <int D>
void LaplaceSystem<D>::findSpans(const std::vector<size_t>& rows) {
  using Key = std::array<uintptr_t, 2 * D + 1>;
  std::vector<std::pair<Key, size_t>> keys(rows.size());
  parallelFor(
      rows.size(),
      [&](size_t j) {
        const size_t row = rows[j];
        const RowStencil<D, double> s = stencil(row);
        Key key{reinterpret_cast<uintptr_t>(c.row(row)), reinterpret_cast<uintptr_t>(w[0].row(row))};
        uintptr_t edges = 0;
        const int k[3] = {0, int(row % size_t(dims[1])), D == 3 ? int(row / size_t(dims[1])) : 0};
        for (int a = 1; a < D; ++a) {
          key[size_t(2 * a)] = reinterpret_cast<uintptr_t>(w[a].row(row));
          key[size_t(2 * a + 1)] = reinterpret_cast<uintptr_t>(s.wlo[a]);
          edges |= uintptr_t(k[a] == 0 && !periodic[a]) << (2 * a);
          edges |= uintptr_t(k[a] == dims[a] - 1 && !periodic[a]) << (2 * a + 1);
        }
        key[size_t(2 * D)] = edges;
        keys[j] = {key, row};
      },
      256);
  std::sort(keys.begin(), keys.end());
  std::vector<size_t> first;  // the first of each run of equal keys
  for (size_t j = 0; j < keys.size(); ++j)
    if (j == 0 || keys[j].first != keys[j - 1].first) first.push_back(j);
  parallelFor(first.size(), [&](size_t g) {
    const size_t row = keys[first[g]].second;
    const Span uniform = longestSpan(row, false), sweep = longestSpan(row, true);
    const size_t end = g + 1 < first.size() ? first[g + 1] : keys.size();
    for (size_t j = first[g]; j < end; ++j) uniformSpan_[keys[j].second] = uniform, sweepSpan_[keys[j].second] = sweep;
  });
}

template <int D>
uint16_t LaplaceSystem<D>::positiveCount(const float* row) const {
  return uint16_t(std::count_if(row, row + dims[0], [](float v) { return v > 0; }));
}

template <int D>
void LaplaceSystem<D>::countActive() {
  active_ = 0;
  size_t positiveC = 0;
  for (size_t row = 0; row < activeOf_.size(); ++row) active_ += activeOf_[row], positiveC += positiveCOf_[row];
  singular_ = positiveC == 0;
}

template <int D>
template <class T, bool Dot>
double LaplaceSystem<D>::applyRow(size_t row, const T* x, T* y, const T* b) const {
  const size_t nx = size_t(dims[0]);
  const bool px = periodic[0];
  const T sc = T(scale);
  RowStencil<D, T> s = rowStencil<D>(*this, x, zeros<T>(), zerosW_.data(), row);
  const float* wa[D];
  for (int a = 0; a < D; ++a) wa[a] = w[a].row(row);
  const float* cr = c.row(row);
  const T* xr = x + s.base;
  T* yr = y;  // the row's own values
  auto edge = [&](size_t i) {
    size_t il = i == 0 ? nx - 1 : i - 1, ih = i + 1 == nx ? 0 : i + 1;
    float wl = (i == 0 && !px) ? 0.0f : wa[0][il];
    yr[i] = sc * (T(cr[i]) * xr[i] + faceSum<D, T>(s, wa, xr, i, il, ih, wl));
    return Dot ? double(xr[i]) * double(yr[i]) : 0.0;
  };
  double dot = edge(0);
  auto general = [&](size_t from, size_t to) {
    for (size_t i = from; i < to; ++i) {  // interior: no wrap, no branch
      yr[i] = sc * (T(cr[i]) * xr[i] + faceSum<D, T>(s, wa, xr, i, i - 1, i + 1, wa[0][i - 1]));
      if constexpr (Dot) dot += double(xr[i]) * double(yr[i]);
    }
  };
  // The row's uniform span: the same sums without the weight loads (every face weighs wu).
  const Span& span = uniformSpan_[row];
  const size_t lo = span.lo, hi = span.hi;
  if (lo < hi) {
    general(1, lo);
    const T c0 = T(cr[lo]), wu = T(span.w);
    auto run = [&](auto weighted) {
      constexpr bool W = decltype(weighted)::value;
      size_t i = lo;
      const T* br = b ? b + s.base : nullptr;
#if MORPHOFLOW_AVX2_KERNELS
      if (useAvx2() && hi - lo >= Wide<T>::kLanes) {
        i = applyUniformAvx<D, W, T>(s, xr, yr, br, i, hi, sc, c0, wu);
        // The last cells in one more vector placed to end at hi (the cells
        // it repeats get the same values again: y depends on x and b only).
        if (i < hi) i = applyUniformAvx<D, W, T>(s, xr, yr, br, hi - Wide<T>::kLanes, hi, sc, c0, wu);
      }
#endif
      for (; i < hi; ++i) {
        const T y = sc * (c0 * xr[i] + faceSumUniform<D, W, T>(s, xr, i, wu));
        yr[i] = br ? br[i] - y : y;
      }
      if constexpr (Dot) {
        auto xy = [&](size_t k) { return double(xr[k]) * double(yr[k]); };
        dot += orderedSum(lo, hi, xy);
      }
    };
    if (span.w == 1.0f)
      run(std::false_type{});
    else
      run(std::true_type{});
    general(hi, nx - 1);
  } else if (nx > 2) {
    general(1, nx - 1);
  }
  if (nx > 1) dot += edge(nx - 1);
  return dot;
}

template <int D>
template <class T>
void LaplaceSystem<D>::apply(const std::vector<T>& x, std::vector<T>* y) const {
  const size_t nx = size_t(dims[0]);
  parallelForRows<D>(dims, [&](size_t row) { applyRow<T, false>(row, x.data(), y->data() + row * nx); });
}

template <int D>
double LaplaceSystem<D>::applyDot(const Vector& x, Vector* y) const {
  const size_t nx = size_t(dims[0]);
  return deterministicRowSum<D>(
      dims, [&](size_t row) { return applyRow<double, true>(row, x.data(), y->data() + row * nx); });
}

template <int D>
template <class T, bool SumSquares>
double LaplaceSystem<D>::defectRow(size_t row, const T* b, const T* x, T* r) const {
  // r = b - A x on the uniform span (all active), A x elsewhere; then b - A x
  // there too while the row is in cache.
  applyRow<T, false>(row, x, r, b);
  const size_t nx = size_t(dims[0]), base = row * nx;
  T* __restrict rr = r;
  const T* __restrict br = b + base;
  const float* __restrict dr = diag.row(row);
  // b - A x where the cell is active, else 0, as a bit mask: a branch (or
  // a select GCC must assume may trap) would keep the loop scalar.
  using Bits = std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>;
  auto finish = [&](size_t from, size_t to) {
    for (size_t i = from; i < to; ++i) {
      const Bits active = Bits(0) - Bits(dr[i] > 0.0f);
      rr[i] = std::bit_cast<T>(std::bit_cast<Bits>(T(br[i] - rr[i])) & active);
    }
  };
  const Span& span = uniformSpan_[row];
  if (span.lo < span.hi) {
    finish(0, span.lo);
    finish(span.hi, nx);
  } else {
    finish(0, nx);
  }
  if constexpr (!SumSquares) return 0.0;
  auto square = [&](size_t i) { return double(rr[i]) * double(rr[i]); };
  return orderedSum(size_t(0), nx, square);
}

template <int D>
template <class T>
void LaplaceSystem<D>::defect(const T* b, const T* x, T* r) const {
  const size_t nx = size_t(dims[0]);
  parallelForRows<D>(dims, [&](size_t row) { defectRow<T, false>(row, b, x, r + row * nx); });
}

template <int D>
double LaplaceSystem<D>::residual(const Vector& b, const Vector& x, Vector* r) const {
  // The norm while each row is in cache, rather than a second pass over r.
  return std::sqrt(
      deterministicRowSum<D>(dims, [&](size_t row) {
        return defectRow<double, true>(row, b.data(), x.data(), r->data() + row * size_t(dims[0]));
      }));
}

template <int D>
double LaplaceSystem<D>::residualInPlace(Vector* b, const Vector& x) const {
  const size_t nx = size_t(dims[0]);
  return std::sqrt(deterministicRowSum<D>(dims, [&](size_t row) {
    thread_local std::vector<double> r;  // the row's residual, then over its b
    r.resize(nx);
    const double s = defectRow<double, true>(row, b->data(), x.data(), r.data());
    std::copy(r.begin(), r.end(), b->data() + row * nx);
    return s;
  }));
}

template <int D>
double LaplaceSystem<D>::residualRow(size_t row, const Vector& b, const Vector& x, double* r) const {
  return defectRow<double, true>(row, b.data(), x.data(), r);
}

namespace {
constexpr size_t kSlabPlanes = 8;  // the smoother's slabs: at least this many planes
constexpr size_t kSlabCells = 16384;  // and cells
}  // namespace

template <int D>
template <class T>
void LaplaceSystem<D>::gaussSeidel(const T* b, T* x, bool reverse) const {
  const size_t nx = size_t(dims[0]);
  const bool px = periodic[0];
  const T inv = T(1.0 / scale);
  const bool serial = coloursMeetAcrossRows();
  size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= size_t(dims[a]);
  [[maybe_unused]] const bool wide = useAvx2();
  auto sweepRow = [&](size_t row, size_t y, size_t z, int colour, bool shared) {
    RowStencil<D, T> s = rowStencil<D, T>(*this, x, zeros<T>(), zerosW_.data(), row, y, z);
    const size_t parity = y + z;
    const float* wa[D];
    for (int a = 0; a < D; ++a) wa[a] = w[a].row(row);
    const float* dr = diag.row(row);
    auto rd = [&](size_t i) { return inverse(dr[i]); };
    const T* br = b + s.base;
    T* xr = x + s.base;
    // x_i = (b_i / scale + sum_f w_f x_j) / diag_i; invDiag is 0 on inactive cells.
    auto edge = [&](size_t i) {
      size_t il = i == 0 ? nx - 1 : i - 1, ih = i + 1 == nx ? 0 : i + 1;
      float wl = (i == 0 && !px) ? 0.0f : wa[0][il];
      xr[i] = (br[i] * inv + neighbourSum<D, T>(s, wa, xr, i, il, ih, wl)) * rd(i);
    };
    size_t i = (size_t(colour) + parity) & 1;
    if (i == 0) {
      edge(0);
      i = 2;
    }
    auto general = [&](size_t end) {
      for (; i < end; i += 2)
        xr[i] = (br[i] * inv + neighbourSum<D, T>(s, wa, xr, i, i - 1, i + 1, wa[0][i - 1])) * rd(i);
    };
    // The row's uniform span (one weight wu, one c): the same sums without
    // the weight loads, four or eight cells at a time in float.
    auto uniform = [&](const Span& span, auto weighted) {
      constexpr bool W = decltype(weighted)::value;
      const size_t hi = span.hi;
      if (span.lo >= hi) return;
      const T r0 = rd(span.lo), wu = T(span.w);
      if constexpr (std::is_same_v<T, float>) {
        // The colour's last cells of the span in one more block, placed to
        // end at the span's end: the cells it repeats get the same values
        // again (a cell's update reads the other colour only).
        const size_t first = i;
        auto lastBlock = [&](size_t cells) {
          const size_t j = hi - (cells - 1);
          return j - ((j - first) & 1);
        };
#if MORPHOFLOW_AVX2_KERNELS
        if (wide) {
          i = sweepUniform8<D, W>(s, br, xr, i, hi, inv, r0, wu, shared);
          if (i < hi && hi >= first + 15) i = sweepUniform8<D, W>(s, br, xr, lastBlock(16), hi, inv, r0, wu, shared);
        }
#endif
        i = sweepUniform4<D, W>(s, br, xr, i, hi, inv, r0, wu, shared);
        if (i < hi && hi >= first + 7) i = sweepUniform4<D, W>(s, br, xr, lastBlock(8), hi, inv, r0, wu, shared);
      }
      for (; i < hi; i += 2) xr[i] = (br[i] * inv + neighbourSumUniform<D, W, T>(s, xr, i, wu)) * r0;
    };
    const Span& span = sweepSpan_[row];
    general(std::min(size_t(span.lo), nx - 1));
    if (span.w == 1.0f)
      uniform(span, std::false_type{});
    else
      uniform(span, std::true_type{});
    general(nx - 1);
    if (i + 1 == nx && nx > 1) edge(i);
  };
  const int first = reverse ? 1 : 0, second = 1 - first;
  const size_t ny = size_t(dims[1]);
  if (serial) {
    for (int colour : {first, second})
      for (size_t r = 0; r < rows; ++r) sweepRow(r, r % ny, D == 3 ? r / ny : 0, colour, false);
    return;
  }
  // Both colours in one pass over memory: planes (rows in 2D) along the last
  // axis are cut into slabs, and a slab updates the first colour on plane p,
  // then the second on plane p - 1, whose neighbours then all hold the first
  // colour's new values. The second colour on a slab's first and last planes
  // waits for the neighbouring slabs' first colour (a second, short loop).
  // A cell's update reads the other colour only, so any order and any cut
  // give bitwise the sweep of two whole passes. Where another slab may be
  // reading a plane's other colour at the same time (a slab's first and
  // last planes), the vector kernels store the updated colour's cells only,
  // so no cell is ever written while another task reads it.
  const size_t planes = size_t(dims[D - 1]), rowsPerPlane = rows / planes;
  auto plane = [&](size_t p, int colour, bool shared) {
    if constexpr (D == 2)
      sweepRow(p, p, 0, colour, shared);
    else
      for (size_t y = 0; y < ny; ++y) sweepRow(p * rowsPerPlane + y, y, p, colour, shared);
  };
  // Slabs of at least kSlabPlanes planes and kSlabCells cells, a few per thread.
  const size_t slabs = std::max<size_t>(
      1, std::min({4 * size_t(hardwareThreads()), planes / kSlabPlanes, size() / kSlabCells}));
  auto slabBegin = [&](size_t j) { return j * planes / slabs; };
  parallelFor(slabs, [&](size_t j) {
    const size_t lo = slabBegin(j), hi = slabBegin(j + 1);
    for (size_t p = lo; p < hi; ++p) {
      plane(p, first, slabs > 1 && (p == lo || p + 1 == hi));
      if (p >= lo + 2) plane(p - 1, second, false);
    }
  });
  parallelFor(slabs, [&](size_t j) {
    const size_t lo = slabBegin(j), hi = slabBegin(j + 1);
    plane(lo, second, slabs > 1);
    if (hi - 1 > lo) plane(hi - 1, second, slabs > 1);
  });
}

template <int D>
bool LaplaceSystem<D>::coloursMeetAcrossRows() const {
  for (int a = 1; a < D; ++a)
    if (periodic[a] && dims[a] % 2 == 1) return true;
  return false;
}

template <int D>
void LaplaceSystem<D>::relaxBox(const Vector& b, Vector* xp, const IVec<D>& lo, const IVec<D>& hi, int sweeps,
                                double omega) const {
  if (boxEmpty<D>(lo, hi)) return;
  Vector& x = *xp;
  const size_t nx = size_t(dims[0]), ny = size_t(dims[1]);
  const bool px = periodic[0];
  const double inv = 1.0 / scale;
  const bool serial = coloursMeetAcrossRows();
  const std::vector<size_t> rows = rowsOf<D>(dims, lo, hi);
  auto sweepRow = [&](size_t row, int colour) {
    const size_t y = row % ny, z = D == 3 ? row / ny : 0;
    const RowStencil<D, double> s = rowStencil<D, double>(*this, x.data(), zeros<double>(), zerosW_.data(), row, y, z);
    const float* wa[D];
    for (int a = 0; a < D; ++a) wa[a] = w[a].row(row);
    const float* dr = diag.row(row);
    const double* br = b.data() + s.base;
    double* xr = x.data() + s.base;
    // x_i = (b_i / scale + sum_f w_f x_j) / diag_i on active cells of the colour.
    // (the colour's cells: every other one from the first of the colour)
    for (size_t i = size_t(lo[0]) + (size_t(lo[0]) + y + z + size_t(colour)) % 2; i < size_t(hi[0]); i += 2) {
      if (!(dr[i] > 0.0f)) continue;
      const size_t il = i == 0 ? nx - 1 : i - 1, ih = i + 1 == nx ? 0 : i + 1;
      const float wl = (i == 0 && !px) ? 0.0f : wa[0][il];
      const double gs = (br[i] * inv + neighbourSum<D, double>(s, wa, xr, i, il, ih, wl)) * double(inverse(dr[i]));
      xr[i] = omega == 1.0 ? gs : xr[i] + omega * (gs - xr[i]);
    }
  };
  for (int sweep = 0; sweep < sweeps; ++sweep)
    for (int colour = 0; colour < 2; ++colour) {
      if (serial) {
        for (size_t row : rows) sweepRow(row, colour);
      } else {
        parallelFor(
            rows.size(), [&](size_t k) { sweepRow(rows[k], colour); }, 16);
      }
    }
}

template <int D>
void LaplaceSystem<D>::removeNullSpace(Vector* xp) const {
  Vector& x = *xp;
  if (active_ == 0) return;
  const size_t nx = size_t(dims[0]);
  const double mean = deterministicRowSum<D>(dims, [&](size_t row) {
    const float* d = diag.row(row);
    const double* xr = x.data() + row * nx;
    double s = 0.0;
    for (size_t i = 0; i < nx; ++i) s += d[i] > 0 ? xr[i] : 0.0;
    return s;
  }) / double(active_);
  parallelForRows<D>(dims, [&](size_t row) {
    const float* d = diag.row(row);
    double* xr = x.data() + row * nx;
    for (size_t i = 0; i < nx; ++i) xr[i] = d[i] > 0 ? xr[i] - mean : 0.0;
  });
}

template <int D>
LaplaceSystem<D> makeNeumannLaplacian(const IVec<D>& dims, const std::array<bool, D>& periodic,
                                      double h) {
  LaplaceSystem<D> s(dims, periodic, 1.0 / (h * h));
  for (int a = 0; a < D; ++a) s.w[a].fill(1.0f);
  s.finalize();
  return s;
}

double dot(const Vector& a, const Vector& b) {
  return deterministicSum(a.size(), [&](size_t i) { return a[i] * b[i]; });
}
double norm2(const Vector& a) { return std::sqrt(dot(a, a)); }
void axpy(double alpha, const Vector& x, Vector* y) {
  Vector& yy = *y;
  parallelFor(x.size(), [&](size_t i) { yy[i] += alpha * x[i]; }, 4096);
}

template struct LaplaceSystem<2>;
template struct LaplaceSystem<3>;
#define MORPHOFLOW_LAPLACE_KERNELS(D, T)                                                  \
  template void LaplaceSystem<D>::apply<T>(const std::vector<T>&, std::vector<T>*) const; \
  template void LaplaceSystem<D>::defect<T>(const T*, const T*, T*) const;                \
  template void LaplaceSystem<D>::gaussSeidel<T>(const T*, T*, bool) const;
MORPHOFLOW_LAPLACE_KERNELS(2, double)
MORPHOFLOW_LAPLACE_KERNELS(3, double)
MORPHOFLOW_LAPLACE_KERNELS(2, float)
MORPHOFLOW_LAPLACE_KERNELS(3, float)
#undef MORPHOFLOW_LAPLACE_KERNELS
template LaplaceSystem<2> makeNeumannLaplacian<2>(const IVec<2>&, const std::array<bool, 2>&, double);
template LaplaceSystem<3> makeNeumannLaplacian<3>(const IVec<3>&, const std::array<bool, 3>&, double);

}  // namespace morphoflow
