// The implicit viscosity's set-up and store (fluid/viscosity.cpp; the solve is the Laplacian's), one MODE each.
// MODE_VISCOUS_SETUP    b, x of component a's implicit viscous system
// MODE_VISCOUS_STORE    u_a = x on free faces (not prescribed, nor inside a cut obstacle)
#include "fluid_faces.glsl"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_VISCOUS_SETUP)  // d0 = b, d1 = x, d2 = boundary rhs
  const int gi = indexOf(coordsOf(i, udims), faceDims());
  const bool held = fixedFace[velOff[axis] + gi] != 0u;
  const REAL u = REAL(vel[velOff[axis] + gi]);
  d0[i] = held ? REAL(0) : u + s * d2[i];
  d1[i] = held ? REAL(0) : u;
#elif defined(MODE_VISCOUS_STORE)  // d1 = x
  const int gi = indexOf(coordsOf(i, udims), faceDims());
  // (or the viscosity's held flags)
  if (fixedFace[velOff[axis] + gi] == 0u) vel[velOff[axis] + gi] = float(d1[i]);
#endif
}
