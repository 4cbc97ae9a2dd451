// The projection's stages besides its solve (fluid/pressure_projection.cpp), one MODE each,
// the formulas kernels/projection.inc's, in XREAL (the solve's solution type):
// MODE_DIVERGENCE       rhs = -(div u) / h through the faces' open fractions, 0 in cells
//                       without a pressure
// MODE_WARM_START       phi = dt (2 rate - rate_prev) (or dt rate), rate = phi / last dt
//                       (rate_prev in float, as the CPU keeps it)
// MODE_GRADIENT         u_a -= d phi / d x_a on free faces (outflow: ghost phi = -phi)
// MODE_CLEAR_PHI        phi = 0 in the cells a moving solid covers (solid flag 2: no pressure, inside)
// SOLID_FLUX            the divergence adds a moving solid's flux through the closed parts of the faces
#if !defined(MODE_DIVERGENCE)
#define D0_REAL XREAL  // phi, the pressure solve's solution
#endif
#define D1_REAL float  // rate_prev
#include "fluid_faces.glsl"
#define PP_FN XREAL
#define PP_REAL XREAL
#include "projection.inc"
#if defined(SOLID_FLUX)
layout(std430, binding = 13) readonly buffer SolidFlux { double solidFlux[]; };
#endif

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_DIVERGENCE)
  const ivec3 k = coordsOf(i, cells);
  XREAL d = XREAL(0);
  for (int a = 0; a < DIM; ++a) {
    ivec3 fd = cells, up = k;
    fd[a] += 1;
    up[a] += 1;
    const int hi = velOff[a] + indexOf(up, fd), lo = velOff[a] + indexOf(k, fd);
#if defined(CUT_FACES)  // a cut obstacle's faces: the flux through their open part
    d += ppAxisFlux(XREAL(open[hi]), XREAL(vel[hi]), XREAL(open[lo]), XREAL(vel[lo]));
#else
    d += ppAxisFlux(XREAL(1), XREAL(vel[hi]), XREAL(1), XREAL(vel[lo]));
#endif
  }
  XREAL r = d * -invH;
#if defined(SOLID_FLUX)
  r += XREAL(solidFlux[i]) * -invH;
#endif
  d0[i] = solid[i] != 0u ? REAL(0) : REAL(r);  // (solid: the cells without a pressure)
#elif defined(MODE_CLEAR_PHI)  // d0 = phi
  if (solid[i] == 2u) d0[i] = XREAL(0);
#elif defined(MODE_WARM_START)  // d0 = phi, d1 = rate_prev
  const XREAL rate = d0[i] * invLastDt;
  d0[i] = ppWarmStart(rate, XREAL(d1[i]), dt, extrapolate);
  d1[i] = float(rate);
#elif defined(MODE_GRADIENT)  // d0 = phi
  if (fixedFace[velOff[axis] + i] != 0u) return;
  const ivec3 k = coordsOf(i, faceDims());
  ivec3 lo = k, hi = k;
  lo[axis] -= 1;
  if (periodic[axis] != 0) {
    if (lo[axis] < 0) lo[axis] += cells[axis];
    if (hi[axis] >= cells[axis]) hi[axis] -= cells[axis];
  }
  XREAL pl, ph;
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
  vel[velOff[axis] + i] = float(ppProjectedFace(XREAL(vel[velOff[axis] + i]), pl, ph, invH));
#endif
}
