#include "rd/fused_explicit.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include <tbb/enumerable_thread_specific.h>

#include "core/parallel.h"
#include "core/simd_dispatch.h"
#include "rd/models.h"
#include "rd/newton_batch.h"

#pragma GCC diagnostic ignored "-Wpsabi"  // 32-byte lanes passed between always-inline helpers only

namespace morphoflow {

namespace {

typedef float vf4x __attribute__((vector_size(16)));
typedef float vf8x __attribute__((vector_size(32)));
typedef float vf16x __attribute__((vector_size(64)));  // one AVX-512 register (used in avx512 targets only)
// The same with float alignment, for unaligned loads and stores that stay
// typed as float (a memcpy would let the compiler assume a store may change
// the loop's constants, and reload them every iteration).
typedef float vf4u __attribute__((vector_size(16), aligned(4)));
typedef float vf8u __attribute__((vector_size(32), aligned(4)));
typedef float vf16u __attribute__((vector_size(64), aligned(4)));

// Float lanes for the models whose rates are plain arithmetic: every double
// (a parameter, a constant) is rounded to float first and every operation is
// a float one, so one lane and eight give the same bits.
template <class V>
struct FL {
  V v;
  FL() : v{} {}
  FL(V x) : v(x) {}
  FL(double d) : v(V{} + float(d)) {}
};
template <class V> MF_INLINE FL<V> operator+(FL<V> a, FL<V> b) { return FL<V>(a.v + b.v); }
template <class V> MF_INLINE FL<V> operator-(FL<V> a, FL<V> b) { return FL<V>(a.v - b.v); }
template <class V> MF_INLINE FL<V> operator*(FL<V> a, FL<V> b) { return FL<V>(a.v * b.v); }
template <class V> MF_INLINE FL<V> operator/(FL<V> a, FL<V> b) { return FL<V>(a.v / b.v); }
template <class V> MF_INLINE FL<V> operator-(FL<V> a) { return FL<V>(-a.v); }
template <class V> MF_INLINE FL<V> operator+(FL<V> a, double b) { return a + FL<V>(b); }
template <class V> MF_INLINE FL<V> operator-(FL<V> a, double b) { return a - FL<V>(b); }
template <class V> MF_INLINE FL<V> operator*(FL<V> a, double b) { return a * FL<V>(b); }
template <class V> MF_INLINE FL<V> operator/(FL<V> a, double b) { return a / FL<V>(b); }
template <class V> MF_INLINE FL<V> operator+(double a, FL<V> b) { return FL<V>(a) + b; }
template <class V> MF_INLINE FL<V> operator-(double a, FL<V> b) { return FL<V>(a) - b; }
template <class V> MF_INLINE FL<V> operator*(double a, FL<V> b) { return FL<V>(a) * b; }
template <class V> MF_INLINE FL<V> operator/(double a, FL<V> b) { return FL<V>(a) / b; }


// The models whose rates take float lanes (no comparisons in them).
template <class M>
constexpr bool kFloatLanes =
    std::is_same_v<M, models::Turing> || std::is_same_v<M, models::TuringSanderson> ||
    std::is_same_v<M, models::GrayScott> || std::is_same_v<M, models::GrayScottSanderson> ||
    std::is_same_v<M, models::FitzHughNagumo> || std::is_same_v<M, models::Barkley> ||
    std::is_same_v<M, models::BarkleyTurbulent> || std::is_same_v<M, models::Brusselator>;

MF_INLINE double load(const float* p, double) { return double(*p); }
MF_INLINE NewtonLanes load(const float* p, NewtonLanes) {
  return __builtin_convertvector(vf4x(*reinterpret_cast<const vf4u*>(p)), NewtonLanes);
}
MF_INLINE FL<float> load(const float* p, FL<float>) { return FL<float>(*p); }
MF_INLINE FL<vf4x> load(const float* p, FL<vf4x>) { return FL<vf4x>(vf4x(*reinterpret_cast<const vf4u*>(p))); }
MF_INLINE FL<vf8x> load(const float* p, FL<vf8x>) { return FL<vf8x>(vf8x(*reinterpret_cast<const vf8u*>(p))); }
MF_INLINE FL<vf16x> load(const float* p, FL<vf16x>) { return FL<vf16x>(vf16x(*reinterpret_cast<const vf16u*>(p))); }
MF_INLINE void store(float* p, double v) { *p = float(v); }
MF_INLINE void store(float* p, NewtonLanes v) { *reinterpret_cast<vf4u*>(p) = __builtin_convertvector(v, vf4x); }
MF_INLINE void store(float* p, FL<float> v) { *p = v.v; }
MF_INLINE void store(float* p, FL<vf4x> v) { *reinterpret_cast<vf4u*>(p) = v.v; }
MF_INLINE void store(float* p, FL<vf8x> v) { *reinterpret_cast<vf8u*>(p) = v.v; }
MF_INLINE void store(float* p, FL<vf16x> v) { *reinterpret_cast<vf16u*>(p) = v.v; }
// max(v, 0) as the comparison v < 0 picks it (a NaN stays NaN).
MF_INLINE double clampZero(double v) { return v < 0.0 ? 0.0 : v; }
MF_INLINE NewtonLanes clampZero(NewtonLanes v) { return v < 0.0 ? NewtonLanes{} : v; }
MF_INLINE FL<float> clampZero(FL<float> v) { return FL<float>(v.v < 0.0f ? 0.0f : v.v); }
template <class V>
MF_INLINE FL<V> clampZero(FL<V> v) {
  return FL<V>(v.v < 0.0f ? V{} : v.v);
}

template <class L>
constexpr int lanes() {
  if constexpr (std::is_same_v<L, double> || std::is_same_v<L, FL<float>>) return 1;
  else if constexpr (std::is_same_v<L, NewtonLanes>) return 4;
  else return int(sizeof(L) / sizeof(float));
}
// The lane family of a model: float lanes where its rates allow, else doubles.
template <class M>
using Scalar = std::conditional_t<kFloatLanes<M>, FL<float>, double>;

// The rows a cell's stencil reads: its own and its neighbours along y (and
// z), wrapped or (zero flux) the row itself at a wall, per species.
template <int D, int N>
struct RowJob {
  const float* c[N];
  const float* nb[N][2 * (D - 1)];
  float* out[N];
  int nx;
  bool periodic;
  double dt, kd[N];  // d / h^2 for the Laplacian, d for the 5 x 5 kernel (in physical units)
  const double* p;
  unsigned clamped;  // bit per species
  unsigned kernel;   // bit per species diffusing by the 5 x 5 kernel (2D)
  const float* krow[N][5];  // its rows y - 2 .. y + 2
  double tw[25];             // its weights, row-major (dy, then dx)
};

// The kernel's weights as lanes, converted once per row.
template <class L, int D, int N>
MF_INLINE void laneWeights(const RowJob<D, N>& j, L* w) {
  for (int t = 0; t < 25; ++t) w[t] = L{} + j.tw[t];  // (L{} + d: a splat for every lane type)
}

// One 5 x 5 convolution (seed 000 eq. 37) of rows y - 2 .. y + 2: one sum
// per kernel row, then the five together: short dependency chains (a single
// running sum of 25 taps would wait on the add latency), in the same order at
// every width.
template <class L, class At>
MF_INLINE L kernel5(const float* const* rows, const L* w, At at) {
  L acc[5];
#pragma GCC unroll 5
  for (int dy = 0; dy < 5; ++dy) {
    acc[dy] = w[5 * dy] * at(rows[dy], -2);
#pragma GCC unroll 4
    for (int dx = 1; dx < 5; ++dx) acc[dy] = acc[dy] + w[5 * dy + dx] * at(rows[dy], dx - 2);
  }
  return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + acc[4];
}

// Species s's diffusion term at cells x, x + 1, ... (L's lanes at a time);
// at(row, dx) reads a row at x + dx.
template <int D, int N, class L, bool K, class At>
MF_INLINE L laplacian(const RowJob<D, N>& j, int s, const L* w, At at) {
  if (K && (j.kernel >> s & 1u)) return kernel5(j.krow[s], w, at);  // seed 000 eq. 37
  L lap = at(j.c[s], -1) + at(j.c[s], 1);
  for (int k = 0; k < 2 * (D - 1); ++k) lap = lap + at(j.nb[s][k], 0);
  return lap - double(2 * D) * at(j.c[s], 0);
}

// The Euler update of cells x, x + 1, ... from their diffusion terms (seed 000 eq. 27).
template <class M, int D, class L, class At>
MF_INLINE void update(const RowJob<D, M::N>& j, int x, const L* lap, At at) {
  constexpr int N = M::N;
  L c[N], r[N];
  for (int s = 0; s < N; ++s) c[s] = at(j.c[s], 0);
  M::rates(c, j.p, r);  // the model's own rates (rd/models.h)
  for (int s = 0; s < N; ++s) {
    L v = c[s] + j.dt * (r[s] + j.kd[s] * lap[s]);
    if (j.clamped >> s & 1u) v = clampZero(v);  // the model's clamped species (e.g. Turing's b)
    store(j.out[s] + x, v);
  }
}

template <class M, int D, class L, bool K, class At>
MF_INLINE void cellsAt(const RowJob<D, M::N>& j, int x, const L* w, At at) {
  L lap[M::N];
  for (int s = 0; s < M::N; ++s) lap[s] = laplacian<D, M::N, L, K>(j, s, w, at);
  update<M, D>(j, x, lap, at);
}

// Local copies of a row's job: nothing the loops store can change them, so they stay in registers.
template <class M, int D>
struct LocalJob {
  RowJob<D, M::N> j;
  double p[M::P > 0 ? M::P : 1];
  explicit LocalJob(const RowJob<D, M::N>& job) : j(job) {
    for (int k = 0; k < M::P; ++k) p[k] = job.p[k];
    j.p = p;
  }
};

template <class M, int D, class L>
MF_INLINE int interior(const RowJob<D, M::N>& job, int x, int end) {
  constexpr int n = lanes<L>();
  LocalJob<M, D> local(job);
  const RowJob<D, M::N>& j = local.j;
  for (; x + n <= end; x += n)
    cellsAt<M, D, L, false>(j, x, nullptr, [&](const float* row, int dx) { return load(row + x + dx, L()); });
  return x;
}

// With the 5 x 5 kernel: a chunk of the row at a time, each species' kernel
// over the whole chunk first (few pointers live, so none spills), then the
// updates from the kept terms. The same operations per cell as cellsAt.
template <class M, int D, class L>
MF_INLINE int interiorKernel(const RowJob<D, M::N>& job, int x, int end) {
  constexpr int N = M::N, n = lanes<L>(), kChunk = 32;  // vectors of n cells per chunk
  LocalJob<M, D> local(job);
  const RowJob<D, N>& j = local.j;
  L w[25];
  laneWeights<L>(j, w);
  L lap[kChunk][N];
  while (x + n <= end) {
    const int count = std::min(kChunk, (end - x) / n);
    for (int s = 0; s < N; ++s) {
      if (!(j.kernel >> s & 1u)) {
        for (int k = 0; k < count; ++k) {
          const int xk = x + k * n;
          lap[k][s] =
              laplacian<D, N, L, false>(j, s, w, [&](const float* row, int dx) { return load(row + xk + dx, L()); });
        }
        continue;
      }
      // Row pointers that step with the cells: each load is one pointer and a constant offset.
      const float* rows[5];
      for (int dy = 0; dy < 5; ++dy) rows[dy] = j.krow[s][dy] + x;
      for (int k = 0; k < count; ++k) {
        lap[k][s] = kernel5(rows, w, [](const float* row, int dx) { return load(row + dx, L()); });
        for (int dy = 0; dy < 5; ++dy) rows[dy] += n;
      }
    }
    for (int k = 0; k < count; ++k, x += n)
      update<M, D>(j, x, lap[k], [&](const float* row, int dx) { return load(row + x + dx, L()); });
  }
  return x;
}

template <class M, int D, class L, bool K>
MF_INLINE int interiorOf(const RowJob<D, M::N>& j, int x, int end) {
  if constexpr (K) return interiorKernel<M, D, L>(j, x, end);
  else return interior<M, D, L>(j, x, end);
}

// The row's cells from x on, in the widest lanes that fit (returns the first left).
template <class M, int D, bool K>
int interiorSse(const RowJob<D, M::N>& j, int x, int end) {
  if constexpr (kFloatLanes<M>) return interiorOf<M, D, FL<vf4x>, K>(j, x, end);
  else return interiorOf<M, D, NewtonLanes, K>(j, x, end);
}
#if MORPHOFLOW_AVX2_KERNELS
template <class M, int D, bool K>
__attribute__((target("avx2"))) int interiorAvx2(const RowJob<D, M::N>& j, int x, int end) {
  if constexpr (kFloatLanes<M>) x = interiorOf<M, D, FL<vf8x>, K>(j, x, end);
  return interiorOf<M, D, std::conditional_t<kFloatLanes<M>, FL<vf4x>, NewtonLanes>, K>(j, x, end);
}
// The 5 x 5 kernel in sixteen lanes: its weights fit AVX-512's 32 registers.
template <class M, int D>
__attribute__((target("avx2,avx512f,avx512vl"))) int interiorAvx512(const RowJob<D, M::N>& j, int x, int end) {
  if constexpr (kFloatLanes<M>) x = interiorKernel<M, D, FL<vf16x>>(j, x, end);
  return interiorAvx2<M, D, true>(j, x, end);
}
#endif

// One cell by the scalar code, its x neighbours wrapped or mirrored at the row's ends.
template <class M, int D>
void edgeCell(const RowJob<D, M::N>& j, int x) {
  using L = Scalar<M>;
  L w[25];
  laneWeights<L>(j, w);
  cellsAt<M, D, L, true>(j, x, w, [&](const float* row, int dx) {
    int q = x + dx;
    if (q < 0 || q >= j.nx) q = j.periodic ? (q % j.nx + j.nx) % j.nx : std::clamp(q, 0, j.nx - 1);
    return load(row + q, L());
  });
}

template <class M>
constexpr bool kLaneRates = M::N == 2 && requires(const NewtonLanes* y, const double* q, NewtonLanes* r) {
  M::rates(y, q, r);
};
static_assert(!kFloatLanes<models::MeinhardtLateral>);

template <int D, class M>
class Engine final : public FusedExplicitRD<D> {
  static constexpr int N = M::N;

