// Bi-/trilinear sampling as core/linear_sampler.h (non-periodic axes clamp to
// the outermost samples, periodic axes wrap; a face grid carries one
// duplicate sample) and the MAC velocity at a point, in fluid cell units.
// Needs `vel` (the D components at velOff[a]), `cells`, `periodic`.
struct Tap { int lo, hi; float t; };

// AxisSamples::at (core/linear_sampler.h)
Tap tapAt(float p, int n, int period, bool wrap, float off) {
  precise float g = p - off;
  if (isnan(g)) g = 0.0;
  Tap r;
  if (!wrap) {
    g = clamp(g, 0.0, float(n - 1));
    const int i = min(int(g), max(n - 2, 0));
    r.lo = i;
    r.hi = min(i + 1, n - 1);
    r.t = g - float(i);
    return r;
  }
  const float f = floor(g);
  int i = int(f - float(period) * floor(f / float(period)));
  if (i >= period) i -= period;
  int j = i + 1;
  if (j == period) j = n > period ? period : 0;
  r.lo = i;
  r.hi = j;
  r.t = g - f;
  return r;
}

// The 2^DIM corners' indices in a grid of dims d, x first (as interpolate<D>).
void corners(Tap t[3], ivec3 d, out int idx[8]) {
  for (int k = 0; k < (1 << DIM); ++k)
    idx[k] = indexOf(ivec3((k & 1) != 0 ? t[0].hi : t[0].lo, (k & 2) != 0 ? t[1].hi : t[1].lo,
                           (k & 4) != 0 ? t[2].hi : t[2].lo), d);
}
// kernels/multilinear.inc in float; `precise`: no fused multiply-adds, so
// each operation rounds as the CPU's does.
#define ML_FN float
#define ML_T float
#ifndef PRECISE
#define PRECISE precise
#endif
#include "multilinear.inc"
float blend(float v[8], Tap t[3]) {
  if (DIM == 2) return bilinear(v[0], v[1], v[2], v[3], t[0].t, t[1].t);
  return trilinear(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], t[0].t, t[1].t, t[2].t);
}

// Velocity component a at p: on its faces along a, at centres along the others.
float velocityAt(int a, vec3 p) {
  Tap t[3];
  ivec3 d = cells;
  d[a] += 1;
  for (int b = 0; b < 3; ++b) {
    if (b >= DIM) { t[b] = Tap(0, 0, 0.0); continue; }
    t[b] = b == a ? tapAt(p[b], cells[b] + 1, cells[b], periodic[b] != 0, 0.0)
                  : tapAt(p[b], cells[b], cells[b], periodic[b] != 0, 0.5);
  }
  int idx[8];
  corners(t, d, idx);
  float v[8];
  for (int k = 0; k < (1 << DIM); ++k) v[k] = vel[velOff[a] + idx[k]];
  return blend(v, t);
}

