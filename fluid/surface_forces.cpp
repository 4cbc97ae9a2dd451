#include "fluid/surface_forces.h"

#include <cmath>

#include "core/parallel.h"
#include "core/sampling.h"

namespace morphoflow {

template <int D>
std::vector<SurfaceElement> cutSurfaceElements(const VelocityConstraints<D>& vc) {
  std::vector<SurfaceElement> out;
  if (vc.cut.empty()) return out;
  const double h = vc.h, face = std::pow(h, D - 1);
  for (size_t i = 0; i < vc.solid.size(); ++i) {
    const IVec<D> k = vc.solid.coord(i);
    double c[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) c[a] = (k[a] + 0.5) * h;
    // The fluid part's closed boundary: the surface's area vector is the
    // sum of the faces' open area vectors (outward normals).
    SurfaceElement e;
    double norm2 = 0.0;
    for (int a = 0; a < D; ++a) {
      e.area[size_t(a)] = (double(vc.open[a](k + unitVector<D>(a))) - double(vc.open[a](k))) * face;
      norm2 += e.area[size_t(a)] * e.area[size_t(a)];
    }
    if (!(norm2 > 1e-24 * face * face)) continue;
    const double len = std::sqrt(norm2);
    double n[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) n[a] = e.area[size_t(a)] / len;
    // The surface point: where the distance changes sign along the normal
    // through the centre (by its sign alone, so image shapes work too).
    auto along = [&](double s, double* x) {
      for (int a = 0; a < D; ++a) x[a] = c[a] + s * n[a];
    };
    double lo = -1.5 * h, hi = 1.5 * h, x[3] = {0, 0, 0};
    along(lo, x);
    if (vc.cut.distance(x) >= 0.0) continue;  // no crossing within reach
    along(hi, x);
    if (vc.cut.distance(x) < 0.0) continue;
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      along(mid, x);
      (vc.cut.distance(x) < 0.0 ? lo : hi) = mid;
    }
    along(0.5 * (lo + hi), x);
    for (int a = 0; a < D; ++a) e.x[size_t(a)] = x[a];
    out.push_back(e);
  }
  return out;
}

template <int D>
std::array<double, 3> surfaceForce(const std::vector<SurfaceElement>& elements, const MacVelocity<D>& u,
                                   const Grid<float, D>& p, double mu, const CutSurface* bodies) {
  const double h = u.h(), d1 = 2.0 * h, d2 = 3.0 * h;
  const Layout<D> cells = Layout<D>::cellCentred(h, u.cells(), u.periodic());
  std::array<double, 3> force{0, 0, 0};
  for (const SurfaceElement& e : elements) {
    double len = 0.0;
    for (int a = 0; a < D; ++a) len += e.area[size_t(a)] * e.area[size_t(a)];
    len = std::sqrt(len);
    Vec<D> x1, x2;
    for (int a = 0; a < D; ++a) {
      const double n = e.area[size_t(a)] / len;
      x1[a] = e.x[size_t(a)] + d1 * n;
      x2[a] = e.x[size_t(a)] + d2 * n;
    }
    // p at the wall, extrapolated linearly; du/dn from u(0) = 0, u(d1), u(d2).
    const double p1 = sampleLinear(p, cells, x1), p2 = sampleLinear(p, cells, x2);
    const double pw = (d2 * p1 - d1 * p2) / (d2 - d1);
    Vec<D> u1 = u.sample(x1), u2 = u.sample(x2);
    if (bodies && bodies->moving()) {  // relative to the wall's velocity at the surface point
      const std::array<double, 3> w = bodies->velocity(e.x.data());
      for (int a = 0; a < D; ++a) u1[a] -= w[size_t(a)], u2[a] -= w[size_t(a)];
    }
    for (int a = 0; a < D; ++a) {
      const double dudn = (d2 * d2 * u1[a] - d1 * d1 * u2[a]) / (d1 * d2 * (d2 - d1));
      force[size_t(a)] += -pw * e.area[size_t(a)] + mu * dudn * len;
    }
  }
  return force;
}

template std::vector<SurfaceElement> cutSurfaceElements<2>(const VelocityConstraints<2>&);
template std::vector<SurfaceElement> cutSurfaceElements<3>(const VelocityConstraints<3>&);
template std::array<double, 3> surfaceForce<2>(const std::vector<SurfaceElement>&, const MacVelocity<2>&,
                                               const Grid<float, 2>&, double, const CutSurface*);
template std::array<double, 3> surfaceForce<3>(const std::vector<SurfaceElement>&, const MacVelocity<3>&,
                                               const Grid<float, 3>&, double, const CutSurface*);

}  // namespace morphoflow
