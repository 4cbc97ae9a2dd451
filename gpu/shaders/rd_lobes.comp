// Kim & Lin's cosine-lobe diffusion operator rebuilt on the GPU every step
// (seed 001 eq. 14-17; rd/cosine_lobe.h, RDSolver::assemble), in REAL
// precision without trigonometry: with u = the unit gradient (the central
// differences of rd/grid_difference.h) turned by theta0, cos(j phi) is
// Re(u^j) and the nearest lobe the centre e^{i 2 pi m / j} closest to u.
// MODE_A       a_i = a(theta) at each cell (its mean where the gradient is 0)
// MODE_FACES   w[a]_i = mean of a over the face (0 across a wall), and with
//              Dirichlet walls c_i = 2 sum of a over the cell's wall faces
// (GpuLaplace::recomputeDiagonal and assignShifted complete the systems.)
layout(std430, binding = 0) readonly buffer X { REAL x[]; };
layout(std430, binding = 1) buffer A { REAL lobeA[]; };
layout(std430, binding = 2) buffer W0 { float w0[]; };
layout(std430, binding = 3) buffer W1 { float w1[]; };
layout(std430, binding = 4) buffer W2 { float w2[]; };
layout(std430, binding = 5) buffer C { float cTerm[]; };
layout(std430, binding = 7) buffer Faces { REAL faces[]; };   // the Dirichlet faces' weights
layout(std430, binding = 8) readonly buffer Rot { REAL rot[]; };  // cos, sin of theta0 per cell

uniform ivec3 dims;
uniform bool periodic, dirichlet, witkinKass, rotated;
uniform int lobes;              // j (eq. 16)
uniform REAL speeds[8];       // a_n (eq. 16), or a1, a2 (eq. 15)
uniform REAL centres[16];     // cos, sin of each lobe's centre 2 pi m / j
uniform REAL meanA;           // a's mean over the circle

// centralDifference: wrapped if periodic, one-sided at walls
REAL difference(ivec3 c, int a) {
  const int n = dims[a];
  ivec3 lo = c, hi = c;
  lo[a] = c[a] - 1;
  hi[a] = c[a] + 1;
  REAL span = REAL(2.0);
  if (periodic) {
    lo[a] = (lo[a] + n) % n;
    hi[a] = hi[a] % n;
  } else {
    if (lo[a] < 0) { lo[a] = 0; span = REAL(1.0); }
    if (hi[a] >= n) { hi[a] = n - 1; span = REAL(1.0); }
  }
  return (x[indexOf(hi, dims)] - x[indexOf(lo, dims)]) / span;
}

REAL2 times(REAL2 a, REAL2 b) { return REAL2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x); }

REAL lobeDiffusivity(REAL2 u) {  // u = e^{i phi}
  if (witkinKass) {  // eq. 15
    const REAL alpha = REAL(0.25) * (speeds[0] + speeds[1]);
    const REAL2 u2 = times(u, u);
    const REAL lobe = REAL(0.5) * (REAL(1.0) + times(u2, u2).x);
    return alpha + ((abs(u.x) >= abs(u.y) ? speeds[0] : speeds[1]) - alpha) * lobe;
  }
  int n = 0;  // eq. 16: the lobe whose centre is nearest
  REAL best = REAL(-2.0);
  for (int m = 0; m < lobes; ++m) {
    const REAL dotc = u.x * centres[2 * m] + u.y * centres[2 * m + 1];
    if (dotc > best) { best = dotc; n = m; }
  }
  REAL2 uj = REAL2(REAL(1.0), REAL(0.0));
  for (int m = 0; m < lobes; ++m) uj = times(uj, u);
  return speeds[n] * REAL(0.5) * (REAL(1.0) + uj.x);
}

void main() {
  const int i = flatIndex();
  if (i >= dims.x * dims.y * dims.z) return;
  const ivec3 c = coordsOf(i, dims);
#if defined(MODE_A)
  const REAL gx = difference(c, 0), gy = difference(c, 1);
  REAL a = meanA;  // theta undefined
  if (gx != REAL(0.0) || gy != REAL(0.0)) {
    REAL2 u = REAL2(gx, gy) / sqrt(gx * gx + gy * gy);
    if (rotated) u = times(u, REAL2(rot[2 * i], rot[2 * i + 1]));
    a = lobeDiffusivity(u);
  }
  lobeA[i] = a;
#elif defined(MODE_FACES)
  REAL wall = REAL(0.0);
  for (int a = 0; a < DIM; ++a) {
    const bool inside = periodic || c[a] + 1 < dims[a];
    const float f = inside ? float(REAL(0.5) * (lobeA[i] + lobeA[indexOf(stepWrapped(c, a, 1, dims), dims)])) : 0.0;
    if (a == 0) w0[i] = f; else if (a == 1) w1[i] = f; else w2[i] = f;
    wall += lobeA[i] * REAL(int(c[a] == 0) + int(c[a] == dims[a] - 1));
  }
  faces[i] = dirichlet ? wall : REAL(0.0);
  cTerm[i] = dirichlet ? float(REAL(2.0) * wall) : 0.0;
#endif
}