 public:
  Engine(const IVec<D>& cells, double h, bool periodic, const std::vector<double>& d, const std::vector<double>& p)
      : h_(h), periodic_(periodic), d_(d), p_(p) {
    this->cells_ = cells;
    size_t n = 1;
    for (int a = 0; a < D; ++a) n *= size_t(cells[a]);
    const ModelInfo info = M::info();
    this->x_.assign(N, std::vector<float>(n, 0.0f));
    this->next_ = this->x_;
    for (int s : info.clamped) clamped_ |= 1u << s;
    if (p_.empty())
      for (const ParameterInfo& q : info.parameters) p_.push_back(q.value);
    if (d_.empty()) d_ = info.diffusion;
  }

  void setKernel(const std::array<std::array<double, 5>, 5>& kernel, const std::vector<int>& species) override {
    if (D != 2 || !periodic_) throw std::invalid_argument("the 5 x 5 kernel is for periodic 2D layers");
    kernel_ = kernel;
    kernelSpecies_ = 0;
    for (int s = 0; s < N; ++s)
      if (species.empty() || std::find(species.begin(), species.end(), s) != species.end()) kernelSpecies_ |= 1u << s;
  }

  void step(double dt, int steps) override {
    for (int done = 0; done < steps;) {
      const int k = std::min(steps - done, stepsPerPass());
      if (k == 1) singleStep(dt);
      else blockedPass(dt, k);
      done += k;
    }
  }

