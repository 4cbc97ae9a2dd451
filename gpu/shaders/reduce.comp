// Deterministic sums in double (of REAL vectors, products exact): MODE_PARTIAL has each of the dispatch's
// (fixed number of) work groups sum a fixed, strided share of the terms in
// a fixed tree order into partial[slot * 256 + group]; MODE_FINAL sums those
// partials the same way in one work group into scalars[slot] (kernels that
// make the terms can do the partial pass themselves: fused_sum.glsl). Terms (MODE_PARTIAL):
// TERM_DOT x_i y_i, TERM_ACTIVE_SUM x_i where diag_i > 0, TERM_ACTIVE_COUNT
// 1 where diag_i > 0, TERM_MAX_ABS |f_i| (a float vector, combined by max).
layout(std430, binding = 0) readonly buffer X { REAL x[]; };
layout(std430, binding = 1) readonly buffer Y { REAL y[]; };
layout(std430, binding = 2) readonly buffer Diag { float diag[]; };
layout(std430, binding = 3) buffer Partial { double partial[]; };
layout(std430, binding = 4) buffer Scalars { double scalars[]; };
layout(std430, binding = 5) readonly buffer Fl { float fl[]; };

#if defined(TERM_MAX_ABS)
#define COMBINE(a, b) max(a, b)
#else
#define COMBINE(a, b) ((a) + (b))
#endif

uniform int n;      // terms (MODE_PARTIAL) or partials (MODE_FINAL)
uniform int slot;   // where the sum goes (its partials at slot * 256)

shared double sums[256];

double term(int i) {
#if defined(TERM_DOT)
  return double(x[i]) * double(y[i]);
#elif defined(TERM_MAX_ABS)
  return double(abs(fl[i]));
#elif defined(TERM_ACTIVE_SUM)
  return diag[i] > 0.0 ? double(x[i]) : 0.0lf;
#else
  return diag[i] > 0.0 ? 1.0lf : 0.0lf;
#endif
}

void main() {
  const int lid = int(gl_LocalInvocationID.x);
  double s = 0.0lf;
#if defined(MODE_PARTIAL)
  const int stride = int(gl_NumWorkGroups.x) * 256;
  for (int i = int(gl_WorkGroupID.x) * 256 + lid; i < n; i += stride) s = COMBINE(s, term(i));
#else
  for (int i = lid; i < n; i += 256) s = COMBINE(s, partial[slot * 256 + i]);
#endif
  sums[lid] = s;
  barrier();
  for (int half_ = 128; half_ > 0; half_ >>= 1) {
    if (lid < half_) sums[lid] = COMBINE(sums[lid], sums[lid + half_]);
    barrier();
  }
  if (lid != 0) return;
#if defined(MODE_PARTIAL)
  partial[slot * 256 + int(gl_WorkGroupID.x)] = sums[0];
#else
  scalars[slot] = sums[0];
#endif
}
