#include "coupling/chemical_advection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/parallel.h"
#include "fluid/advection.h"

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
  } else {  // Catmull-Rom
    const double t2 = t * t, t3 = t2 * t;
    a.first = 0, a.count = 4;
    a.w[0] = 0.5 * (-t3 + 2 * t2 - t);
    a.w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
    a.w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
    a.w[3] = 0.5 * (t3 - t2);
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
  size_t n = 1;
  for (int a = 0; a < D; ++a) n *= size_t(domain_.cells[a]);
  if (!domain_.solid.empty() && domain_.solid.size() != n) throw std::invalid_argument("coupling: solid mask has the wrong size");
  for (auto& f : feet_) f.assign(n, 0.0f);
  fromInflow_.assign(n, 0);
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

template <int D>
void ChemicalAdvector<D>::advect(const MacVelocity<D>& u, double dt, const std::vector<Grid<double, D>*>& species) {
  const ChemicalDomain<D>& d = domain_;
  const bool inflow = !d.inflowValues.empty();
  // Feet once for all species (seed 001 eq. 19: x* = x - dt u), with the
  // fluid's vector kernels; periodic domains trace cell by cell.
  if (!traceCellFeet<D>(u, dt, d.cells, d.h, &feet_))
    forEachCell<D>(d.cells, [&](const IVec<D>& k, size_t i) {
      const Vec<D> x = (Vec<D>(k) + 0.5) * d.h;
      const Vec<D> c = traceBack<D>(u, x, dt) / d.h - Vec<D>(0.5);
      for (int a = 0; a < D; ++a) feet_[size_t(a)][i] = float(c[a]);
    });
  // Beyond the outermost cell centre of an inflow side the value blends
  // into the inflow concentration, reached at the wall itself.
  if (inflow)
    parallelFor(fromInflow_.size(), [&](size_t i) {
      double in = 0.0;
      for (int a = 0; a < D; ++a) {
        const double c = feet_[size_t(a)][i];
        if (d.inflow[size_t(a)][0]) in = std::max(in, std::clamp(-2.0 * c, 0.0, 1.0));
        if (d.inflow[size_t(a)][1]) in = std::max(in, std::clamp(2.0 * (c - (d.cells[a] - 1)), 0.0, 1.0));
      }
      fromInflow_[i] = in;
    }, 4096);
  // Every species from one stencil per cell (one set of weights, 2^D
  // loads per species).
  const size_t ns = species.size();
  while (scratch_.size() < ns) scratch_.emplace_back(d.cells);
  std::vector<double> in(ns, 0.0);
  std::vector<const double*> src(ns);
  std::vector<double*> dst(ns);
  for (size_t s = 0; s < ns; ++s) {
    in[s] = inflow ? d.inflowValues[s] : 0.0;
    src[s] = species[s]->data();
    dst[s] = scratch_[s].data();
  }
  const bool linear = interpolation_ == ChemicalInterpolation::Linear;
  parallelFor(fromInflow_.size(), [&](size_t i) {
    const double w = inflow ? fromInflow_[i] : 0.0;
    if (w >= 1.0) {
      for (size_t s = 0; s < ns; ++s) dst[s][i] = in[s];
      return;
    }
    Vec<D> c;
    for (int a = 0; a < D; ++a) c[a] = feet_[size_t(a)][i];
    if (linear) {
      size_t index[1 << D];
      double weight[1 << D];
      linearStencil<D>(d.cells, d.periodic, c, index, weight);
      for (size_t s = 0; s < ns; ++s) {
        double v = 0.0;
        for (int k = 0; k < (1 << D); ++k) v += weight[k] * src[s][index[k]];
        dst[s][i] = w * in[s] + (1.0 - w) * v;
      }
    } else {
      for (size_t s = 0; s < ns; ++s)
        dst[s][i] = w * in[s] + (1.0 - w) * sampleChemical<D>(*species[s], d.periodic, c, interpolation_);
    }
  }, 1024);
  for (size_t s = 0; s < ns; ++s) std::swap(species[s]->values(), scratch_[s].values());
  emptySolids(species);
}

template class ChemicalAdvector<2>;
template class ChemicalAdvector<3>;
template double sampleChemical<2>(const Grid<double, 2>&, const std::array<bool, 2>&, const Vec<2>&, ChemicalInterpolation);
template double sampleChemical<3>(const Grid<double, 3>&, const std::array<bool, 3>&, const Vec<3>&, ChemicalInterpolation);

}  // namespace morphoflow
