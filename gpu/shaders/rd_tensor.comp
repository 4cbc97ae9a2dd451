// A diffusion tensor whose principal diffusivities follow a species'
// gradient (seed 004 eq. 18-19; rd/diffusion_tensor.h), rebuilt on the GPU
// every step, in REAL (float or double), then assembled as
// AnisotropicSystem::fromTensor and RDSolver::assemble do.
// MODE_SIGMA   the components (xx, yy, (zz,) xy, (xz, yz)) per cell, at sigma[k n + i]
// MODE_FACES   the axis faces (the mean of sigma_aa over the face), the mixed
//              couplings of each plane, and with Dirichlet walls c and the faces' weights
#if defined(MODE_SIGMA)
layout(std430, binding = 0) readonly buffer X { REAL x[]; };         // the shape species
layout(std430, binding = 1) readonly buffer Dir { REAL dir[]; };     // the direction, axis a at a n + i
layout(std430, binding = 2) readonly buffer L1 { REAL lambda1[]; };
layout(std430, binding = 3) readonly buffer L2 { REAL lambda2[]; };
#endif
#if defined(MODE_SIGMA) || defined(MODE_FACES)
layout(std430, binding = 4) buffer Sigma { REAL sigma[]; };
#endif
#if defined(MODE_FACES)
layout(std430, binding = 5) buffer W0 { float w0[]; };
layout(std430, binding = 6) buffer W1 { float w1[]; };
layout(std430, binding = 7) buffer W2 { float w2[]; };
layout(std430, binding = 8) buffer C { float cTerm[]; };
layout(std430, binding = 9) buffer Faces { REAL faces[]; };
layout(std430, binding = 10) buffer Mixed { float v[]; } mixedK[2 * (DIM == 3 ? 3 : 1)];  // up, down per plane
#endif

uniform ivec3 dims;
uniform bool periodic, dirichlet;
uniform REAL shape, floorFraction;

const int kPlanes = DIM == 3 ? 3 : 1;
int n() { return dims.x * dims.y * dims.z; }

#if defined(MODE_SIGMA)
// centralDifference: wrapped if periodic, one-sided at walls
REAL difference(ivec3 c, int a) {
  const int m = dims[a];
  ivec3 lo = c, hi = c;
  lo[a] = c[a] - 1;
  hi[a] = c[a] + 1;
  REAL span = REAL(2.0);
  if (periodic) {
    lo[a] = (lo[a] + m) % m;
    hi[a] = hi[a] % m;
  } else {
    if (lo[a] < 0) { lo[a] = 0; span = REAL(1.0); }
    if (hi[a] >= m) { hi[a] = m - 1; span = REAL(1.0); }
  }
  return (x[indexOf(hi, dims)] - x[indexOf(lo, dims)]) / span;
}
#endif

// c shifted by one cell along each axis of `o` (each -1, 0 or 1), and whether it stays inside
int shifted(ivec3 c, ivec3 o, out bool inside) {
  inside = true;
  for (int a = 0; a < DIM; ++a) {
    int v = c[a] + o[a];
    if (v < 0 || v >= dims[a]) {
      if (!periodic) inside = false;
      v = (v + dims[a]) % dims[a];
    }
    c[a] = v;
  }
  return indexOf(c, dims);
}

int planeAxis(int p, int which) { return p == 0 ? which : p == 1 ? 2 * which : 1 + which; }

void main() {
  const int i = flatIndex();
  if (i >= n()) return;
  const ivec3 c = coordsOf(i, dims);
#if defined(MODE_SIGMA)
  REAL a[3] = REAL[3](REAL(0.0), REAL(0.0), REAL(0.0));
  REAL len2 = REAL(0.0);
  for (int q = 0; q < DIM; ++q) {
    a[q] = dir[q * n() + i];
    len2 += a[q] * a[q];
  }
  REAL l1 = lambda1[i], l2 = lambda2[i];
  if (!(len2 > REAL(0.0))) {  // no direction: isotropic with the mean diffusivity
    const REAL mean = (l1 + REAL(DIM - 1) * l2) / REAL(DIM);
    for (int q = 0; q < DIM + kPlanes; ++q) sigma[q * n() + i] = q < DIM ? mean : REAL(0.0);
    return;
  }
  const REAL inv = REAL(1.0) / sqrt(len2);
  for (int q = 0; q < DIM; ++q) a[q] *= inv;
  REAL g[3] = REAL[3](REAL(0.0), REAL(0.0), REAL(0.0));
  REAL g2 = REAL(0.0);
  for (int q = 0; q < DIM; ++q) {
    g[q] = difference(c, q);
    g2 += g[q] * g[q];
  }
  if (g2 > REAL(0.0)) {  // eq. 18-19
    REAL dotA = REAL(0.0);
    for (int q = 0; q < DIM; ++q) dotA += g[q] * a[q];
    const REAL dl = shape * dotA / sqrt(g2);
    const REAL lowest = floorFraction * (l1 + REAL(DIM - 1) * l2) / REAL(DIM);
    l1 = max(l1 + dl, lowest);
    l2 = max(l2 - dl, lowest);
  }
  const REAL dl = l1 - l2;  // sigma = lambda2 I + (lambda1 - lambda2) a a^T (eq. 15)
  for (int q = 0; q < DIM; ++q) sigma[q * n() + i] = l2 + dl * a[q] * a[q];
  for (int p = 0; p < kPlanes; ++p) sigma[(DIM + p) * n() + i] = dl * a[planeAxis(p, 0)] * a[planeAxis(p, 1)];
#elif defined(MODE_FACES)
  REAL wall = REAL(0.0);
  for (int a = 0; a < DIM; ++a) {
    ivec3 o = ivec3(0);
    o[a] = 1;
    bool inside;
    const int j = shifted(c, o, inside);
    const float f = inside ? float(REAL(0.5) * (sigma[a * n() + i] + sigma[a * n() + j])) : 0.0;
    if (a == 0) w0[i] = f; else if (a == 1) w1[i] = f; else w2[i] = f;
    wall += sigma[a * n() + i] * REAL(int(c[a] == 0) + int(c[a] == dims[a] - 1));
  }
  for (int p = 0; p < kPlanes; ++p) {  // the 2x2 block's two other cells (seed 004 eq. 17)
    const int a = planeAxis(p, 0), b = planeAxis(p, 1);
    ivec3 ea = ivec3(0), eb = ivec3(0);
    ea[a] = 1;
    eb[b] = 1;
    bool inA, inUp, inDown;
    const int ia = shifted(c, ea, inA), ibUp = shifted(c, eb, inUp), ibDown = shifted(c, -eb, inDown);
    const int sab = (DIM + p) * n();
    mixedK[2 * p].v[i] = inA && inUp ? float(REAL(0.25) * (sigma[sab + ia] + sigma[sab + ibUp])) : 0.0;
    mixedK[2 * p + 1].v[i] = inA && inDown ? float(REAL(-0.25) * (sigma[sab + ia] + sigma[sab + ibDown])) : 0.0;
  }
  faces[i] = dirichlet ? wall : REAL(0.0);
  cTerm[i] = dirichlet ? float(REAL(2.0) * wall) : 0.0;
#endif
}
