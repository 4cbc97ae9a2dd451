#include "coupling/smoke_layer.h"

#include "core/parallel.h"
#include "fluid/smoke.h"  // coverBlend

namespace morphoflow {

template <int D>
SmokeTaps<D> smokeTaps(const Layout<D>& smoke, const IVec<D>& smokeCells, const IVec<D>& cells, double h) {
  SmokeTaps<D> taps;
  for (int a = 0; a < D; ++a) {
    const size_t n = size_t(cells[a]);
    taps.i0[a].resize(n);
    taps.i1[a].resize(n);
    taps.t[a].resize(n);
    for (size_t k = 0; k < n; ++k) {
      // as sampleLinear (core/sampling.h) at x = (k + 1/2) h
      Vec<D> x(0.0);
      x[a] = (double(k) + 0.5) * h;
      double t = 0.0;
      detail::axisStencil(smoke.toGrid(x)[a], smokeCells[a], smoke.periodic[a], smoke.period[a], &taps.i0[a][k],
                          &taps.i1[a][k], &t);
      taps.t[a][k] = float(t);
    }
  }
  return taps;
}

template <int D>
void blendLayer(RDSolver<D>* rd, const Grid<float, D>& cover, const std::vector<double>& values) {
  for (int s = 0; s < rd->species(); ++s) {
    Grid<double, D>& x = rd->field(s);
    const double v = values[size_t(s)];
    parallelFor(x.size(), [&](size_t i) { x[i] = coverBlend(x[i], cover[i], v); }, 4096);
  }
}

template <int D>
void maskLayer(RDSolver<D>* rd, const Grid<float, D>& smoke, const SmokeTaps<D>& taps, double threshold,
               const std::vector<double>& rest) {
  const int ns = rd->species();
  forEachCell<D>(rd->cells(), [&](const IVec<D>& k, size_t i) {
    int i0[D], i1[D];
    double t[D];
    for (int a = 0; a < D; ++a) {
      i0[a] = taps.i0[a][size_t(k[a])];
      i1[a] = taps.i1[a][size_t(k[a])];
      t[a] = double(taps.t[a][size_t(k[a])]);
    }
    if (double(interpolateStencil<float, D>(smoke, i0, i1, t)) > threshold) return;
    for (int s = 0; s < ns; ++s) rd->field(s)[i] = rest[size_t(s)];
  });
}

template SmokeTaps<2> smokeTaps<2>(const Layout<2>&, const IVec<2>&, const IVec<2>&, double);
template SmokeTaps<3> smokeTaps<3>(const Layout<3>&, const IVec<3>&, const IVec<3>&, double);
template void blendLayer<2>(RDSolver<2>*, const Grid<float, 2>&, const std::vector<double>&);
template void blendLayer<3>(RDSolver<3>*, const Grid<float, 3>&, const std::vector<double>&);
template void maskLayer<2>(RDSolver<2>*, const Grid<float, 2>&, const SmokeTaps<2>&, double,
                           const std::vector<double>&);
template void maskLayer<3>(RDSolver<3>*, const Grid<float, 3>&, const SmokeTaps<3>&, double,
                           const std::vector<double>&);

}  // namespace morphoflow
