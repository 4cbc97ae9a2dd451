// The fluid's forces (fluid/forces.cpp) and its inflow dye (fluid/fluid_solver.cpp), one MODE each.
// MODE_FORCES           u_a += dt f_a + dt b dir_a (dye at the face)
// MODE_INFLOW_DYE       dye stripes on the inflow side's cells
#include "fluid_faces.glsl"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_FORCES)
  const ivec3 k = coordsOf(i, faceDims());
  float v = fa;
  if (fb != 0.0) {  // dye at the face: mean of the two cells it separates (one at walls)
    ivec3 lo = k, hi = k;
    lo[axis] -= 1;
    if (lo[axis] < 0) lo = hi;
    if (hi[axis] >= cells[axis]) hi = lo;
    v += fb * 0.5 * (f0[indexOf(lo, cells)] + f0[indexOf(hi, cells)]);
  }
  vel[velOff[axis] + i] += v;
#elif defined(MODE_INFLOW_DYE)
  const ivec3 k = coordsOf(i, cells);
  if (k[inflow.x] != (inflow.y != 0 ? cells[inflow.x] - 1 : 0) || solid[i] != 0u) return;
  const int band = int(floor(double(k[inflow.z]) / double(cells[inflow.z]) * double(2 * inflow.w)));
  f0[i] = band % 2 == 0 ? 1.0 : 0.0;
#endif
}
