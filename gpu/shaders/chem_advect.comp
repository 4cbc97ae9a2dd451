// The chemicals carried by the fluid (coupling/chemical_advection.cpp; seed
// 001 eq. 18-20), two species in double precision, one invocation a
// reaction-diffusion cell. MODE_ADVECT: the cell centre is traced back
// through the fluid's MAC velocity (midpoint rule, single precision, in
// fluid cell units), and both species take their value at the foot, linear
// or Catmull-Rom (clamped to the linear stencil's range); past the outermost
// cell centre of an inflow side the value blends into the inflow
// concentration. MODE_SOLIDS: solid cells take the solid values.
layout(std430, binding = 0) readonly buffer Vel { float vel[]; };
layout(std430, binding = 1) readonly buffer S0 { double s0[]; };
layout(std430, binding = 2) readonly buffer S1 { double s1[]; };
layout(std430, binding = 3) buffer T0 { double t0[]; };
layout(std430, binding = 4) buffer T1 { double t1[]; };
layout(std430, binding = 5) readonly buffer Solid { uint solid[]; };

uniform ivec3 cells, periodic, velOff;  // the fluid's
uniform ivec3 rdCells;
uniform float c;          // dt / h_fluid
uniform float r;          // h_rd / h_fluid
uniform ivec3 inflowLo, inflowHi;
uniform bool inflow;
uniform dvec2 inValue, solidValue;
uniform bool cubic;

#include "mac_sampling.glsl"
#define WEIGHTS4(name, t, w) void name(double t, precise out double w[4])
#define PRECISE precise
#include "interpolation.inc"

// j wrapped into [0, n) (GLSL's % is undefined for negative operands)
int wrapIndex(int j, int n) { return j >= 0 ? j % n : (n - 1) - ((-j - 1) % n); }

// The sample indices and weights of one axis (axisWeights): linear takes
// k = 1, 2; cubic k = 0..3 at i - 1 .. i + 2.
void axisWeights(double x, int n, bool wrap, out int index[4], out double w[4]) {
  if (!wrap) x = clamp(x, 0.0lf, double(n - 1));
  const double f = floor(x);
  precise double t = x - f;
  const int i = int(f);
  for (int k = 0; k < 4; ++k) {
    const int j = i - 1 + k;
    index[k] = wrap ? wrapIndex(j, n) : clamp(j, 0, n - 1);
  }
  if (!cubic) {
    w[0] = 0.0lf; w[1] = 1.0lf - t; w[2] = t; w[3] = 0.0lf;
    return;
  }
  catmullRomWeights(t, w);
}

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
  double w = 0.0lf;
  if (inflow)
    for (int a = 0; a < DIM; ++a) {
      const double x = double(foot[a]);
      if (inflowLo[a] != 0) w = max(w, clamp(-2.0lf * x, 0.0lf, 1.0lf));
      if (inflowHi[a] != 0) w = max(w, clamp(2.0lf * (x - double(rdCells[a] - 1)), 0.0lf, 1.0lf));
    }
  if (w >= 1.0lf) {
    t0[i] = inValue.x;
    t1[i] = inValue.y;
    return;
  }
  int idx[3][4];
  double wt[3][4];
  for (int a = 0; a < 3; ++a) {
    if (a < DIM) {
      axisWeights(double(foot[a]), rdCells[a], periodic[a] != 0, idx[a], wt[a]);
    } else {
      for (int q = 0; q < 4; ++q) { idx[a][q] = 0; wt[a][q] = q == 1 ? 1.0lf : 0.0lf; }
    }
  }
  const int first = cubic ? 0 : 1, count = cubic ? 4 : 2;
  const int nx = rdCells.x, ny = rdCells.y;
  precise dvec2 sum = dvec2(0.0lf);
  dvec2 lo = dvec2(1e300lf), hi = dvec2(-1e300lf);
  const int kz0 = DIM == 3 ? first : 1, kz1 = DIM == 3 ? first + count : 2;
  for (int kz = kz0; kz < kz1; ++kz)
    for (int ky = first; ky < first + count; ++ky)
      for (int kx = first; kx < first + count; ++kx) {
        const int at = idx[0][kx] + nx * (idx[1][ky] + ny * idx[2][kz]);
        precise double wk = wt[0][kx] * wt[1][ky];
        if (DIM == 3) wk = wk * wt[2][kz];
        const dvec2 v = dvec2(s0[at], s1[at]);
        sum += wk * v;
        if ((kx == 1 || kx == 2) && (ky == 1 || ky == 2) && (DIM == 2 || kz == 1 || kz == 2)) {
          lo = min(lo, v);
          hi = max(hi, v);
        }
      }
  if (cubic) sum = clamp(sum, lo, hi);  // no new extrema
  precise dvec2 out_ = w * inValue + (1.0lf - w) * sum;
  t0[i] = out_.x;
  t1[i] = out_.y;
#endif
}
