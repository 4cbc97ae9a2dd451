#include "rd/coarse_to_fine.h"

#include <cassert>

#include "core/parallel.h"

namespace morphoflow {

template <int D>
void prolongate(const Grid<double, D>& coarse, Grid<double, D>* fine, bool periodic) {
  const IVec<D>& nc = coarse.dims();
  for (int a = 0; a < D; ++a) assert(fine->dim(a) == 2 * nc[a]);
  forEachCell<D>(fine->dims(), [&](const IVec<D>& f, size_t i) {
    // Per axis: the two coarse neighbours and their weights.
    int lo[D], hi[D];
    for (int a = 0; a < D; ++a) {
      const int m = f[a] / 2;
      int other = f[a] % 2 == 0 ? m - 1 : m + 1;
      if (periodic) other = (other + nc[a]) % nc[a];
      else other = other < 0 ? 0 : other >= nc[a] ? nc[a] - 1 : other;
      lo[a] = m;
      hi[a] = other;
    }
    double v = 0.0;
    for (int corner = 0; corner < (1 << D); ++corner) {
      IVec<D> c;
      double w = 1.0;
      for (int a = 0; a < D; ++a) {
        const bool useHi = (corner >> a) & 1;
        c[a] = useHi ? hi[a] : lo[a];
        w *= useHi ? 0.25 : 0.75;
      }
      v += w * coarse[coarse.index(c)];
    }
    (*fine)[i] = v;
  });
}

template void prolongate<2>(const Grid<double, 2>&, Grid<double, 2>*, bool);
template void prolongate<3>(const Grid<double, 3>&, Grid<double, 3>*, bool);

}  // namespace morphoflow
