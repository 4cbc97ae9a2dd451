// One semi-Lagrangian pass (fluid/advection.cpp; Stam 1999, Kim & Lin eq.
// 19-20) over every sample of a grid: the midpoint back-trace through the
// MAC velocity, then bi-/trilinear interpolation of src at the foot, with
// the same boundary rules as core/linear_sampler.h (non-periodic axes clamp
// to the outermost samples, periodic axes wrap; a face grid carries one
// duplicate sample). Positions are in fluid cell units. With LIMITS the
// stencil's min and max are written too (the MacCormack/BFECC limiters).
layout(std430, binding = 0) readonly buffer Vel { float vel[]; };   // the D components at velOff[a]
layout(std430, binding = 1) readonly buffer Src { float src[]; };   // at srcOff
layout(std430, binding = 2) writeonly buffer Dst { float dst[]; };  // at dstOff
layout(std430, binding = 3) writeonly buffer Lo { float lo[]; };
layout(std430, binding = 4) writeonly buffer Hi { float hi[]; };

uniform ivec3 cells;     // fluid cells (1 beyond DIM)
uniform ivec3 periodic;
uniform ivec3 velOff;
uniform float c;         // dt / h (negative: a backward pass)
uniform ivec3 sdims;     // the advected grid's samples
uniform vec3 soff;       // sample k sits at k + soff (cell units)
uniform int srcOff, dstOff;

#include "mac_sampling.glsl"

void main() {
  const int i = flatIndex();
  if (i >= sdims.x * sdims.y * sdims.z) return;
  const ivec3 k = coordsOf(i, sdims);
  precise vec3 p = vec3(k) + soff, m = p, foot = p;
  for (int a = 0; a < DIM; ++a) m[a] = p[a] - 0.5 * c * velocityAt(a, p);
  for (int a = 0; a < DIM; ++a) foot[a] = p[a] - c * velocityAt(a, m);
  Tap t[3];
  for (int b = 0; b < 3; ++b) {
    // a face grid's period is its cells, one sample fewer than it has
    const int period = soff[b] == 0.0 ? sdims[b] - 1 : sdims[b];
    t[b] = b < DIM ? tapAt(foot[b], sdims[b], period, periodic[b] != 0, soff[b]) : Tap(0, 0, 0.0);
  }
  int idx[8];
  corners(t, sdims, idx);
  float v[8];
  for (int q = 0; q < (1 << DIM); ++q) v[q] = src[srcOff + idx[q]];
  dst[dstOff + i] = blend(v, t);
#if defined(LIMITS)
  float mn = v[0], mx = v[0];
  for (int q = 1; q < (1 << DIM); ++q) {
    mn = min(mn, v[q]);
    mx = max(mx, v[q]);
  }
  lo[i] = mn;
  hi[i] = mx;
#endif
}