 private:
  int outer() const { return this->cells_[D - 1]; }
  size_t sliceCells() const {
    return D == 2 ? size_t(this->cells_[0]) : size_t(this->cells_[0]) * size_t(this->cells_[1]);
  }
  int reach() const { return kernelSpecies_ ? 2 : 1; }  // the stencil's reach along the outer axis
  static int wrap(int q, int n) { return (q % n + n) % n; }
  // Outer slice q's neighbour on `side` (a wall: q itself; periodic: unwrapped).
  int outerNeighbour(int q, int side) const {
    const int p = q + side;
    return !periodic_ && (p < 0 || p >= outer()) ? q : p;
  }
  // Outer slice q of the current state (q unwrapped where periodic).
  const float* stateSlice(int s, int q) const {
    return this->x_[size_t(s)].data() + size_t(periodic_ ? wrap(q, outer()) : q) * sliceCells();
  }

  // Steps per pass: the setting, or several where the state (x_ and next_)
  // outgrows the L3 (measured on the 2-core machine of docs/performance.md:
  // blocking gains 1.4-1.6x at 2048^2 and 1.1x at 256^3, and loses 10-20% at
  // 1024^2 and 128^3, which stay in its 32 MiB L3).
  int stepsPerPass() const override {
    if (this->stepsPerPass_ > 0) return this->stepsPerPass_;
    const double stateBytes = 2.0 * N * sizeof(float) * double(sliceCells()) * outer();
    return stateBytes <= kCachedState ? 1 : D == 2 ? 8 : 4;
  }
  static constexpr double kCachedState = 32.0 * (1 << 20);
  // Outer slices per task of a blocked pass: the halo each recomputes,
  // R (steps - 1) on each side, against 128 R rows in 2D or 32 planes in 3D.
  int slabSlices() const {
    if (this->slicesPerTask_ > 0) return int(this->slicesPerTask_);
    return D == 2 ? 128 * reach() : 32;
  }

