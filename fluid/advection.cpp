#include "fluid/advection.h"

#include <algorithm>

#include "core/linear_sampler.h"
#include "core/parallel.h"

namespace morphoflow {

namespace {

// One semi-Lagrangian pass; optionally records the min/max of each stencil.
// Works in cell units: p = k + offset, foot = p - (dt/h) u(p - (dt/2h) u(p)).
template <int D>
void semiLagrangian(const Grid<float, D>& src, const Layout<D>& layout, const MacVelocity<D>& u,
                    double dt, Grid<float, D>* dst, Grid<float, D>* lo, Grid<float, D>* hi) {
  const LinearSampler<D> field(src, layout);
  std::array<LinearSampler<D>, D> vel = makeVelocitySamplers(u);
  const float c = float(dt / u.h());
  const IVec<D> dims = src.dims();
  parallelForRows<D>(dims, [&](size_t row) {
    float p[D], m[D], f[D];
    size_t rest = row;
    for (int a = 1; a < D; ++a) {
      p[a] = float(int(rest % size_t(dims[a]))) + field.offset[a];
      rest /= size_t(dims[a]);
    }
    const size_t base = row * size_t(dims[0]);
    for (int x = 0; x < dims[0]; ++x) {
      p[0] = float(x) + field.offset[0];
      for (int a = 0; a < D; ++a) m[a] = p[a] - 0.5f * c * vel[size_t(a)](p);
      for (int a = 0; a < D; ++a) f[a] = p[a] - c * vel[size_t(a)](m);
      size_t i = base + size_t(x);
      if (lo)
        (*dst)[i] = field(f, &(*lo)[i], &(*hi)[i]);
      else
        (*dst)[i] = field(f);
    }
  });
}

}  // namespace

template <int D>
void advectField(const Grid<float, D>& src, const Layout<D>& layout, const MacVelocity<D>& u,
                 double dt, AdvectionScheme scheme, Grid<float, D>* dst, AdvectionScratch<D>* scratch) {
  if (scheme == AdvectionScheme::SemiLagrangian) {
    semiLagrangian<D>(src, layout, u, dt, dst, nullptr, nullptr);
    return;
  }
  AdvectionScratch<D> local;
  typename AdvectionScratch<D>::Set& s = (scratch ? *scratch : local).forShape(src.dims());
  Grid<float, D>&lo = s.lo, &hi = s.hi, &back = s.back;
  if (scheme == AdvectionScheme::MacCormack) {
    // phi^ = A(phi); phi~ = A^-1(phi^); phi = phi^ + (phi - phi~) / 2, limited.
    Grid<float, D>& fwd = *dst;
    semiLagrangian<D>(src, layout, u, dt, &fwd, &lo, &hi);
    semiLagrangian<D>(fwd, layout, u, -dt, &back, nullptr, nullptr);
    parallelFor(src.size(), [&](size_t i) {
      float v = fwd[i] + 0.5f * (src[i] - back[i]);
      // Revert to first order where the correction leaves the stencil's range.
      if (v >= lo[i] && v <= hi[i]) fwd[i] = v;
    }, 4096);
    return;
  }
  // BFECC: phi_bar = phi + (phi - A^-1 A phi) / 2, then A(phi_bar), limited.
  Grid<float, D>& fwd = s.fwd;
  semiLagrangian<D>(src, layout, u, dt, &fwd, nullptr, nullptr);
  semiLagrangian<D>(fwd, layout, u, -dt, &back, nullptr, nullptr);
  Grid<float, D>& corrected = fwd;  // fwd is no longer needed
  parallelFor(src.size(), [&](size_t i) { corrected[i] = src[i] + 0.5f * (src[i] - back[i]); }, 4096);
  semiLagrangian<D>(corrected, layout, u, dt, dst, nullptr, nullptr);
  semiLagrangian<D>(src, layout, u, dt, &back, &lo, &hi);  // first-order fallback
  parallelFor(src.size(), [&](size_t i) {
    if ((*dst)[i] < lo[i] || (*dst)[i] > hi[i]) (*dst)[i] = back[i];
  }, 4096);
}

template <int D>
void advectVelocity(const MacVelocity<D>& u, double dt, AdvectionScheme scheme, MacVelocity<D>* dst,
                    AdvectionScratch<D>* scratch) {
  for (int a = 0; a < D; ++a) advectField<D>(u[a], u.layout(a), u, dt, scheme, &(*dst)[a], scratch);
}

template void advectField<2>(const Grid<float, 2>&, const Layout<2>&, const MacVelocity<2>&, double,
                             AdvectionScheme, Grid<float, 2>*, AdvectionScratch<2>*);
template void advectField<3>(const Grid<float, 3>&, const Layout<3>&, const MacVelocity<3>&, double,
                             AdvectionScheme, Grid<float, 3>*, AdvectionScratch<3>*);
template void advectVelocity<2>(const MacVelocity<2>&, double, AdvectionScheme, MacVelocity<2>*, AdvectionScratch<2>*);
template void advectVelocity<3>(const MacVelocity<3>&, double, AdvectionScheme, MacVelocity<3>*, AdvectionScratch<3>*);

}  // namespace morphoflow
