// The fluid's shared declarations for its stage shaders (fluid_forces.comp,
// velocity_constraints.comp, advection_correction.comp,
// pressure_projection.comp, viscosity.comp): the MAC velocity is one buffer,
// component a at velOff[a] with dims cells + e_a.
layout(std430, binding = 0) buffer Vel { float vel[]; };
layout(std430, binding = 1) readonly buffer Fixed { uint fixedFace[]; };
layout(std430, binding = 2) readonly buffer Value { float value[]; };
layout(std430, binding = 3) buffer F0 { float f0[]; };   // dye; src; ...
layout(std430, binding = 4) buffer F1 { float f1[]; };   // back
layout(std430, binding = 5) buffer F2 { float f2[]; };   // lo
layout(std430, binding = 6) buffer F3 { float f3[]; };   // hi
#if !defined(D0_REAL)
#define D0_REAL REAL
#endif
layout(std430, binding = 7) buffer D0 { D0_REAL d0[]; };  // rhs / phi (XREAL) / b (REAL: the solver vectors')
#if !defined(D1_REAL)
#define D1_REAL REAL
#endif
layout(std430, binding = 8) buffer D1 { D1_REAL d1[]; };  // rate_prev (float) / x / boundary rhs
layout(std430, binding = 9) buffer D2 { REAL d2[]; };  // boundary rhs
layout(std430, binding = 10) readonly buffer Solid { uint solid[]; };
layout(std430, binding = 11) buffer F4 { float f4[]; };  // hi
layout(std430, binding = 12) readonly buffer Open { float open[]; };  // the faces' open fractions

uniform ivec3 cells, periodic, velOff;
uniform int axis;           // the velocity component a
uniform int n;              // samples of the grid the mode runs over
uniform ivec3 udims;        // MODE_VISCOUS_*: the unknowns (faces less a periodic duplicate layer)
uniform float fa, fb;       // MODE_FORCES: dt f_a, dt b dir_a
uniform int f1Off, dstOff;  // offsets into f1 / f0 (MODE_MACCORMACK / BFECC)
uniform XREAL invH, dt, invLastDt;  // the projection's (in its solution's type)
uniform REAL s;
uniform bool extrapolate;
uniform ivec4 inflow;       // MODE_INFLOW_DYE: axis, high side, across axis, stripes

ivec3 faceDims() { ivec3 d = cells; d[axis] += 1; return d; }
