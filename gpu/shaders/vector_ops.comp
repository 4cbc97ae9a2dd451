// Element-wise steps on real vectors (REAL: float or double; every sum
// accumulated in double from exact products). The reaction-diffusion layer's, one
// invocation a cell:
// OP_SCALE_ADD  y = a x + b y (a, b uniforms)
// OP_CLAMP_ZERO y = max(y, 0)
// OP_THETA_STEP y += ca x + cb (-z + cc q): the theta scheme's explicit part
//               (x = R, y = the species, z = A y, q = the Dirichlet faces), in
//               rd_solver.cpp's order, no fused multiply-adds
// OP_HOLD       y = x where held[i] != 0 (fixed regions; frozen species hold everywhere)
// OP_ADD_FACES  y += ca faces (x: the Dirichlet faces per cell)
// DOT_PARTIAL: the preconditioned CG's (core/pcg.cpp), with the scalars read
// on the device (no round trip) and the reductions next to them fused in
// (fused_sum.glsl), over the reduction's groups, bitwise separate passes:
// OP_UPDATE_XR  x += alpha p, r -= alpha q, alpha = S[rz] / S[pq], S[pq]
//               summed from its partials (slots.y) in each group; the
//               partials of r . r into slots.z; and, slots.w >= 0, the
//               diagonal preconditioner too: w = r / diag, r . w into slots.w
// OP_UPDATE_P   p = z + beta p, beta = S[rzNew] / S[rz] (first: p = z),
//               S[rzNew] summed from its partials (slots.x), and stored;
//               GATE: then group 0 makes the solve's check (gate_logic.glsl)
//               with S[pq] and S[rr] summed from theirs (slots.z, slots.w)
// OP_TO_FLOAT   f = float(x / sqrt(S[rr])) (into a multigrid level), S[rr]
//               summed from its partials (slots.x), and stored
// OP_JACOBI     y = x / diag (0 on inactive cells), the partials of x . y
//               into slots.x
// OP_FROM_FLOAT y = double(f) sqrt(S[rr]), the partials of z . y into slots.y
// OP_SUB_MEAN   x -= S[sum] / S[count] on active cells, 0 on inactive ones,
//               S[sum] summed from its partials (slots.x), and stored, first
// SWEEP_FIRST (OP_TO_FLOAT) and SWEEP_LAST (OP_FROM_FLOAT): the multigrid's
// finest level (f: its b, then its x) with its first pre-smoothing colour
// (colour 0 from x = 0, written into levelX) or its last post-smoothing
// colour (colour 0, into f) made first, as laplace.comp's MODE_SMOOTH
// does (gpu_multigrid.cpp)
#if defined(OP_UPDATE_XR) || defined(OP_SUB_MEAN)
layout(std430, binding = 0) buffer X { XREAL x[]; };  // a solve's solution
#else
layout(std430, binding = 0) buffer X { REAL x[]; };
#endif
layout(std430, binding = 1) buffer Y { REAL y[]; };
layout(std430, binding = 2) buffer Z { REAL z[]; };
layout(std430, binding = 3) buffer Q { REAL q[]; };
layout(std430, binding = 4) buffer F { float f[]; };
layout(std430, binding = 5) readonly buffer Diag { float diag[]; };
layout(std430, binding = 6) buffer Scalars { double S[]; };
layout(std430, binding = 7) readonly buffer Held { uint held[]; };

uniform int n;
uniform ivec4 slots;   // the scalar slots each op reads
uniform bool first;
uniform REAL ca, cb, cc;

#if defined(DOT_PARTIAL)
layout(std430, binding = 8) buffer Partials { double partial[]; };
layout(std430, binding = 9) buffer W { REAL w[]; };
#include "fused_sum.glsl"
#if defined(GATE)
#define GATE_BASE 10
#define GATE_ARGS 11
#define GATE_STATE 12
#include "gate_logic.glsl"
#endif

#if defined(SWEEP_FIRST) || defined(SWEEP_LAST)
uniform ivec3 levelDims;
uniform double levelScale;
bool colour0(int i) {
  const ivec3 c = coordsOf(i, levelDims);
  return ((c.x + c.y + c.z) & 1) == 0;
}
#endif
#if defined(SWEEP_FIRST)
layout(std430, binding = 10) buffer LevelX { float levelX[]; };
// The sweep's update from x = 0: the neighbours' sum is +0.
float firstSweepAt(int i, float bi) {
  if (!colour0(i) || diag[i] <= 0.0) return 0.0;
  precise float t = bi / float(levelScale) + 0.0;
  return t / diag[i];
}
#endif
#if defined(SWEEP_LAST)
layout(std430, binding = 11) readonly buffer W0 { float w0[]; };
layout(std430, binding = 12) readonly buffer W1 { float w1[]; };
layout(std430, binding = 13) readonly buffer W2 { float w2[]; };
layout(std430, binding = 14) readonly buffer LevelB { float levelB[]; };
#define STENCIL_REAL float
#define LX(i) f[i]
#define LW(a, i) ((a) == 0 ? w0[i] : (a) == 1 ? w1[i] : w2[i])
#include "laplace_stencil.glsl"
// Cell i's x after the sweep's last colour (written where it changes).
float lastSweepAt(int i) {
  if (!colour0(i)) return f[i];
  const float d = diag[i];
  const float xi = d <= 0.0 ? 0.0 : gaussSeidelAt(coordsOf(i, levelDims), i, levelDims, levelScale, levelB[i], d);
  f[i] = xi;
  return xi;
}
#endif

