// The 5-/7-point systems of core/laplace_system.h on the GPU:
//   (A x)_i = scale (c_i x_i + sum_f w_f (x_i - x_j(f))),  diag = c + sum_f w_f,
// w[a]_i couples i and i + e_a (0 across a non-periodic edge), a cell with
// diag 0 is inactive. MODE_APPLY: y = A x; MODE_RESIDUAL (with DOT_PARTIAL
// only): y = b - A x (both in the CPU's form: c and the face differences,
// not the rounded diagonal);
// MODE_SMOOTH: one colour of a red-black Gauss-Seidel sweep,
// x_i = (b_i / scale + sum_f w_f x_j) / diag_i; MODE_JACOBI: y = x + omega
// (that update - x) (levels whose odd periodic axis mixes the colours).
// REAL (the host's) is the PCG vectors' precision, float for the multigrid
// levels; sums are accumulated in double from exact products.
// CROSS (apply and residual): the mixed terms of a tensor diffusion operator
// (core/anisotropic_system.h), pair couplings K (x_i - x_q) with the four
// diagonal neighbours in each plane; the preconditioners take the axis part.
// DOT_PARTIAL (apply and residual): with the partial pass of the
// dot product the PCG takes next (see main).
#if defined(MODE_RESIDUAL)
layout(std430, binding = 0) buffer X { XREAL x[]; };  // the solution (XREAL)
#else
layout(std430, binding = 0) buffer X { REAL x[]; };
#endif
layout(std430, binding = 1) buffer Y { REAL y[]; };
#if defined(MODE_RESIDUAL) && defined(DOT_PARTIAL)
layout(std430, binding = 2) buffer B { REAL b[]; };  // (made mean-free in place)
#else
layout(std430, binding = 2) readonly buffer B { REAL b[]; };
#endif
layout(std430, binding = 3) readonly buffer W0 { float w0[]; };
layout(std430, binding = 4) readonly buffer W1 { float w1[]; };
layout(std430, binding = 5) readonly buffer W2 { float w2[]; };
layout(std430, binding = 6) readonly buffer Diag { float diag[]; };
layout(std430, binding = 7) readonly buffer C { float cTerm[]; };

uniform ivec3 dims;
uniform double scale;
#define CELLS (dims.x * dims.y * dims.z)
uniform int colour;    // MODE_SMOOTH: the cells with (x + y + z) % 2 == colour (-1: every cell)
#if defined(CELL_LIST)
// MODE_SMOOTH on the cells cellList[listFirst ..] alone (listCount of them)
layout(std430, binding = 8) readonly buffer Cells { uint cellList[]; };
uniform int listFirst;
uniform int listCount;
#endif
uniform float omega;   // MODE_JACOBI

#if defined(CROSS)
// K(p, p + e_a + e_b) and K(p, p + e_a - e_b) of plane 0 (xy), 1 (xz), 2 (yz)
layout(std430, binding = 8) readonly buffer Mixed { float k[]; } mixed[2 * (DIM == 3 ? 3 : 1)];

// The mixed terms' sum at cell c (index i): the couplings of +up and +down
// live at i, those of -up and -down at the neighbour (0 across a wall).
REAL crossSum(ivec3 c, int i) {
  REAL s = REAL(0);
  const REAL xi = x[i];
  for (int p = 0; p < (DIM == 3 ? 3 : 1); ++p) {
    const int a = p == 2 ? 1 : 0, b = p == 0 ? 1 : 2;
    const ivec3 up = stepWrapped(stepWrapped(c, a, 1, dims), b, 1, dims);
    const ivec3 down = stepWrapped(stepWrapped(c, a, 1, dims), b, -1, dims);
    const ivec3 upNeg = stepWrapped(stepWrapped(c, a, -1, dims), b, -1, dims);
    const ivec3 downNeg = stepWrapped(stepWrapped(c, a, -1, dims), b, 1, dims);
    const int q0 = indexOf(up, dims);
    const int q1 = indexOf(down, dims);
    const int q2 = indexOf(upNeg, dims);
    const int q3 = indexOf(downNeg, dims);
    s += REAL(mixed[2 * p].k[i]) * (xi - x[q0]);
    s += REAL(mixed[2 * p + 1].k[i]) * (xi - x[q1]);
    s += REAL(mixed[2 * p].k[q2]) * (xi - x[q2]);
    s += REAL(mixed[2 * p + 1].k[q3]) * (xi - x[q3]);
  }
  return s;
}
#endif

