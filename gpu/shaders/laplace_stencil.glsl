// The face sums of laplace.comp's 5-/7-point systems on one level, through
// the accessors the including shader defines: LX(i), the level's x, and
// LW(a, i), the weight of the face between i and i + e_a (REAL: the
// vectors' precision). Shared by laplace.comp, multigrid.comp and
// vcycle_tail.comp.

// sum_f w_f (x_i - x_j(f)) over the 2 DIM faces of cell c (index i), the CPU's face sum.
REAL faceSum(ivec3 c, int i, ivec3 dims) {
  const REAL xi = LX(i);
  precise REAL s = REAL(0);
  for (int a = 0; a < DIM; ++a) {
    const int iu = indexOf(stepWrapped(c, a, 1, dims), dims), il = indexOf(stepWrapped(c, a, -1, dims), dims);
    s += REAL(LW(a, i)) * (xi - LX(iu)) + REAL(LW(a, il)) * (xi - LX(il));
  }
  return s;
}

// sum_f w_f x_j(f) over the 2 DIM faces of cell c (index i); the lower
// face of cell 0 on a non-periodic axis is the zeroed one of cell n - 1.
REAL neighbourSum(ivec3 c, int i, ivec3 dims) {
  REAL s = REAL(0);
  for (int a = 0; a < DIM; ++a) {
    const int iu = indexOf(stepWrapped(c, a, 1, dims), dims), il = indexOf(stepWrapped(c, a, -1, dims), dims);
    s += REAL(LW(a, i)) * LX(iu) + REAL(LW(a, il)) * LX(il);
  }
  return s;
}

// scale (c_i x_i + the face sum) at cell c (index i), c_i = ci: A x on an
// active cell, rounded as the CPU's (precise: the explicit step depends on
// it bit for bit).
REAL operatorTerm(ivec3 c, int i, ivec3 dims, double scale, float ci) {
  precise REAL ax = REAL(scale) * (REAL(ci) * LX(i) + faceSum(c, i, dims));
  return ax;
}

// The red-black Gauss-Seidel update of active cell c (index i), diagonal d:
// (b_i / scale + sum_f w_f x_j) / d.
REAL gaussSeidelAt(ivec3 c, int i, ivec3 dims, double scale, REAL bi, float d) {
  return (bi / REAL(scale) + neighbourSum(c, i, dims)) / REAL(d);
}
