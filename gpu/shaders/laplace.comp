// The 5-/7-point systems of core/laplace_system.h on the GPU:
//   (A x)_i = scale (c_i x_i + sum_f w_f (x_i - x_j(f))),  diag = c + sum_f w_f,
// w[a]_i couples i and i + e_a (0 across a non-periodic edge), a cell with
// diag 0 is inactive. MODE_APPLY: y = A x; MODE_RESIDUAL: y = b - A x (both
// in the CPU's form: c and the face differences, not the rounded diagonal);
// MODE_SMOOTH: one colour of a red-black Gauss-Seidel sweep,
// x_i = (b_i / scale + sum_f w_f x_j) / diag_i; MODE_JACOBI: y = x + omega
// (that update - x) (levels whose odd periodic axis mixes the colours).
// REAL is double for the PCG vectors, float for the multigrid levels.
layout(std430, binding = 0) buffer X { REAL x[]; };
layout(std430, binding = 1) buffer Y { REAL y[]; };
layout(std430, binding = 2) readonly buffer B { REAL b[]; };
layout(std430, binding = 3) readonly buffer W0 { float w0[]; };
layout(std430, binding = 4) readonly buffer W1 { float w1[]; };
layout(std430, binding = 5) readonly buffer W2 { float w2[]; };
layout(std430, binding = 6) readonly buffer Diag { float diag[]; };
layout(std430, binding = 7) readonly buffer C { float cTerm[]; };

uniform ivec3 dims;
uniform double scale;
uniform int colour;    // MODE_SMOOTH: the cells with (x + y + z) % 2 == colour
uniform float omega;   // MODE_JACOBI

float weight(int a, int i) { return a == 0 ? w0[i] : a == 1 ? w1[i] : w2[i]; }

// sum_f w_f (x_i - x_j(f)) over the 2 DIM faces of cell c (index i), the CPU's face sum.
REAL faceSum(ivec3 c, int i) {
  const REAL xi = x[i];
  REAL s = REAL(0);
  for (int a = 0; a < DIM; ++a) {
    const int iu = indexOf(stepWrapped(c, a, 1, dims), dims), il = indexOf(stepWrapped(c, a, -1, dims), dims);
    s += REAL(weight(a, i)) * (xi - x[iu]) + REAL(weight(a, il)) * (xi - x[il]);
  }
  return s;
}

// sum_f w_f x_j(f) over the 2 DIM faces of cell c (index i); the lower
// face of cell 0 on a non-periodic axis is the zeroed one of cell n - 1.
REAL neighbourSum(ivec3 c, int i) {
  REAL s = REAL(0);
  for (int a = 0; a < DIM; ++a) {
    const int iu = indexOf(stepWrapped(c, a, 1, dims), dims), il = indexOf(stepWrapped(c, a, -1, dims), dims);
    s += REAL(weight(a, i)) * x[iu] + REAL(weight(a, il)) * x[il];
  }
  return s;
}

void main() {
  const int i = flatIndex();
  if (i >= dims.x * dims.y * dims.z) return;
  const ivec3 c = coordsOf(i, dims);
#if defined(MODE_SMOOTH)
  if (((c.x + c.y + c.z) & 1) != colour) return;
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
#if defined(MODE_APPLY)
  y[i] = REAL(scale) * (REAL(cTerm[i]) * x[i] + faceSum(c, i));
#elif defined(MODE_RESIDUAL)
  y[i] = b[i] - REAL(scale) * (REAL(cTerm[i]) * x[i] + faceSum(c, i));
#else
  const REAL s = neighbourSum(c, i);
#endif
#if defined(MODE_SMOOTH)
  x[i] = (b[i] / REAL(scale) + s) / REAL(d);
#elif defined(MODE_JACOBI)
  const REAL g = (b[i] / REAL(scale) + s) / REAL(d);
  y[i] = x[i] + REAL(omega) * (g - x[i]);
#endif
}
