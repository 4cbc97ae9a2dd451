// One explicit Euler step of a two-species reaction-diffusion model
// (rd_settings.h: x += dt (R(x) + d lap x)), the 5- or 7-point Laplacian with
// periodic or zero-flux walls. The host prepends #version, DIM, the model's
// modelRates (gpu/gpu_models.h: kernels/models/) and the work-group size.
layout(std430, binding = 0) readonly buffer InU { float inU[]; };
layout(std430, binding = 1) readonly buffer InV { float inV[]; };
layout(std430, binding = 2) writeonly buffer OutU { float outU[]; };
layout(std430, binding = 3) writeonly buffer OutV { float outV[]; };

uniform ivec3 cells;      // nx, ny, nz (nz = 1 in 2D)
uniform bool periodic;    // else zero-flux (Neumann) walls
uniform float dt;
uniform vec2 dOverH2;     // d_u / h^2, d_v / h^2
uniform float p[NPARAMETERS];  // the model's parameters, in order
uniform uint clamped;     // bit s: species s stays >= 0 (the model's projection)

int at(ivec3 c) { return c.x + cells.x * (c.y + cells.y * c.z); }

// The neighbour's index, wrapped (periodic) or mirrored onto the cell itself (no flux).
int neighbour(ivec3 c, int axis, int step) {
  ivec3 q = c;
  q[axis] += step;
  if (q[axis] < 0 || q[axis] >= cells[axis]) q[axis] = periodic ? (q[axis] + cells[axis]) % cells[axis] : c[axis];
  return at(q);
}

void main() {
  const ivec3 c = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(c, cells))) return;
  const int i = at(c);
  const float u = inU[i], v = inV[i];
  float lapU = 0.0, lapV = 0.0;
  for (int axis = 0; axis < DIM; ++axis)
    for (int s = -1; s <= 1; s += 2) {
      const int j = neighbour(c, axis, s);
      lapU += inU[j] - u;
      lapV += inV[j] - v;
    }
  const float x[2] = float[2](u, v);
  float r[2];
  modelRates(x, p, r);
  const float nu = u + dt * (r[0] + dOverH2.x * lapU), nv = v + dt * (r[1] + dOverH2.y * lapV);
  outU[i] = (clamped & 1u) != 0u ? max(nu, 0.0) : nu;
  outV[i] = (clamped & 2u) != 0u ? max(nv, 0.0) : nv;
}