REAL jacobi(REAL r, int i) { return diag[i] > 0.0 ? r / REAL(diag[i]) : REAL(0); }

void main() {
  const int groups = int(gl_NumWorkGroups.x);
#if defined(OP_UPDATE_XR)  // x, y = r, z = p, q
  const double pq = finalSum(slots.y, groups);
  const double alphaD = pq > 0.0lf ? S[slots.x] / pq : 0.0lf;  // 0 on breakdown
  const REAL alpha = REAL(alphaD);
  double rr = 0.0lf, rw = 0.0lf;
  FOR_REDUCTION(i, n) {
    x[i] += XREAL(alphaD) * XREAL(z[i]);
    const REAL r = y[i] - alpha * q[i];
    y[i] = r;
    rr = rr + double(r) * double(r);
    if (slots.w >= 0) {
      const REAL wi = jacobi(r, i);
      w[i] = wi;
      rw = rw + double(r) * double(wi);
    }
  }
  if (slots.w >= 0)
    writePartials(dvec2(rr, rw), slots.z, slots.w);
  else
    writePartial(rr, slots.z);
#elif defined(OP_UPDATE_P)  // x = z, y = p
  const double rzNew = finalSum(slots.x, groups);
  const REAL beta = REAL(first ? 0.0lf : rzNew / S[slots.y]);
  FOR_REDUCTION(i, n) y[i] = first ? x[i] : x[i] + beta * y[i];
  if (gl_WorkGroupID.x == 0u && gl_LocalInvocationID.x == 0u) S[slots.x] = rzNew;
#if defined(GATE)
  if (gl_WorkGroupID.x == 0u) checkAsLastPass(slots.z, slots.w);
#endif
#elif defined(OP_TO_FLOAT)
  const double rr = finalSum(slots.x, groups);
  FOR_REDUCTION(i, n) {
    const float bi = float(double(x[i]) / sqrt(rr));
    f[i] = bi;
#if defined(SWEEP_FIRST)
    levelX[i] = firstSweepAt(i, bi);
#endif
  }
  if (gl_WorkGroupID.x == 0u && gl_LocalInvocationID.x == 0u) S[slots.x] = rr;
#elif defined(OP_JACOBI)  // x = r, y = z
  double s = 0.0lf;
  FOR_REDUCTION(i, n) {
    const REAL zi = jacobi(x[i], i);
    y[i] = zi;
    s = s + double(x[i]) * double(zi);
  }
  writePartial(s, slots.x);
#elif defined(OP_SUB_MEAN)
  const double sum = finalSum(slots.x, groups);
  FOR_REDUCTION(i, n) x[i] = diag[i] > 0.0 ? x[i] - XREAL(sum / S[slots.y]) : XREAL(0);
  if (gl_WorkGroupID.x == 0u && gl_LocalInvocationID.x == 0u) S[slots.x] = sum;
#elif defined(OP_FROM_FLOAT)  // y = z, z = r
  double s = 0.0lf;
  FOR_REDUCTION(i, n) {
#if defined(SWEEP_LAST)
    const REAL zi = REAL(double(lastSweepAt(i)) * sqrt(S[slots.x]));
#else
    const REAL zi = REAL(double(f[i]) * sqrt(S[slots.x]));
#endif
    y[i] = zi;
    s = s + double(z[i]) * double(zi);
  }
  writePartial(s, slots.y);
#endif
}
#else
void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(OP_SCALE_ADD)
  y[i] = ca * x[i] + cb * y[i];
#elif defined(OP_THETA_STEP)
  precise REAL L = -z[i] + cc * q[i];
  precise REAL v = y[i] + (cb != REAL(0) ? ca * x[i] + cb * L : ca * x[i]);
  y[i] = v;
#elif defined(OP_CLAMP_ZERO)
  y[i] = max(y[i], REAL(0));
#elif defined(OP_HOLD)
  if (held[i] != 0u) y[i] = x[i];
#elif defined(OP_ADD_FACES)
  y[i] += ca * x[i];
#endif
}
#endif
