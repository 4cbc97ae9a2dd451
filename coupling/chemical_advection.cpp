#include "coupling/chemical_advection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/parallel.h"
#include "core/sampling.h"
#include "core/simd_dispatch.h"
#include "coupling/ard_step.h"
#include "coupling/bspline.h"
#include "coupling/interpolation_weights.h"
#include "fluid/advection.h"

#if MORPHOFLOW_AVX2_KERNELS
#include <immintrin.h>
#endif

namespace morphoflow {

namespace {

// Sample indices and weights along one axis: linear uses 2 (from k = 1),
// cubic 4 (k = 0..3 at i - 1 .. i + 2).
struct AxisWeights {
  int index[4];
  double w[4];
  int first, count;
};

AxisWeights axisWeights(double c, int n, bool periodic, ChemicalInterpolation interp) {
  AxisWeights a{};
  c = boundedCoordinate(c);
  if (!periodic) c = std::clamp(c, 0.0, double(n - 1));
  const double f = std::floor(c), t = c - f;
  const int i = int(f);
  for (int k = 0; k < 4; ++k) {
    int j = i - 1 + k;
    a.index[k] = periodic ? ((j % n) + n) % n : std::clamp(j, 0, n - 1);
  }
  if (interp == ChemicalInterpolation::Linear) {
    a.first = 1, a.count = 2;
    a.w[1] = 1.0 - t, a.w[2] = t;
  } else {
    a.first = 0, a.count = 4;
    catmullRomWeights(t, a.w);
  }
  return a;
}

// The linear case of sampleChemical without the four-entry tables: the same
// indices, weights and summation order, so bitwise the same value.
struct LinearAxis {
  size_t lo, hi;
  double wlo, whi;
};
inline LinearAxis linearAxis(double c, int n, bool periodic) {
  c = boundedCoordinate(c);
  if (!periodic) c = std::clamp(c, 0.0, double(n - 1));
  const double f = std::floor(c), t = c - f;
  const int i = int(f);
  if (periodic) return {size_t(((i % n) + n) % n), size_t((((i + 1) % n) + n) % n), 1.0 - t, t};
  return {size_t(i), size_t(std::min(i + 1, n - 1)), 1.0 - t, t};
}

// The 2^D cells and weights of the linear sample at c, in sampleChemical's
// order (x fastest), each weight the product wx wy (wz) in that order: so
// sum_k w_k g[i_k] is bitwise the general sampler's linear value.
template <int D>
void linearStencil(const IVec<D>& dims, const std::array<bool, D>& periodic, const Vec<D>& c,
                   size_t (&index)[1 << D], double (&weight)[1 << D]) {
  LinearAxis ax[D];
  for (int a = 0; a < D; ++a) ax[a] = linearAxis(c[a], dims[a], periodic[size_t(a)]);
  const size_t nx = size_t(dims[0]);
  const size_t y[2] = {nx * ax[1].lo, nx * ax[1].hi};
  const double wy[2] = {ax[1].wlo, ax[1].whi};
  const size_t x[2] = {ax[0].lo, ax[0].hi};
  const double wx[2] = {ax[0].wlo, ax[0].whi};
  if constexpr (D == 2) {
    for (int ky = 0; ky < 2; ++ky)
      for (int kx = 0; kx < 2; ++kx) {
        index[2 * ky + kx] = x[kx] + y[ky];
        weight[2 * ky + kx] = wx[kx] * wy[ky];
      }
  } else {
    const size_t plane = nx * size_t(dims[1]);
    const size_t z[2] = {plane * ax[2].lo, plane * ax[2].hi};
    const double wz[2] = {ax[2].wlo, ax[2].whi};
    for (int kz = 0; kz < 2; ++kz)
      for (int ky = 0; ky < 2; ++ky)
        for (int kx = 0; kx < 2; ++kx) {
          index[4 * kz + 2 * ky + kx] = x[kx] + y[ky] + z[kz];
          weight[4 * kz + 2 * ky + kx] = wx[kx] * wy[ky] * wz[kz];
        }
  }
}

// Every species' linear samples for the cells of a run: the arguments of
// ChemicalAdvector::advect's cell loop.
template <int D>
struct LinearRun {
  IVec<D> dims;
  std::array<const float*, D> feet;
  const double* fromInflow;  // null: no inflow sides
  const double* in;          // per species
  const double* const* src;
  double* const* dst;
  size_t species;
};

#if MORPHOFLOW_AVX2_KERNELS
// linearStencil and the weighted sums for four cells at a time, each lane
// with the scalar code's operations in its order (no FMA), the 2^D samples
// per species gathered: bitwise the scalar loop's values. Walls only (no
// periodic axis) and int32 cell indices. Returns the first cell not done.
template <int D>
__attribute__((target("avx2"))) size_t linearRunAvx2(const LinearRun<D>& r, size_t i, size_t end) {
  __m128i lo[D], hi[D];
  __m256d wlo[D], whi[D];
  for (; i + 4 <= end; i += 4) {
    for (int a = 0; a < D; ++a) {
      // linearAxis: c clamped to [0, n - 1], i = floor, hi = min(i + 1, n - 1).
      const __m256d top = _mm256_set1_pd(double(r.dims[a] - 1)), zero = _mm256_setzero_pd();
      __m256d c = _mm256_cvtps_pd(_mm_loadu_ps(r.feet[size_t(a)] + i));
      c = _mm256_blendv_pd(c, top, _mm256_cmp_pd(top, c, _CMP_LT_OQ));
      c = _mm256_max_pd(c, zero);  // (a NaN foot becomes 0, as boundedCoordinate does)
      const __m256d f = _mm256_floor_pd(c), t = _mm256_sub_pd(c, f);
      lo[a] = _mm256_cvttpd_epi32(f);
      hi[a] = _mm_min_epi32(_mm_add_epi32(lo[a], _mm_set1_epi32(1)), _mm_set1_epi32(r.dims[a] - 1));
      wlo[a] = _mm256_sub_pd(_mm256_set1_pd(1.0), t);
      whi[a] = t;
    }
    __m128i index[1 << D];
    __m256d weight[1 << D];
    const __m128i nx = _mm_set1_epi32(r.dims[0]);
    for (int k = 0; k < (1 << D); ++k) {
      const int kx = k & 1, ky = (k >> 1) & 1;
      __m128i idx = _mm_add_epi32(kx ? hi[0] : lo[0], _mm_mullo_epi32(nx, ky ? hi[1] : lo[1]));
      __m256d w = _mm256_mul_pd(kx ? whi[0] : wlo[0], ky ? whi[1] : wlo[1]);
      if constexpr (D == 3) {
        const int kz = k >> 2;
        const __m128i plane = _mm_set1_epi32(r.dims[0] * r.dims[1]);
        idx = _mm_add_epi32(idx, _mm_mullo_epi32(plane, kz ? hi[2] : lo[2]));
        w = _mm256_mul_pd(w, kz ? whi[2] : wlo[2]);
      }
      index[k] = idx;
      weight[k] = w;
    }
    const __m256d w = r.fromInflow ? _mm256_loadu_pd(r.fromInflow + i) : _mm256_setzero_pd();
    const __m256d keep = _mm256_sub_pd(_mm256_set1_pd(1.0), w);
    const __m256d full = _mm256_cmp_pd(w, _mm256_set1_pd(1.0), _CMP_GE_OQ);
    for (size_t s = 0; s < r.species; ++s) {
      __m256d v = _mm256_setzero_pd();
      for (int k = 0; k < (1 << D); ++k)
        v = _mm256_add_pd(
            v, _mm256_mul_pd(weight[k], _mm256_mask_i32gather_pd(_mm256_setzero_pd(), r.src[s], index[k],
                                                                 _mm256_castsi256_pd(_mm256_set1_epi64x(-1)), 8)));
      const __m256d in = _mm256_set1_pd(r.in[s]);
      const __m256d out = _mm256_add_pd(_mm256_mul_pd(w, in), _mm256_mul_pd(keep, v));
      _mm256_storeu_pd(r.dst[s] + i, _mm256_blendv_pd(out, in, full));
    }
  }
  return i;
}
#endif

}  // namespace

template <int D>
double sampleChemical(const Grid<double, D>& g, const std::array<bool, D>& periodic, const Vec<D>& c,
                      ChemicalInterpolation interp) {
  AxisWeights ax[D];
  for (int a = 0; a < D; ++a) ax[a] = axisWeights(c[a], g.dim(a), periodic[size_t(a)], interp);
  const size_t nx = size_t(g.dim(0)), ny = size_t(g.dim(1));
  double sum = 0.0, lo = INFINITY, hi = -INFINITY;
  const int kz0 = D == 3 ? ax[D - 1].first : 0, kz1 = D == 3 ? ax[D - 1].first + ax[D - 1].count : 1;
  for (int kz = kz0; kz < kz1; ++kz)
    for (int ky = ax[1].first; ky < ax[1].first + ax[1].count; ++ky)
      for (int kx = ax[0].first; kx < ax[0].first + ax[0].count; ++kx) {
        size_t idx = size_t(ax[0].index[kx]) + nx * size_t(ax[1].index[ky]);
        double w = ax[0].w[kx] * ax[1].w[ky];
        bool inner = (kx == 1 || kx == 2) && (ky == 1 || ky == 2);
        if constexpr (D == 3) {
          idx += nx * ny * size_t(ax[2].index[kz]);
          w *= ax[2].w[kz];
          inner = inner && (kz == 1 || kz == 2);
        }
        const double v = g[idx];
        sum += w * v;
        if (inner) lo = std::min(lo, v), hi = std::max(hi, v);
      }
  // Clamp the cubic to the linear stencil's range: no new extrema.
  return interp == ChemicalInterpolation::Cubic ? std::clamp(sum, lo, hi) : sum;
}

template <int D>
ChemicalAdvector<D>::ChemicalAdvector(ChemicalDomain<D> domain, ChemicalInterpolation interpolation)
    : domain_(std::move(domain)), interpolation_(interpolation) {
  if (!domain_.solid.empty() && domain_.solid.size() != cells())
    throw std::invalid_argument("coupling: solid mask has the wrong size");
}

template <int D>
size_t ChemicalAdvector<D>::cells() const {
  size_t n = 1;
  for (int a = 0; a < D; ++a) n *= size_t(domain_.cells[a]);
  return n;
}

// Without an inflow side every foot's inflow weight is 0: no weights are
// kept, and the passes blend with none (the same values, bit for bit).
template <int D>
bool ChemicalAdvector<D>::weighsInflow() const {
  bool side = false;
  for (const auto& s : domain_.inflow) side = side || s[0] || s[1];
  return side && !domain_.inflowValues.empty();
}

template <int D>
void ChemicalAdvector<D>::emptySolids(const std::vector<Grid<double, D>*>& species) const {
  if (domain_.solid.empty()) return;
  for (size_t s = 0; s < species.size(); ++s) {
    Grid<double, D>& g = *species[s];
    const double v = s < domain_.solidValues.size() ? domain_.solidValues[s] : 0.0;
    parallelFor(g.size(), [&](size_t i) { if (domain_.solid[i]) g[i] = v; }, 4096);
  }
}

namespace {

// The weight of the inflow value at every foot (1: it left through an inflow
// side): beyond the outermost cell centre of an inflow side the value blends
// into the inflow concentration, reached at the wall itself.
template <int D>
void inflowWeights(const ChemicalDomain<D>& d, const std::array<float*, D>& feet, std::vector<double>* w) {
  parallelFor(w->size(), [&](size_t i) {
    double in = 0.0;
    for (int a = 0; a < D; ++a) {
      const double c = feet[size_t(a)][i];
      if (d.inflow[size_t(a)][0]) in = std::max(in, std::clamp(-2.0 * c, 0.0, 1.0));
      if (d.inflow[size_t(a)][1]) in = std::max(in, std::clamp(2.0 * (c - (d.cells[a] - 1)), 0.0, 1.0));
    }
    (*w)[i] = in;
  }, 4096);
}

// Feet of every cell over dt (seed 001 eq. 19: x* = x - dt u), with the
// fluid's vector kernels; periodic domains trace cell by cell.
template <int D>
void cellFeet(const ChemicalDomain<D>& d, const MacVelocity<D>& u, double dt, const std::array<float*, D>& feet) {
  if (traceCellFeet<D>(u, dt, d.cells, d.h, feet)) return;
  forEachCell<D>(d.cells, [&](const IVec<D>& k, size_t i) {
    const Vec<D> x = (Vec<D>(k) + 0.5) * d.h;
    const Vec<D> c = traceBack<D>(u, x, dt) / d.h - Vec<D>(0.5);
    for (int a = 0; a < D; ++a) feet[size_t(a)][i] = float(c[a]);
  });
}

// Runs cell(i) over all cells in chunks; `run`, when given, does the chunk's
// leading cells four at a time first and returns the first one not done.
template <class Cell, class Run>
void forChunks(size_t cells, const Cell& cell, const Run& run) {
  constexpr size_t kRun = 1024;
  parallelFor((cells + kRun - 1) / kRun, [&](size_t chunk) {
    size_t i = chunk * kRun;
    const size_t end = std::min(cells, i + kRun);
    i = run(i, end);
    for (; i < end; ++i) cell(i);
  });
}

}  // namespace

template <int D>
void ChemicalAdvector<D>::trace(const MacVelocity<D>& u, double dt, WorkPool* pool) {
  const ChemicalDomain<D>& d = domain_;
  const bool weighed = weighsInflow();
  const bool bfecc = interpolation_ == ChemicalInterpolation::BFECC;
  const size_t n = cells();
  // (floats first: the species' scratch that follows is a double vector)
  feet_.lend(pool ? pool : &own_, bfecc ? 2 * D : D, n, FloatArrays::First::Floats);
  cellFeet<D>(d, u, dt, feet(0));
  if (weighed) fromInflow_.resize(n), inflowWeights<D>(d, feet(0), &fromInflow_);
  if (bfecc) {  // the forward trace of BFECC's backward step: the feet over -dt
    cellFeet<D>(d, u, -dt, feet(1));
    if (weighed) backFromInflow_.resize(n), inflowWeights<D>(d, feet(1), &backFromInflow_);
  }
}

template <int D>
void ChemicalAdvector<D>::carry(const std::vector<Grid<double, D>*>& species, WorkPool* pool) {
  const ChemicalDomain<D>& d = domain_;
  const bool inflow = !d.inflowValues.empty(), weighed = weighsInflow();
  const bool bfecc = interpolation_ == ChemicalInterpolation::BFECC;
  const size_t ns = species.size();
  std::array<const float*, D> fwdFeet{}, backFeet{};
  for (int a = 0; a < D; ++a) {
    fwdFeet[size_t(a)] = feet(0)[size_t(a)];
    if (bfecc) backFeet[size_t(a)] = feet(1)[size_t(a)];
  }
  const bool spline = interpolation_ == ChemicalInterpolation::BSpline;
  const bool linear = interpolation_ == ChemicalInterpolation::Linear || bfecc;
  const size_t cells = this->cells();
  bool walls = true;
  for (int a = 0; a < D; ++a) walls = walls && !d.periodic[size_t(a)];
  [[maybe_unused]] const bool wide = walls && cells < (size_t(1) << 31) && useAvx2();
  // dst[i] = the sample at cell i's foot, blended into the inflow value `in`
  // by the weights w (null: none); `run` may do a chunk's leading cells first.
  auto pass = [&](const std::array<const float*, D>& feet, const double* w, double in, double* dst,
                  const auto& sampleAt, const auto& run) {
    forChunks(cells, [&](size_t i) {
      const double wi = w ? w[i] : 0.0;
      if (wi >= 1.0) {
        dst[i] = in;
        return;
      }
      Vec<D> c;
      for (int a = 0; a < D; ++a) c[a] = feet[size_t(a)][i];
      dst[i] = wi * in + (1.0 - wi) * sampleAt(c);
    }, run);
  };
  auto scalar = [](size_t i, size_t) { return i; };
  // src sampled linearly at `feet` into dst (2^D loads a cell).
  auto linearPass = [&](const std::array<const float*, D>& feet, const double* w, double in, const double* src,
                        double* dst) {
    [[maybe_unused]] LinearRun<D> run{d.cells, feet, w, &in, &src, &dst, 1};
    pass(feet, w, in, dst, [&](const Vec<D>& c) {
      size_t index[1 << D];
      double weight[1 << D];
      linearStencil<D>(d.cells, d.periodic, c, index, weight);
      double v = 0.0;
      for (int k = 0; k < (1 << D); ++k) v += weight[k] * src[index[k]];
      return v;
    }, [&](size_t i, [[maybe_unused]] size_t end) {
#if MORPHOFLOW_AVX2_KERNELS
      if (wide) i = linearRunAvx2<D>(run, i, end);
#endif
      return i;
    });
  };
  const double* inflowWeight = weighed ? fromInflow_.data() : nullptr;
  // Species s into scratch_ by the cubic or the spline (16 or 64 loads a cell).
  auto cubicPass = [&](size_t s) {
    pass(
        fwdFeet, inflowWeight, inflow ? d.inflowValues[s] : 0.0, scratch_.data(),
        [&](const Vec<D>& c) {
          return spline ? sampleBSpline<D>(coefficients_, *species[s], d.periodic, c)
                        : sampleChemical<D>(*species[s], d.periodic, c, interpolation_);
        },
        scalar);
  };
  // BFECC (Kim, Liu, Llamas & Rossignac 2005): forward phi^ = A(phi) into scratch_,
  // backward phi_b = A^-1(phi^) into coefficients_, then A(phi + (phi - phi_b) / 2),
  // limited to the range of phi's linear neighbours of the foot.
  auto bfeccPass = [&](size_t s) {
    const double in = inflow ? d.inflowValues[s] : 0.0;
    const double* phi = species[s]->data();
    coefficients_.reshape(d.cells);
    auto forward = [&] { linearPass(fwdFeet, inflowWeight, in, phi, scratch_.data()); };
    auto backward = [&] {
      linearPass(backFeet, weighed ? backFromInflow_.data() : nullptr, in, scratch_.data(), coefficients_.data());
    };
    const double* back = coefficients_.data();
    auto compensated = [&] {
      pass(
          fwdFeet, inflowWeight, in, scratch_.data(),
          [&](const Vec<D>& c) {
            size_t index[1 << D];
            double weight[1 << D];
            linearStencil<D>(d.cells, d.periodic, c, index, weight);
            double v = 0.0, lo = INFINITY, hi = -INFINITY;
            for (int k = 0; k < (1 << D); ++k) {
              const double p = phi[index[k]];
              v += weight[k] * (1.5 * p - 0.5 * back[index[k]]);
              lo = std::min(lo, p), hi = std::max(hi, p);
            }
            return std::clamp(v, lo, hi);
          },
          scalar);
    };
    bfeccPasses(forward, backward, compensated);
  };
  // One species at a time through one scratch (the species are independent):
  // after the swap it holds the old values' storage, the next one's scratch.
  for (size_t s = 0; s < ns; ++s) {
    if (pool) pool->lend(&scratch_.values());
    scratch_.reshape(d.cells);
    if (bfecc) {
      if (pool) pool->lend(&coefficients_.values());
      bfeccPass(s);
      if (pool) pool->give(&coefficients_.values());
    } else if (linear) {
      linearPass(fwdFeet, inflowWeight, inflow ? d.inflowValues[s] : 0.0, species[s]->data(), scratch_.data());
    } else {
      if (spline) bsplineCoefficients<D>(*species[s], d.periodic, &coefficients_);
      cubicPass(s);
    }
    std::swap(species[s]->values(), scratch_.values());
    if (pool) pool->give(&scratch_.values());
  }
  feet_.give(pool ? pool : &own_);
  emptySolids(species);
}

template class ChemicalAdvector<2>;
template class ChemicalAdvector<3>;
template double sampleChemical<2>(const Grid<double, 2>&, const std::array<bool, 2>&, const Vec<2>&,
                                  ChemicalInterpolation);
template double sampleChemical<3>(const Grid<double, 3>&, const std::array<bool, 3>&, const Vec<3>&,
                                  ChemicalInterpolation);

}  // namespace morphoflow
