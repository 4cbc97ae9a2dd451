// The transfers of core/multigrid.h between a fine level (dims fd) and the
// next coarser one (dims cd = (fd + 1) / 2), the same weights, on the fly:
// along each axis fine cell f takes 3/4 of its parent f / 2 and 1/4 of the
// parent's neighbour on f's side (all of the parent where that neighbour is
// beyond a non-periodic edge). Through the accessors the including shader
// defines: FINE(i), the fine residual, and COARSE(i), the coarse x. Shared
// by multigrid.comp and vcycle_tail.comp.

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

// b_c at coarse cell i: the transposed weights times r_f, over 2^D.
float restrictAt(int i, ivec3 fd, ivec3 cd, bvec3 periodic) {
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
        row += prolongWeight(x, C.x, cd.x, periodic.x) * FINE(indexOf(ivec3(x, y, z), fd));
      }
      s += wy * row;
    }
  }
  return s * (1.0 / float(1 << DIM));
}

// The interpolated x_c at fine cell i.
float prolongAt(int i, ivec3 fd, ivec3 cd, bvec3 periodic) {
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
      s += wy * (wx * COARSE(indexOf(ivec3(px, y, z), cd)) + (1.0 - wx) * COARSE(indexOf(ivec3(nx, y, z), cd)));
    }
  }
  return s;
}
