// The chemicals carried by the fluid (coupling/chemical_advection.cpp; seed
// 001 eq. 18-20), two species in REAL (float or REAL), one invocation a
// reaction-diffusion cell. MODE_ADVECT: the cell centre is traced back
// through the fluid's MAC velocity (midpoint rule, single precision, in
// fluid cell units), and both species take their value at the foot, linear
// or Catmull-Rom (clamped to the linear stencil's range); past the outermost
// cell centre of an inflow side the value blends into the inflow
// concentration; with `spline`, the cubic B-spline of the coefficients C0,
// C1 (coupling/bspline.h: mirrored at walls, wrapped on periodic axes),
// clamped to the linear stencil's range; with `bfecc`, the linear samples of
// the error-compensated 1.5 S - 0.5 C, C the backward step's values, clamped
// the same way (chemical_advection.cpp's bfecc). MODE_SOLIDS: solid cells take the
// solid values. MODE_PREFILTER: one invocation a line along `axis` of the
// coefficients T0, in place (kernels/bspline_prefilter.inc, with the powers
// of the pole the host computed).
layout(std430, binding = 0) readonly buffer Vel { float vel[]; };
layout(std430, binding = 1) readonly buffer S0 { REAL s0[]; };
layout(std430, binding = 2) readonly buffer S1 { REAL s1[]; };
layout(std430, binding = 3) buffer T0 { REAL t0[]; };
layout(std430, binding = 4) buffer T1 { REAL t1[]; };
layout(std430, binding = 5) readonly buffer Solid { uint solid[]; };
layout(std430, binding = 6) readonly buffer C0 { REAL c0[]; };
layout(std430, binding = 7) readonly buffer C1 { REAL c1[]; };

uniform ivec3 cells, periodic, velOff;  // the fluid's
uniform ivec3 rdCells;
uniform float c;          // dt / h_fluid
uniform float r;          // h_rd / h_fluid
uniform ivec3 inflowLo, inflowHi;
uniform bool inflow;
uniform REAL2 inValue, solidValue;
uniform bool cubic, spline;
uniform bool bfecc;       // BFECC's last pass: samples of 1.5 S - 0.5 C (C: the backward step), limited to S's range
uniform int axis, lines;
uniform REAL z, zn, z2n;  // the pole, z^n and z^(2n - 2) along the axis

#include "mac_sampling.glsl"
#define WEIGHTS4(name, t, w) void name(REAL t, precise out REAL w[4])
#define W_REAL REAL
#ifndef PRECISE
#define PRECISE precise
#endif
#include "interpolation.inc"

// j wrapped into [0, n) (GLSL's % is undefined for negative operands)
int wrapIndex(int j, int n) { return j >= 0 ? j % n : (n - 1) - ((-j - 1) % n); }

// The sample indices and weights of one axis (axisWeights): linear takes
// k = 1, 2; cubic k = 0..3 at i - 1 .. i + 2.
void axisWeights(REAL x, int n, bool wrap, out int index[4], out REAL w[4]) {
  if (!wrap) x = clamp(x, REAL(0.0), REAL(n - 1));
  const REAL f = floor(x);
  precise REAL t = x - f;
  const int i = int(f);
  for (int k = 0; k < 4; ++k) {
    const int j = i - 1 + k;
    index[k] = wrap ? wrapIndex(j, n) : clamp(j, 0, n - 1);
  }
  if (!cubic) {
    w[0] = REAL(0.0); w[1] = REAL(1.0) - t; w[2] = t; w[3] = REAL(0.0);
    return;
  }
  catmullRomWeights(t, w);
}

// The spline's indices along an axis (splineAxis): i - 1 .. i + 2 mirrored
// at walls or wrapped, the linear neighbours i0, i1 and the fraction t.
void splineAxis(REAL x, int n, bool wrap, out int index[4], out int i0, out int i1, out REAL t) {
  if (!wrap) x = clamp(x, REAL(0.0), REAL(n - 1));
  const REAL f = floor(x);
  t = x - f;
  const int i = int(f);
  for (int k = 0; k < 4; ++k) {
    int j = i - 1 + k;
    if (wrap) {
      j = wrapIndex(j, n);
    } else if (n == 1) {
      j = 0;
    } else {
      if (j < 0) j = -j;
      if (j > n - 1) j = 2 * (n - 1) - j;
      j = clamp(j, 0, n - 1);
    }
    index[k] = j;
  }
  i0 = wrap ? wrapIndex(i, n) : i;
  i1 = wrap ? wrapIndex(i + 1, n) : min(i + 1, n - 1);
}

#if defined(MODE_PREFILTER)
#define BS_REAL REAL
#define BS_LINE int base, int stride
#define BS_AT(k) t0[base + stride * (k)]
#include "bspline_prefilter.inc"

