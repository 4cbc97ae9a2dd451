// The prescribed velocities (fluid/velocity_constraints.cpp), one MODE each.
// MODE_FIXED            prescribed faces take their values
// MODE_PERIODIC         face n_a of a periodic axis copies face 0
#include "fluid_faces.glsl"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_FIXED)
  if (fixedFace[velOff[axis] + i] != 0u) vel[velOff[axis] + i] = value[velOff[axis] + i];
#elif defined(MODE_PERIODIC)
  const ivec3 d = faceDims(), k = coordsOf(i, d);
  if (k[axis] != cells[axis]) return;
  ivec3 bottom = k;
  bottom[axis] = 0;
  vel[velOff[axis] + i] = vel[velOff[axis] + indexOf(bottom, d)];
#endif
}