  // Row y of outer slice q (in 2D the row q itself) from the slices in(s, q')
  // return, into out[s] (slice q's start): the same job as every other path.
  template <class In>
  void runRow(int y, int q, double dt, const In& in, float* const* out, [[maybe_unused]] bool wide) const {
    const int nx = this->cells_[0];
    RowJob<D, N> j;
    j.nx = nx;
    j.periodic = periodic_;
    j.dt = dt;
    j.p = p_.data();
    j.clamped = clamped_;
    j.kernel = kernelSpecies_;
    for (int t = 0; t < 25; ++t) j.tw[t] = kernel_[size_t(t / 5)][size_t(t % 5)];
    for (int s = 0; s < N; ++s) {
      j.kd[s] = d_[size_t(s)] / ((kernelSpecies_ >> s & 1u) ? 1.0 : h_ * h_);
      const float* slice = in(s, q);
      if constexpr (D == 2) {
        j.c[s] = slice;
        for (int side = 0; side < 2; ++side) j.nb[s][side] = in(s, outerNeighbour(q, side ? 1 : -1));
        if (kernelSpecies_)  // (periodic only: setKernel refuses walls)
          for (int dy = -2; dy <= 2; ++dy) j.krow[s][dy + 2] = in(s, q + dy);
        j.out[s] = out[s];
      } else {
        const int ny = this->cells_[1];
        j.c[s] = slice + size_t(y) * size_t(nx);
        for (int side = 0; side < 2; ++side) {
          int p = y + (side ? 1 : -1);
          if (p < 0 || p >= ny) p = periodic_ ? wrap(p, ny) : y;
          j.nb[s][side] = slice + size_t(p) * size_t(nx);
          j.nb[s][2 + side] = in(s, outerNeighbour(q, side ? 1 : -1)) + size_t(y) * size_t(nx);
        }
        j.out[s] = out[s] + size_t(y) * size_t(nx);
      }
    }
    // The cells whose stencil leaves the row take the scalar code with wrapped (or mirrored) neighbours.
    const int reachX = std::min(kernelSpecies_ ? 2 : 1, nx);
    for (int x = 0; x < reachX; ++x) edgeCell<M, D>(j, x);
    const int end = std::max(reachX, nx - reachX);
    const int x = kernelSpecies_ ? interiorRow<true>(j, reachX, end, wide) : interiorRow<false>(j, reachX, end, wide);
    for (int e = std::max(x, end); e < nx; ++e) edgeCell<M, D>(j, e);
  }

