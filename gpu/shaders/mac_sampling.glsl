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
// `precise`: no fused multiply-adds, so each operation rounds as the CPU's does.
float blend(float v[8], Tap t[3]) {
  precise float a0 = v[0] + t[0].t * (v[1] - v[0]), a1 = v[2] + t[0].t * (v[3] - v[2]);
  precise float y0 = a0 + t[1].t * (a1 - a0);
  if (DIM == 2) return y0;
  precise float b0 = v[4] + t[0].t * (v[5] - v[4]), b1 = v[6] + t[0].t * (v[7] - v[6]);
  precise float y1 = b0 + t[1].t * (b1 - b0);
  precise float r = y0 + t[2].t * (y1 - y0);
  return r;
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

