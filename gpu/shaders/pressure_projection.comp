// The projection's stages besides its solve (fluid/pressure_projection.cpp), one MODE each.
// MODE_DIVERGENCE       rhs = -(div u) / h through the faces' open fractions, 0 in cells
//                       without a pressure (double)
// MODE_WARM_START       phi = dt (2 rate - rate_prev) (or dt rate), rate = phi / last dt
// MODE_GRADIENT         u_a -= d phi / d x_a on free faces (outflow: ghost phi = -phi)
#include "fluid_faces.glsl"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_DIVERGENCE)
  const ivec3 k = coordsOf(i, cells);
  double d = 0.0lf;
  for (int a = 0; a < DIM; ++a) {
    ivec3 fd = cells, up = k;
    fd[a] += 1;
    up[a] += 1;
    const int hi = velOff[a] + indexOf(up, fd), lo = velOff[a] + indexOf(k, fd);
#if defined(CUT_FACES)  // a cut obstacle's faces: the flux through their open part
    d += double(open[hi]) * double(vel[hi]) - double(open[lo]) * double(vel[lo]);
#else
    d += double(vel[hi]) - double(vel[lo]);
#endif
  }
  d0[i] = solid[i] != 0u ? 0.0lf : d * -invH;  // (solid: the cells without a pressure)
#elif defined(MODE_WARM_START)  // d0 = phi, d1 = rate_prev
  const double rate = d0[i] / lastDt;
  d0[i] = dt * (extrapolate ? 2.0lf * rate - d1[i] : rate);
  d1[i] = rate;
#elif defined(MODE_GRADIENT)  // d0 = phi
  if (fixedFace[velOff[axis] + i] != 0u) return;
  const ivec3 k = coordsOf(i, faceDims());
  ivec3 lo = k, hi = k;
  lo[axis] -= 1;
  if (periodic[axis] != 0) {
    if (lo[axis] < 0) lo[axis] += cells[axis];
    if (hi[axis] >= cells[axis]) hi[axis] -= cells[axis];
  }
  double pl, ph;
  if (lo[axis] < 0) {  // outflow on the low side: ghost phi = -phi
    ph = d0[indexOf(hi, cells)];
    pl = -ph;
  } else if (hi[axis] >= cells[axis]) {
    pl = d0[indexOf(lo, cells)];
    ph = -pl;
  } else {
    pl = d0[indexOf(lo, cells)];
    ph = d0[indexOf(hi, cells)];
  }
  vel[velOff[axis] + i] = float(double(vel[velOff[axis] + i]) - (ph - pl) * invH);
#endif
}
