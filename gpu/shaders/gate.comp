// A Krylov solve's device-side convergence (gpu/gpu_gate.h, gate_logic.glsl):
// one work group of common.glsl's 256 invocations.
// MODE_START   go = b != 0 and ||r|| / ||b|| > tol; iterations = 0
// MODE_CHECK   the test after an iteration
// MODE_FINISH  the solve's verdict into the tally
// MODE_REFRESH only the arguments
// First, the final passes of the sums whose partials the kernels before
// wrote (finals: up to two slots, -1 none; fused_sum.glsl) into their slots.
// Then every slot's dispatch arguments: its groups while going, 0 after.
layout(std430, binding = 0) buffer Scalars { double S[]; };
layout(std430, binding = 4) buffer Partials { double partial[]; };
#define GATE_BASE 1
#define GATE_ARGS 2
#define GATE_STATE 3
#include "fused_sum.glsl"
#include "gate_logic.glsl"

uniform ivec2 finals;
uniform int groups;  // the partials of each final

void main() {
  const uint lid = gl_LocalInvocationID.x;
  for (int k = 0; k < 2; ++k) {
    if (finals[k] < 0) continue;
    const double v = finalSum(finals[k], groups);
    if (lid == 0u) S[finals[k]] = v;
  }
  if (lid == 0u) {
#if defined(MODE_START)
    gateStart();
#elif defined(MODE_CHECK)
    gateCheck();
#elif defined(MODE_FINISH)
    gateFinish();
#endif
  }
  writeGateArgs();
}
