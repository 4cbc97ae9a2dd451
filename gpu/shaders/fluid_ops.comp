// The stages of the stable-fluids step (fluid/fluid_solver.cpp) besides
// advection and the linear solves, one MODE each; the MAC velocity is one
// buffer, component a at velOff[a] with dims cells + e_a.
// MODE_FORCES           u_a += dt f_a + dt b dir_a (dye at the face)      (fluid/forces.cpp)
// MODE_FIXED            prescribed faces take their values              (velocity_constraints.cpp)
// MODE_PERIODIC         face n_a of a periodic axis copies face 0
// MODE_MACCORMACK       phi = fwd + (src - back) / 2 where inside [lo, hi] (Selle et al. 2008)
// MODE_BFECC_CORRECT    dst = src + (src - back) / 2                    (Kim et al. 2005)
// MODE_BFECC_LIMIT      dst = back (first order) where dst leaves [lo, hi]
// MODE_INFLOW_DYE       dye stripes on the inflow side's cells
// MODE_DIVERGENCE       rhs = -(div u) / h through the faces' open fractions, 0 in cells
//                       without a pressure (double)                     (pressure_projection.cpp)
// MODE_WARM_START       phi = dt (2 rate - rate_prev) (or dt rate), rate = phi / last dt
// MODE_GRADIENT         u_a -= d phi / d x_a on free faces (outflow: ghost phi = -phi)
// MODE_VISCOUS_SETUP    b, x of component a's implicit viscous system   (viscosity.cpp)
// MODE_VISCOUS_STORE    u_a = x on free faces (not prescribed, nor inside a cut obstacle)
layout(std430, binding = 0) buffer Vel { float vel[]; };
layout(std430, binding = 1) readonly buffer Fixed { uint fixedFace[]; };
layout(std430, binding = 2) readonly buffer Value { float value[]; };
layout(std430, binding = 3) buffer F0 { float f0[]; };   // dye; src; ...
layout(std430, binding = 4) buffer F1 { float f1[]; };   // back
layout(std430, binding = 5) buffer F2 { float f2[]; };   // lo
layout(std430, binding = 6) buffer F3 { float f3[]; };   // hi
layout(std430, binding = 7) buffer D0 { double d0[]; };  // rhs / phi / b
layout(std430, binding = 8) buffer D1 { double d1[]; };  // rate_prev / x / boundary rhs
layout(std430, binding = 9) buffer D2 { double d2[]; };  // boundary rhs
layout(std430, binding = 10) readonly buffer Solid { uint solid[]; };
layout(std430, binding = 11) buffer F4 { float f4[]; };  // hi
layout(std430, binding = 12) readonly buffer Open { float open[]; };  // the faces' open fractions

uniform ivec3 cells, periodic, velOff;
uniform int axis;           // the velocity component a
uniform int n;              // samples of the grid the mode runs over
uniform ivec3 udims;        // MODE_VISCOUS_*: the unknowns (faces less a periodic duplicate layer)
uniform int blockOff;       // MODE_VISCOUS_*: the component's first unknown in b and x (one block system)
uniform float fa, fb;       // MODE_FORCES: dt f_a, dt b dir_a
uniform int f1Off, dstOff;  // offsets into f1 / f0 (MODE_MACCORMACK / BFECC)
uniform double invH, dt, lastDt, s;
uniform bool extrapolate;
uniform ivec4 inflow;       // MODE_INFLOW_DYE: axis, high side, across axis, stripes

ivec3 faceDims() { ivec3 d = cells; d[axis] += 1; return d; }

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
#elif defined(MODE_FIXED)
  if (fixedFace[velOff[axis] + i] != 0u) vel[velOff[axis] + i] = value[velOff[axis] + i];
#elif defined(MODE_PERIODIC)
  const ivec3 d = faceDims(), k = coordsOf(i, d);
  if (k[axis] != cells[axis]) return;
  ivec3 bottom = k;
  bottom[axis] = 0;
  vel[velOff[axis] + i] = vel[velOff[axis] + indexOf(bottom, d)];