  // One step, row by row.
  void singleStep(double dt) {
    const size_t rows = D == 2 ? size_t(outer()) : size_t(outer()) * size_t(this->cells_[1]);
    const bool wide = useAvx2();
    auto row = [&](size_t r) {
      const int y = D == 2 ? 0 : int(r % size_t(this->cells_[1])),
                q = D == 2 ? int(r) : int(r / size_t(this->cells_[1]));
      float* out[N];
      for (int s = 0; s < N; ++s) out[s] = this->next_[size_t(s)].data() + size_t(q) * sliceCells();
      runRow(y, q, dt, [this](int s, int p) { return stateSlice(s, p); }, out, wide);
    };
    if (this->rowsPerTask_ > 0) {
      const size_t per = this->rowsPerTask_;
      parallelFor((rows + per - 1) / per, [&](size_t t) {
        for (size_t r = t * per; r < std::min(rows, (t + 1) * per); ++r) row(r);
      });
    } else {
      parallelFor(rows, row, rowGrain<D>(this->cells_));
    }
    std::swap(this->x_, this->next_);
  }

  // Temporal blocking: `steps` steps in one pass. Each task owns a slab of
  // outer slices [a, b) and sweeps a front along it; at front i, step k
  // computes slice i - R (k - 1) (R the stencil's reach) from step k - 1's
  // slices, which a ring of 2R + 1 slices per step holds, so a slab's steps
  // run while its slices are in cache. The slab's last step is written to the
  // next state; its earlier steps reach R (steps - k) slices past the slab's
  // ends (computed again by the neighbouring task). Every slice is computed
  // by runRow from the same inputs as a single step's, so the fields are
  // bitwise those of `steps` single steps.
  void blockedPass(double dt, int steps) {
    const int n = outer(), R = reach(), W = 2 * R + 1;
    const int slab = slabSlices();
    const size_t tasks = size_t((n + slab - 1) / slab), S = sliceCells();
    const bool wide = useAvx2();
    parallelFor(tasks, [&](size_t t) {
      const int a = int(t) * slab, b = std::min(n, a + slab);
      std::vector<float>& ring = rings_.local();  // (a task reads only the slices it wrote)
      // Slices 64 bytes longer than the field's: rows of a power-of-two
      // length would otherwise all fall on the same cache sets.
      const size_t stride = S + 16;
      ring.resize(size_t(steps - 1) * size_t(W) * N * stride);
      // Step k's slice q in the ring (1 <= k < steps), species s.
      auto ringSlice = [&](int k, int s, int q) {
        return ring.data() + ((size_t(k - 1) * size_t(W) + size_t(wrap(q, W))) * N + size_t(s)) * stride;
      };
      for (int i = a - R * (steps - 1); i < b + R * (steps - 1); ++i)
        for (int k = 1; k <= steps; ++k) {
          const int q = i - R * (k - 1), halo = R * (steps - k);
          if (q < (periodic_ ? a - halo : std::max(a - halo, 0)) || q >= (periodic_ ? b + halo : std::min(b + halo, n)))
            continue;
          float* out[N];
          for (int s = 0; s < N; ++s)
            out[s] = k == steps ? this->next_[size_t(s)].data() + size_t(q) * S : ringSlice(k, s, q);
          auto in = [&](int s, int p) -> const float* { return k == 1 ? stateSlice(s, p) : ringSlice(k - 1, s, p); };
          for (int y = 0; y < (D == 2 ? 1 : this->cells_[1]); ++y) runRow(y, q, dt, in, out, wide);
        }
    });
    std::swap(this->x_, this->next_);
  }

