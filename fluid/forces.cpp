#include "fluid/forces.h"

#include "core/parallel.h"

namespace morphoflow {

template <int D>
void applyForces(const FluidSettings& s, const Grid<float, D>* dye, double dt, MacVelocity<D>* u) {
  const IVec<D>& n = u->cells();
  for (int a = 0; a < D; ++a) {
    const float f = float(dt * s.force[size_t(a)]);
    const float b = float(dt * s.buoyancy * s.buoyancyDirection[size_t(a)]);
    if (f == 0.0f && (b == 0.0f || !dye)) continue;
    Grid<float, D>& g = (*u)[a];
    forEachCell<D>(g.dims(), [&](const IVec<D>& k, size_t i) {
      float v = f;
      if (b != 0.0f && dye) {
        // Dye at the face: mean of the two cells it separates (one at walls).
        IVec<D> lo = k - unitVector<D>(a), hi = k;
        if (lo[a] < 0) lo = hi;
        if (hi[a] >= n[a]) hi = lo;
        v += b * 0.5f * ((*dye)(lo) + (*dye)(hi));
      }
      g[i] += v;
    });
  }
}

template void applyForces<2>(const FluidSettings&, const Grid<float, 2>*, double, MacVelocity<2>*);
template void applyForces<3>(const FluidSettings&, const Grid<float, 3>*, double, MacVelocity<3>*);

}  // namespace morphoflow