#elif defined(MODE_MACCORMACK)  // f0 = fwd at dstOff, f1 = src at f1Off, f2 = back, f3 = lo, f4 = hi
  precise float v = f0[dstOff + i] + 0.5 * (f1[f1Off + i] - f2[i]);
  // revert to first order where the correction leaves the stencil's range
  if (v >= f3[i] && v <= f4[i]) f0[dstOff + i] = v;
#elif defined(MODE_BFECC_CORRECT)  // f0 = dst, f1 = src at f1Off, f2 = back
  precise float v = f1[f1Off + i] + 0.5 * (f1[f1Off + i] - f2[i]);
  f0[i] = v;
#elif defined(MODE_BFECC_LIMIT)  // f0 = dst at dstOff, f1 = first-order back, f2 = lo, f3 = hi
  const float v = f0[dstOff + i];
  if (v < f2[i] || v > f3[i]) f0[dstOff + i] = f1[i];
#elif defined(MODE_INFLOW_DYE)
  const ivec3 k = coordsOf(i, cells);
  if (k[inflow.x] != (inflow.y != 0 ? cells[inflow.x] - 1 : 0) || solid[i] != 0u) return;
  const int band = int(floor(double(k[inflow.z]) / double(cells[inflow.z]) * double(2 * inflow.w)));
  f0[i] = band % 2 == 0 ? 1.0 : 0.0;
#elif defined(MODE_DIVERGENCE)
  const ivec3 k = coordsOf(i, cells);
  double d = 0.0lf;
  for (int a = 0; a < DIM; ++a) {
    ivec3 fd = cells, up = k;
    fd[a] += 1;
    up[a] += 1;
    const int hi = velOff[a] + indexOf(up, fd), lo = velOff[a] + indexOf(k, fd);
#if defined(CUT_FACES)  // a cut obstacle's faces: the flux through their open part
    d += double(open[hi]) * double(vel[hi]) - double(open[lo]) * double(vel[lo]);
#else
    d += double(vel[hi]) - double(vel[lo]);
#endif
  }
  d0[i] = solid[i] != 0u ? 0.0lf : d * -invH;  // (solid: the cells without a pressure)
#elif defined(MODE_WARM_START)  // d0 = phi, d1 = rate_prev
  const double rate = d0[i] / lastDt;
  d0[i] = dt * (extrapolate ? 2.0lf * rate - d1[i] : rate);
  d1[i] = rate;
#elif defined(MODE_GRADIENT)  // d0 = phi
  if (fixedFace[velOff[axis] + i] != 0u) return;
  const ivec3 k = coordsOf(i, faceDims());
  ivec3 lo = k, hi = k;
  lo[axis] -= 1;
  if (periodic[axis] != 0) {
    if (lo[axis] < 0) lo[axis] += cells[axis];
    if (hi[axis] >= cells[axis]) hi[axis] -= cells[axis];
  }
  double pl, ph;
  if (lo[axis] < 0) {  // outflow on the low side: ghost phi = -phi
    ph = d0[indexOf(hi, cells)];
    pl = -ph;
  } else if (hi[axis] >= cells[axis]) {
    pl = d0[indexOf(lo, cells)];
    ph = -pl;
  } else {
    pl = d0[indexOf(lo, cells)];
    ph = d0[indexOf(hi, cells)];
  }
  vel[velOff[axis] + i] = float(double(vel[velOff[axis] + i]) - (ph - pl) * invH);
#elif defined(MODE_VISCOUS_SETUP)  // d0 = b, d1 = x, d2 = boundary rhs
  const int gi = indexOf(coordsOf(i, udims), faceDims());
  const bool held = fixedFace[velOff[axis] + gi] != 0u;
  const double u = double(vel[velOff[axis] + gi]);
  d0[blockOff + i] = held ? 0.0lf : u + s * d2[i];
  d1[blockOff + i] = held ? 0.0lf : u;
#elif defined(MODE_VISCOUS_STORE)  // d1 = x
  const int gi = indexOf(coordsOf(i, udims), faceDims());
  // (or the viscosity's held flags)
  if (fixedFace[velOff[axis] + gi] == 0u) vel[velOff[axis] + gi] = float(d1[blockOff + i]);
#endif
}
