// Element-wise steps of the preconditioned CG (core/pcg.cpp) on double
// vectors, with the scalars read from the device (no round trip):
// OP_UPDATE_XR  x += alpha p, r -= alpha q, alpha = S[rz] / S[pq]
// OP_UPDATE_P   p = z + beta p, beta = S[rzNew] / S[rz] (first: p = z)
// OP_JACOBI     z = r / diag (0 on inactive cells)
// OP_SUB_MEAN   x -= S[sum] / S[count] on active cells, 0 on inactive ones
// OP_TO_FLOAT   f = float(x / sqrt(S[rr]))       (into a multigrid level)
// OP_FROM_FLOAT z = double(f) sqrt(S[rr])
// OP_SCALE_ADD  y = a x + b y (a, b uniforms)
// OP_CLAMP_ZERO y = max(y, 0)
// OP_THETA_STEP y += ca x + cb (-z + cc q): the theta scheme's explicit part
//               (x = R, y = the species, z = A y, q = the Dirichlet faces), in
//               rd_solver.cpp's order, no fused multiply-adds
// OP_HOLD       y = x where held[i] != 0 (fixed regions; frozen species hold everywhere)
// OP_ADD_FACES  y += ca faces (x: the Dirichlet faces per cell)
// OP_ZERO_IF_NO_RHS x = 0 where S[bb] = 0 (a solve whose right-hand side is 0)
layout(std430, binding = 0) buffer X { double x[]; };
layout(std430, binding = 1) buffer Y { double y[]; };
layout(std430, binding = 2) buffer Z { double z[]; };
layout(std430, binding = 3) buffer Q { double q[]; };
layout(std430, binding = 4) buffer F { float f[]; };
layout(std430, binding = 5) readonly buffer Diag { float diag[]; };
layout(std430, binding = 6) readonly buffer Scalars { double S[]; };
layout(std430, binding = 7) readonly buffer Held { uint held[]; };

uniform int n;
uniform ivec4 slots;   // the scalar slots each op reads
uniform bool first;
uniform double ca, cb, cc;

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(OP_UPDATE_XR)  // x, y = r, z = p, q
  const double alpha = S[slots.y] > 0.0lf ? S[slots.x] / S[slots.y] : 0.0lf;  // 0 on breakdown
  x[i] += alpha * z[i];
  y[i] -= alpha * q[i];
#elif defined(OP_UPDATE_P)  // x = z, y = p
  y[i] = first ? x[i] : x[i] + (S[slots.x] / S[slots.y]) * y[i];
#elif defined(OP_JACOBI)  // x = r, y = z
  y[i] = diag[i] > 0.0 ? x[i] / double(diag[i]) : 0.0lf;
#elif defined(OP_SUB_MEAN)
  x[i] = diag[i] > 0.0 ? x[i] - S[slots.x] / S[slots.y] : 0.0lf;
#elif defined(OP_TO_FLOAT)
  f[i] = float(x[i] / sqrt(S[slots.x]));
#elif defined(OP_FROM_FLOAT)  // y = z
  y[i] = double(f[i]) * sqrt(S[slots.x]);
#elif defined(OP_SCALE_ADD)
  y[i] = ca * x[i] + cb * y[i];
#elif defined(OP_THETA_STEP)
  precise double L = -z[i] + cc * q[i];
  precise double v = y[i] + (cb != 0.0lf ? ca * x[i] + cb * L : ca * x[i]);
  y[i] = v;
#elif defined(OP_CLAMP_ZERO)
  y[i] = max(y[i], 0.0lf);
#elif defined(OP_HOLD)
  if (held[i] != 0u) y[i] = x[i];
#elif defined(OP_ADD_FACES)
  y[i] += ca * x[i];
#elif defined(OP_ZERO_IF_NO_RHS)
  if (S[slots.x] == 0.0lf) x[i] = 0.0lf;
#endif
}
