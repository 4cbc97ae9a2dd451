// The transfers of core/multigrid.h between a fine level and the next
// coarser one (grid_transfer.glsl). MODE_RESTRICT: b_c = (sum of the transposed
// weights times r_f) / 2^D on active coarse cells, the fine residual
// r_f = b_f - A_f x_f made where it is read (laplace.comp's MODE_RESIDUAL in
// float, laplace_stencil.glsl), not stored; MODE_PROLONG: x_f += the
// interpolated x_c on active fine cells. MODE_DENSE: the coarsest level
// solved exactly, x = M b with M its (pseudo-)inverse, row by row.
layout(std430, binding = 0) readonly buffer Fine { float fine[]; };   // r_f (restrict)
layout(std430, binding = 1) buffer Coarse { float coarse[]; };        // b_c (restrict) or x_c (prolong)
layout(std430, binding = 2) buffer FineX { float fineX[]; };          // x_f (prolong)
layout(std430, binding = 3) readonly buffer Diag { float diag[]; };   // the written level's
layout(std430, binding = 4) readonly buffer Dense { float dense[]; }; // MODE_DENSE: M, row-major

uniform ivec3 fd, cd;
uniform bvec3 periodic;
uniform int n;  // MODE_DENSE: unknowns

#if defined(MODE_RESTRICT)
layout(std430, binding = 5) readonly buffer FineB { float fineB[]; };
layout(std430, binding = 6) readonly buffer W0 { float w0[]; };
layout(std430, binding = 7) readonly buffer W1 { float w1[]; };
layout(std430, binding = 8) readonly buffer W2 { float w2[]; };
layout(std430, binding = 9) readonly buffer FineDiag { float fineDiag[]; };
layout(std430, binding = 10) readonly buffer FineC { float fineC[]; };
uniform double fineScale;
#define STENCIL_REAL float
#define LX(i) fineX[i]
#define LW(a, i) ((a) == 0 ? w0[i] : (a) == 1 ? w1[i] : w2[i])
#include "laplace_stencil.glsl"
float fineResidual(int j) {
  if (fineDiag[j] <= 0.0) return 0.0;
  return fineB[j] - operatorTerm(coordsOf(j, fd), j, fd, fineScale, fineC[j]);
}
#define FINE(i) fineResidual(i)
#else
#define FINE(i) fine[i]
#endif
#define COARSE(i) coarse[i]
#include "grid_transfer.glsl"

void main() {
  const int i = flatIndex();
#if defined(MODE_RESTRICT)
  if (i >= cd.x * cd.y * cd.z) return;
  if (diag[i] <= 0.0) { coarse[i] = 0.0; return; }
  coarse[i] = restrictAt(i, fd, cd, periodic);
#elif defined(MODE_PROLONG)
  if (i >= fd.x * fd.y * fd.z) return;
  if (diag[i] <= 0.0) return;
  fineX[i] += prolongAt(i, fd, cd, periodic);
#elif defined(MODE_DENSE)  // fine = b, fineX = x
  if (i >= n) return;
  float s = 0.0;
  for (int j = 0; j < n; ++j) s += dense[i * n + j] * fine[j];
  fineX[i] = s;
#endif
}