  // Cells [x, end) of a row: the widest lanes, then one at a time; K: some species take the 5 x 5 kernel.
  template <bool K>
  static int interiorRow(const RowJob<D, N>& j, int x, int end, [[maybe_unused]] bool wide) {
    if constexpr (kLaneRates<M>) {
#if MORPHOFLOW_AVX2_KERNELS
      if (wide && K && useAvx512()) x = interiorAvx512<M, D>(j, x, end);
      if (wide) x = interiorAvx2<M, D, K>(j, x, end);
#endif
      x = interiorSse<M, D, K>(j, x, end);
    }
    return interiorOf<M, D, Scalar<M>, K>(j, x, end);
  }

  double h_;
  bool periodic_;
  std::vector<double> d_, p_;
  unsigned clamped_ = 0, kernelSpecies_ = 0;
  std::array<std::array<double, 5>, 5> kernel_{};
  tbb::enumerable_thread_specific<std::vector<float>> rings_;  // per thread: a blocked pass's steps' slices
};

template <int D, class M>
std::unique_ptr<FusedExplicitRD<D>> make(const std::string& model, const IVec<D>& cells, double h, bool periodic,
                                         const std::vector<double>& d, const std::vector<double>& p) {
  if (model != M::info().name) return nullptr;
  return std::make_unique<Engine<D, M>>(cells, h, periodic, d, p);
}

}  // namespace

template <int D>
std::unique_ptr<FusedExplicitRD<D>> FusedExplicitRD<D>::create(const std::string& model, const IVec<D>& cells, double h,
                                                               bool periodic, const std::vector<double>& d,
                                                               const std::vector<double>& p) {
  std::unique_ptr<FusedExplicitRD<D>> e;
  models::forEach([&](auto tag) {
    using M = typename decltype(tag)::type;
    if (!e) e = make<D, M>(model, cells, h, periodic, d, p);
  });
  return e;
}

template class FusedExplicitRD<2>;
template class FusedExplicitRD<3>;

}  // namespace morphoflow