float weight(int a, int i) { return a == 0 ? w0[i] : a == 1 ? w1[i] : w2[i]; }
#if defined(P_UPDATE)
// The PCG's p update fused into its operator (MODE_APPLY, DOT_PARTIAL; not
// with CROSS): A is applied to p' = z + beta p (b holds z, x holds p),
// computed where it is read as OP_UPDATE_P computes it, and p' is written.
// P_FIRST: the first iteration's, p' = z.
layout(std430, binding = 8) buffer PNew { REAL pNew[]; };
REAL beta_ = REAL(0);
#if defined(P_FIRST)
#define LX(i) b[(i)]
#else
#define LX(i) (b[(i)] + beta_ * x[(i)])
#endif
#else
#define LX(i) x[(i)]
#endif
#define LW(a, i) weight(a, i)
// The residual is evaluated in double from the REAL vectors (exact for the
// x a float solve holds, so its stopping test and reported residual are
// those of the stored solution); the rest in REAL.
#if defined(MODE_RESIDUAL)
#define OP_REAL double
#else
#define OP_REAL REAL
#endif
#define STENCIL_REAL OP_REAL
#include "laplace_stencil.glsl"

#if defined(MODE_APPLY) || defined(MODE_RESIDUAL)
// A x at active cell i.
OP_REAL axAt(int i) {
  const ivec3 c = coordsOf(i, dims);
  precise OP_REAL ax = operatorTerm(c, i, dims, scale, cTerm[i]);
#if defined(CROSS)
  ax += OP_REAL(scale) * OP_REAL(crossSum(c, i));
#endif
  return ax;
}

// A x (MODE_APPLY) or b - A x (MODE_RESIDUAL, b = bi) at cell i; 0 on
// inactive cells.
OP_REAL operatorAt(int i, OP_REAL bi) {
  if (diag[i] <= 0.0) return OP_REAL(0);
#if defined(MODE_APPLY)
  return axAt(i);
#else
  return bi - axAt(i);
#endif
}
#endif

#if defined(DOT_PARTIAL)
// With the partial pass of x . y (MODE_APPLY: p . Ap) or y . y (MODE_RESIDUAL:
// r . r) into slot `slot` (fused_sum.glsl), over the reduction's groups.
// P_UPDATE: beta = S[rzNew] / S[rz], S[rzNew] summed from its partials
// (pSlots.x, pSlots.y), and stored; then group 0 makes the solve's stopping
// test of the iteration before (gate_logic.glsl) with S[pq] and S[rr] summed
// from theirs (pSlots.z, pSlots.w), as OP_UPDATE_P with GATE does (P_FIRST:
// S[rzNew] only). MODE_RESIDUAL, the solve's first and last residuals: also
// (MEAN_FREE) b made mean-free on the active cells first, its sum summed
// from its partials (mean.x) over the count S[mean.y] (OP_SUB_MEAN's);
// (extra.x >= 0) the partials of b . b; (extra.y >= 0, not with CROSS) the diagonal
// preconditioner, zOut = r / diag, and the partials of r . zOut (OP_JACOBI's);
// (extra.z >= 0) where S[extra.z] (b . b) is 0, x = 0 first
// (OP_ZERO_IF_NO_RHS's; then r = b, A 0 being 0); (extra.w >= 0, not with
// extra.y) the partials of the sum of x on the active cells (reduce.comp's
// TERM_ACTIVE_SUM).
layout(std430, binding = 14) buffer Partials { double partial[]; };
uniform int slot;
#include "fused_sum.glsl"
#if defined(P_UPDATE) || defined(MODE_RESIDUAL)
layout(std430, binding = 15) buffer Scalars { double S[]; };
#endif
#if defined(P_UPDATE) && !defined(P_FIRST)
#define GATE_BASE 10
#define GATE_ARGS 11
#define GATE_STATE 12
#include "gate_logic.glsl"
#endif
#if defined(P_UPDATE)
uniform ivec4 pSlots;
#endif
#if defined(MODE_RESIDUAL)
uniform ivec4 extra;  // (CROSS: the mixed terms take zOut's binding; extra.y < 0)
uniform ivec2 mean;
#if !defined(CROSS)
layout(std430, binding = 8) buffer ZOut { REAL zOut[]; };
#endif
#endif

