// The face sums of laplace.comp's 5-/7-point systems on one level, through
// the accessors the including shader defines: LX(i), the level's x, and
// LW(a, i), the weight of the face between i and i + e_a (STENCIL_REAL:
// the vectors' precision). Shared by laplace.comp, multigrid.comp and
// vcycle_tail.comp.

// sum_f w_f (x_i - x_j(f)) over the 2 DIM faces of cell c (index i), the CPU's face sum.
STENCIL_REAL faceSum(ivec3 c, int i, ivec3 dims) {
  const STENCIL_REAL xi = LX(i);
  precise STENCIL_REAL s = STENCIL_REAL(0);
  for (int a = 0; a < DIM; ++a) {
    const int iu = indexOf(stepWrapped(c, a, 1, dims), dims), il = indexOf(stepWrapped(c, a, -1, dims), dims);
    s += STENCIL_REAL(LW(a, i)) * (xi - LX(iu)) + STENCIL_REAL(LW(a, il)) * (xi - LX(il));
  }
  return s;
}

// sum_f w_f x_j(f) over the 2 DIM faces of cell c (index i); the lower
// face of cell 0 on a non-periodic axis is the zeroed one of cell n - 1.
STENCIL_REAL neighbourSum(ivec3 c, int i, ivec3 dims) {
  STENCIL_REAL s = STENCIL_REAL(0);
  for (int a = 0; a < DIM; ++a) {
    const int iu = indexOf(stepWrapped(c, a, 1, dims), dims), il = indexOf(stepWrapped(c, a, -1, dims), dims);
    s += STENCIL_REAL(LW(a, i)) * LX(iu) + STENCIL_REAL(LW(a, il)) * LX(il);
  }
  return s;
}

// scale (c_i x_i + the face sum) at cell c (index i), c_i = ci: A x on an
// active cell, rounded as the CPU's (precise: the explicit step depends on
// it bit for bit).
STENCIL_REAL operatorTerm(ivec3 c, int i, ivec3 dims, double scale, float ci) {
  precise STENCIL_REAL ax = STENCIL_REAL(scale) * (STENCIL_REAL(ci) * LX(i) + faceSum(c, i, dims));
  return ax;
}

// The red-black Gauss-Seidel update of active cell c (index i), diagonal d:
// (b_i / scale + sum_f w_f x_j) / d.
STENCIL_REAL gaussSeidelAt(ivec3 c, int i, ivec3 dims, double scale, STENCIL_REAL bi, float d) {
  return (bi / STENCIL_REAL(scale) + neighbourSum(c, i, dims)) / STENCIL_REAL(d);
}
