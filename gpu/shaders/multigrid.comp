// The transfers of core/multigrid.h between a fine level (dims fd) and the
// next coarser one (dims cd = (fd + 1) / 2), the same weights, on the fly:
// along each axis fine cell f takes 3/4 of its parent f / 2 and 1/4 of the
// parent's neighbour on f's side (all of the parent where that neighbour is
// beyond a non-periodic edge). MODE_RESTRICT: b_c = (sum of the transposed
// weights times r_f) / 2^D on active coarse cells; MODE_PROLONG: x_f += the
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

// The coarse neighbour fine cell f leans towards along an axis of nc coarse
// cells, or the parent itself where there is none.
int sideNeighbour(int f, int nc, bool wrap) {
  const int parent = f >> 1;
  int nb = (f & 1) == 1 ? parent + 1 : parent - 1;
  if (nb < 0 || nb >= nc) nb = wrap ? (nb + nc) % nc : parent;
  return nb;
}
// Weight of coarse index I in the prolongation of fine index f.
float prolongWeight(int f, int I, int nc, bool wrap) {
  const int parent = f >> 1, nb = sideNeighbour(f, nc, wrap);
  if (nb == parent) return I == parent ? 1.0 : 0.0;
  return I == parent ? 0.75 : I == nb ? 0.25 : 0.0;
}

void main() {
  const int i = flatIndex();
#if defined(MODE_RESTRICT)
  if (i >= cd.x * cd.y * cd.z) return;
  if (diag[i] <= 0.0) { coarse[i] = 0.0; return; }
  const ivec3 C = coordsOf(i, cd);
  float s = 0.0;
  for (int mz = 0; mz < (DIM == 3 ? 4 : 1); ++mz) {
    int z = 0;
    float wz = 1.0;
    if (DIM == 3) {
      z = 2 * C.z - 1 + mz;
      if (z < 0 || z >= fd.z) { if (!periodic.z) continue; z = (z + fd.z) % fd.z; }
      wz = prolongWeight(z, C.z, cd.z, periodic.z);
      if (wz == 0.0) continue;
    }
    for (int my = 0; my < 4; ++my) {
      int y = 2 * C.y - 1 + my;
      if (y < 0 || y >= fd.y) { if (!periodic.y) continue; y = (y + fd.y) % fd.y; }
      const float wy = wz * prolongWeight(y, C.y, cd.y, periodic.y);
      if (wy == 0.0) continue;
      float row = 0.0;
      for (int mx = 0; mx < 4; ++mx) {
        int x = 2 * C.x - 1 + mx;
        if (x < 0 || x >= fd.x) { if (!periodic.x) continue; x = (x + fd.x) % fd.x; }
        row += prolongWeight(x, C.x, cd.x, periodic.x) * fine[indexOf(ivec3(x, y, z), fd)];
      }
      s += wy * row;
    }
  }
  coarse[i] = s * (1.0 / float(1 << DIM));
#elif defined(MODE_PROLONG)
  if (i >= fd.x * fd.y * fd.z) return;
  if (diag[i] <= 0.0) return;
  const ivec3 f = coordsOf(i, fd);
  float s = 0.0;
  for (int kz = 0; kz < (DIM == 3 ? 2 : 1); ++kz) {
    int z = 0;
    float wz = 1.0;
    if (DIM == 3) {
      const int parent = f.z >> 1, nb = sideNeighbour(f.z, cd.z, periodic.z);
      wz = nb == parent ? 1.0 - float(kz) : kz == 0 ? 0.75 : 0.25;
      z = kz == 0 ? parent : nb;
      if (wz == 0.0) continue;
    }
    for (int ky = 0; ky < 2; ++ky) {
      const int parent = f.y >> 1, nb = sideNeighbour(f.y, cd.y, periodic.y);
      const float wy = wz * (nb == parent ? 1.0 - float(ky) : ky == 0 ? 0.75 : 0.25);
      if (wy == 0.0) continue;
      const int y = ky == 0 ? parent : nb;
      const int px = f.x >> 1, nx = sideNeighbour(f.x, cd.x, periodic.x);
      const float wx = nx == px ? 1.0 : 0.75;
      s += wy * (wx * coarse[indexOf(ivec3(px, y, z), cd)] + (1.0 - wx) * coarse[indexOf(ivec3(nx, y, z), cd)]);
    }
  }
  fineX[i] += s;
#elif defined(MODE_DENSE)  // fine = b, fineX = x
  if (i >= n) return;
  float s = 0.0;
  for (int j = 0; j < n; ++j) s += dense[i * n + j] * fine[j];
  fineX[i] = s;
#endif
}