void main() {
#if defined(P_UPDATE)
  const int groups = int(gl_NumWorkGroups.x);
  const double rzNew = finalSum(pSlots.x, groups);
#if !defined(P_FIRST)
  beta_ = REAL(rzNew / S[pSlots.y]);
#endif
#endif
  double s = 0.0lf;
#if defined(MODE_RESIDUAL)
  double bb = 0.0lf, rz = 0.0lf, xs = 0.0lf;
  const bool noRhs = extra.z >= 0 && S[extra.z] == 0.0lf;
#if defined(MEAN_FREE)  // (a define, not a uniform test: the final sum's barriers in uniform control flow)
  const double bSum = finalSum(mean.x, int(gl_NumWorkGroups.x));
  if (gl_WorkGroupID.x == 0u && gl_LocalInvocationID.x == 0u) S[mean.x] = bSum;
#endif
#endif
  FOR_REDUCTION(i, CELLS) {
#if defined(MODE_RESIDUAL)
    REAL bi = b[i];
#if defined(MEAN_FREE)  // (b is read at i only)
    bi = diag[i] > 0.0 ? bi - REAL(bSum / S[mean.y]) : REAL(0);
    b[i] = bi;
#endif
    OP_REAL v;
    if (noRhs) {
      x[i] = XREAL(0);
      v = diag[i] <= 0.0 ? OP_REAL(0) : bi;
    } else {
      v = operatorAt(i, bi);
    }
#else
    const REAL v = operatorAt(i, REAL(0));
#endif
    y[i] = REAL(v);
#if defined(P_UPDATE)
    const REAL pi = LX(i);
    pNew[i] = pi;
    s = s + double(pi) * double(v);
#elif defined(MODE_APPLY)
    s = s + double(x[i]) * double(v);
#else
    s = s + double(v) * double(v);  // (the residual's own terms, before it is rounded to REAL)
    if (extra.x >= 0) bb = bb + double(bi) * double(bi);
    if (extra.w >= 0) xs = xs + (diag[i] > 0.0 ? (noRhs ? 0.0lf : double(x[i])) : 0.0lf);
#if !defined(CROSS)
    if (extra.y >= 0) {
      const REAL zi = diag[i] > 0.0 ? REAL(v) / REAL(diag[i]) : REAL(0);
      zOut[i] = zi;
      rz = rz + double(REAL(v)) * double(zi);
    }
#endif
#endif
  }
#if defined(MODE_RESIDUAL)
  writePartials(dvec2(s, extra.y >= 0 ? rz : xs), slot, extra.y >= 0 ? extra.y : extra.w);
  if (extra.x >= 0) writePartial(bb, extra.x);
#else
  writePartial(s, slot);
#endif
#if defined(P_UPDATE)
  if (gl_WorkGroupID.x == 0u) {
    if (gl_LocalInvocationID.x == 0u) S[pSlots.x] = rzNew;
#if !defined(P_FIRST)
    checkAsLastPass(pSlots.z, pSlots.w);
#endif
  }
#endif
}
#else
void main() {
#if defined(CELL_LIST)
  const int k = flatIndex();
  if (k >= listCount) return;
  const int i = int(cellList[listFirst + k]);
#else
  const int i = flatIndex();
  if (i >= CELLS) return;
#endif
#if defined(MODE_APPLY)
  y[i] = operatorAt(i, REAL(0));
#else
  const ivec3 c = coordsOf(i, dims);
#if defined(MODE_SMOOTH)
  if (colour >= 0 && ((c.x + c.y + c.z) & 1) != colour) return;
#endif
  const float d = diag[i];
  if (d <= 0.0) {
#if defined(MODE_SMOOTH)
    x[i] = REAL(0);
#else
    y[i] = REAL(0);
#endif
    return;
  }
  const REAL g = gaussSeidelAt(c, i, dims, scale, b[i], d);
#if defined(MODE_SMOOTH)
  x[i] = g;
#elif defined(MODE_JACOBI)
  y[i] = x[i] + REAL(omega) * (g - x[i]);
#endif
#endif
}
#endif