void main() {
  const int line = flatIndex();
  if (line >= lines) return;
  const int n = rdCells[axis];
  if (n < 2) return;
  // the line's first cell: the others' coordinates from `line`, x fastest
  ivec3 start = ivec3(0);
  int rest = line;
  for (int b = 0; b < DIM; ++b) {
    if (b == axis) continue;
    start[b] = rest % rdCells[b];
    rest /= rdCells[b];
  }
  const int base = indexOf(start, rdCells);
  const int stride = axis == 0 ? 1 : axis == 1 ? rdCells.x : rdCells.x * rdCells.y;
  bsplinePrefilterLine(base, stride, n, periodic[axis] != 0, z, zn, z2n);
}
#else
void main() {
  const int i = flatIndex();
  if (i >= rdCells.x * rdCells.y * rdCells.z) return;
#if defined(MODE_SOLIDS)
  if (solid[i] != 0u) {
    t0[i] = solidValue.x;
    t1[i] = solidValue.y;
  }
#else
  const ivec3 k = coordsOf(i, rdCells);
  // the foot, in the reaction-diffusion grid's coordinates (centre k at k)
  precise vec3 p = vec3(0.0), m = vec3(0.0), foot = vec3(0.0);
  for (int a = 0; a < DIM; ++a) p[a] = (float(k[a]) + 0.5) * r;
  for (int a = 0; a < DIM; ++a) m[a] = p[a] - (0.5 * c) * velocityAt(a, p);
  const float invR = 1.0 / r;
  for (int a = 0; a < DIM; ++a) foot[a] = (p[a] - c * velocityAt(a, m)) * invR - 0.5;
  REAL w = REAL(0.0);
  if (inflow)
    for (int a = 0; a < DIM; ++a) {
      const REAL x = REAL(foot[a]);
      if (inflowLo[a] != 0) w = max(w, clamp(-REAL(2.0) * x, REAL(0.0), REAL(1.0)));
      if (inflowHi[a] != 0) w = max(w, clamp(REAL(2.0) * (x - REAL(rdCells[a] - 1)), REAL(0.0), REAL(1.0)));
    }
  if (w >= REAL(1.0)) {
    t0[i] = inValue.x;
    t1[i] = inValue.y;
    return;
  }
  if (spline) {
    int sidx[3][4], i0[3], i1[3];
    REAL sw[3][4];
    for (int a = 0; a < 3; ++a) {
      if (a < DIM) {
        REAL t;
        splineAxis(REAL(foot[a]), rdCells[a], periodic[a] != 0, sidx[a], i0[a], i1[a], t);
        bsplineWeights(t, sw[a]);
      } else {
        for (int q = 0; q < 4; ++q) { sidx[a][q] = 0; sw[a][q] = REAL(1.0); }
        i0[a] = 0;
        i1[a] = 0;
      }
    }
    precise REAL2 ssum = REAL2(REAL(0.0));
    for (int kz = 0; kz < (DIM == 3 ? 4 : 1); ++kz)
      for (int ky = 0; ky < 4; ++ky)
        for (int kx = 0; kx < 4; ++kx) {
          const int at = sidx[0][kx] + rdCells.x * (sidx[1][ky] + rdCells.y * sidx[2][kz]);
          precise REAL wk = sw[0][kx] * sw[1][ky];
          if (DIM == 3) wk = wk * sw[2][kz];
          ssum += wk * REAL2(c0[at], c1[at]);
        }
    REAL2 slo = REAL2(REAL_HUGE), shi = REAL2(-REAL_HUGE);
    for (int q = 0; q < (1 << DIM); ++q) {
      const int at = ((q & 1) != 0 ? i1[0] : i0[0]) + rdCells.x * (((q & 2) != 0 ? i1[1] : i0[1]) +
                                                                  rdCells.y * ((q & 4) != 0 ? i1[2] : i0[2]));
      const REAL2 v = REAL2(s0[at], s1[at]);
      slo = min(slo, v);
      shi = max(shi, v);
    }
    ssum = clamp(ssum, slo, shi);
    precise REAL2 sout = w * inValue + (REAL(1.0) - w) * ssum;
    t0[i] = sout.x;
    t1[i] = sout.y;
    return;
  }
  int idx[3][4];
  REAL wt[3][4];
  for (int a = 0; a < 3; ++a) {
    if (a < DIM) {
      axisWeights(REAL(foot[a]), rdCells[a], periodic[a] != 0, idx[a], wt[a]);
    } else {
      for (int q = 0; q < 4; ++q) { idx[a][q] = 0; wt[a][q] = q == 1 ? REAL(1.0) : REAL(0.0); }
    }
  }
  const int first = cubic ? 0 : 1, count = cubic ? 4 : 2;
  const int nx = rdCells.x, ny = rdCells.y;
  precise REAL2 sum = REAL2(REAL(0.0));
  REAL2 lo = REAL2(REAL_HUGE), hi = REAL2(-REAL_HUGE);
  const int kz0 = DIM == 3 ? first : 1, kz1 = DIM == 3 ? first + count : 2;
  for (int kz = kz0; kz < kz1; ++kz)
    for (int ky = first; ky < first + count; ++ky)
      for (int kx = first; kx < first + count; ++kx) {
        const int at = idx[0][kx] + nx * (idx[1][ky] + ny * idx[2][kz]);
        precise REAL wk = wt[0][kx] * wt[1][ky];
        if (DIM == 3) wk = wk * wt[2][kz];
        const REAL2 v = REAL2(s0[at], s1[at]);
        if (bfecc) {
          precise REAL2 corrected = REAL(1.5) * v - REAL(0.5) * REAL2(c0[at], c1[at]);
          sum += wk * corrected;
        } else {
          sum += wk * v;
        }
        if ((kx == 1 || kx == 2) && (ky == 1 || ky == 2) && (DIM == 2 || kz == 1 || kz == 2)) {
          lo = min(lo, v);
          hi = max(hi, v);
        }
      }
  if (cubic || bfecc) sum = clamp(sum, lo, hi);  // no new extrema
  precise REAL2 out_ = w * inValue + (REAL(1.0) - w) * sum;
  t0[i] = out_.x;
  t1[i] = out_.y;
#endif
}
#endif
