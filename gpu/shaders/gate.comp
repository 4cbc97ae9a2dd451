// A Krylov solve's device-side convergence (gpu/gpu_gate.h): one work group.
// MODE_START   go = b != 0 and ||r|| / ||b|| > tol; iterations = 0
// MODE_CHECK   while going: iterations += 1, go = p.Ap > 0 and ||r|| / ||b|| > tol
//              and iterations < limit (core/pcg.cpp's loop)
// MODE_FINISH  the true residual ||r|| / ||b||: the solve's verdict (<= tol, with
//              core/pcg.cpp's 1e-4 slack) into the tally
// MODE_REFRESH only the arguments
// First, the final passes of the sums whose partials the kernels before
// wrote (finals: up to two slots, -1 none; fused_sum.glsl) into their slots.
// Then every slot's dispatch arguments: its groups while going, 0 after.
// (one group of common.glsl's 256 invocations)
layout(std430, binding = 0) buffer Scalars { double S[]; };
layout(std430, binding = 1) readonly buffer Base { uint base[]; };
layout(std430, binding = 2) buffer Args { uint args[]; };
layout(std430, binding = 3) buffer State {
  uint go, iterations, solves, total, maxIterations, unconverged, lastIterations, lastConverged;
  double maxResidual, lastResidual;
};

layout(std430, binding = 4) buffer Partials { double partial[]; };
#include "fused_sum.glsl"

uniform ivec3 slot;  // bb, rr, pq
uniform ivec2 finals;
uniform int groups;  // the partials of each final
uniform double tol;
uniform int limit;
uniform int slots;

shared uint going;

double relative() { return S[slot.x] > 0.0lf ? sqrt(S[slot.y]) / sqrt(S[slot.x]) : 0.0lf; }

void main() {
  const uint lid = gl_LocalInvocationID.x;
  for (int k = 0; k < 2; ++k) {
    if (finals[k] < 0) continue;
    const double v = finalSum(finals[k], groups);
    if (lid == 0u) S[finals[k]] = v;
  }
  if (lid == 0u) {
#if defined(MODE_START)
    iterations = 0u;
    go = S[slot.x] > 0.0lf && relative() > tol ? 1u : 0u;
#elif defined(MODE_CHECK)
    if (go != 0u) {
      iterations += 1u;
      go = S[slot.z] > 0.0lf && relative() > tol && iterations < uint(limit) ? 1u : 0u;
    }
#elif defined(MODE_FINISH)
    const double r = relative();
    const bool converged = r <= tol * 1.0001lf;
    solves += 1u;
    total += iterations;
    maxIterations = max(maxIterations, iterations);
    if (!converged) unconverged += 1u;
    lastIterations = iterations;
    lastConverged = converged ? 1u : 0u;
    maxResidual = max(maxResidual, r);
    lastResidual = r;
    go = 1u;  // dispatches outside a solve run
#endif
    going = go;
  }
  barrier();
  for (int k = int(lid); k < slots; k += 256) {
    args[3 * k] = going != 0u ? base[3 * k] : 0u;
    args[3 * k + 1] = base[3 * k + 1];
    args[3 * k + 2] = 1u;
  }
}
