#include "coupling/bspline.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/parallel.h"
#include "core/sampling.h"
#include "coupling/interpolation_weights.h"

namespace morphoflow {

namespace {

const double kPole = std::sqrt(3.0) - 2.0;

// One line of n samples p[k * stride], in place (kernels/bspline_prefilter.inc, shared with the GPU).
#define BS_REAL double
#define BS_LINE double *p, size_t stride
#define BS_AT(k) p[size_t(k) * stride]
#define PRECISE
#include "kernels/bspline_prefilter.inc"
#undef BS_REAL
#undef BS_LINE
#undef BS_AT
#undef PRECISE

// The four coefficient indices along an axis (mirrored at walls, wrapped on
// periodic axes), the linear neighbours i0, i1, and the fraction t.
struct SplineAxis {
  int index[4];
  int i0, i1;
  double t;
};

SplineAxis splineAxis(double c, int n, bool periodic) {
  SplineAxis a{};
  c = boundedCoordinate(c);
  if (!periodic) c = std::clamp(c, 0.0, double(n - 1));
  const double f = std::floor(c);
  a.t = c - f;
  const int i = int(f);
  for (int k = 0; k < 4; ++k) {
    int j = i - 1 + k;
    if (periodic) {
      j = ((j % n) + n) % n;
    } else if (n == 1) {
      j = 0;
    } else {
      if (j < 0) j = -j;
      if (j > n - 1) j = 2 * (n - 1) - j;
      j = std::clamp(j, 0, n - 1);
    }
    a.index[k] = j;
  }
  a.i0 = periodic ? ((i % n) + n) % n : i;
  a.i1 = periodic ? (((i + 1) % n) + n) % n : std::min(i + 1, n - 1);
  return a;
}

}  // namespace

template <int D>
void bsplineCoefficients(const Grid<double, D>& f, const std::array<bool, D>& periodic, Grid<double, D>* c) {
  if (c != &f) *c = f;
  const IVec<D>& n = f.dims();
  for (int a = 0; a < D; ++a) {
    const size_t stride = f.stride(a);
    // the lines along a: every cell whose coordinate along a is 0
    size_t lines = 1;
    for (int b = 0; b < D; ++b)
      if (b != a) lines *= size_t(n[b]);
    parallelFor(lines, [&](size_t line) {
      size_t rest = line, base = 0;
      for (int b = 0; b < D; ++b) {
        if (b == a) continue;
        base += (rest % size_t(n[b])) * f.stride(b);
        rest /= size_t(n[b]);
      }
      bsplinePrefilterLine(c->data() + base, stride, n[a], periodic[size_t(a)], kPole, std::pow(kPole, n[a]),
                           std::pow(kPole, 2 * n[a] - 2));
    }, 16);
  }
}

template <int D>
double sampleBSpline(const Grid<double, D>& c, const Grid<double, D>& f, const std::array<bool, D>& periodic,
                     const Vec<D>& x) {
  SplineAxis ax[D];
  double w[D][4];
  for (int a = 0; a < D; ++a) {
    ax[a] = splineAxis(x[a], f.dim(a), periodic[size_t(a)]);
    bsplineWeights(ax[a].t, w[a]);
  }
  const size_t sy = f.stride(1), sz = D == 3 ? f.stride(D - 1) : 0;
  double sum = 0.0;
  for (int kz = 0; kz < (D == 3 ? 4 : 1); ++kz)
    for (int ky = 0; ky < 4; ++ky)
      for (int kx = 0; kx < 4; ++kx) {
        size_t i = size_t(ax[0].index[kx]) + sy * size_t(ax[1].index[ky]);
        double wk = w[0][kx] * w[1][ky];
        if constexpr (D == 3) {
          i += sz * size_t(ax[2].index[kz]);
          wk *= w[2][kz];
        }
        sum += wk * c[i];
      }
  double lo = INFINITY, hi = -INFINITY;
  for (int k = 0; k < (1 << D); ++k) {
    size_t i = size_t((k & 1) ? ax[0].i1 : ax[0].i0) + sy * size_t((k & 2) ? ax[1].i1 : ax[1].i0);
    if constexpr (D == 3) i += sz * size_t((k & 4) ? ax[2].i1 : ax[2].i0);
    lo = std::min(lo, f[i]);
    hi = std::max(hi, f[i]);
  }
  return std::clamp(sum, lo, hi);
}

template void bsplineCoefficients<2>(const Grid<double, 2>&, const std::array<bool, 2>&, Grid<double, 2>*);
template void bsplineCoefficients<3>(const Grid<double, 3>&, const std::array<bool, 3>&, Grid<double, 3>*);
template double sampleBSpline<2>(const Grid<double, 2>&, const Grid<double, 2>&, const std::array<bool, 2>&,
                                 const Vec<2>&);
template double sampleBSpline<3>(const Grid<double, 3>&, const Grid<double, 3>&, const std::array<bool, 3>&,
                                 const Vec<3>&);

}  // namespace morphoflow
