// A Krylov solve's stopping test on the device (gpu/gpu_gate.h): the solve's
// state, its verdicts, and the arguments of its gated dispatches. Used by
// gate.comp and by the kernel that makes the test as its last pass
// (vector_ops.comp's OP_UPDATE_P with GATE, laplace.comp's P_UPDATE). Define
// GATE_BASE, GATE_ARGS and GATE_STATE (bindings), declare S (the solve's
// scalars) and include fused_sum.glsl before including.
layout(std430, binding = GATE_BASE) readonly buffer Base { uint base[]; };
layout(std430, binding = GATE_ARGS) buffer Args { uint args[]; };
layout(std430, binding = GATE_STATE) buffer State {
  uint go, iterations, solves, total, maxIterations, unconverged, lastIterations, lastConverged;
  double maxResidual, lastResidual;
};

uniform ivec3 gateSlot;  // bb, rr, pq
uniform double gateTol;
uniform int gateLimit;
uniform int gateCount;  // dispatch slots

shared uint gateGoing;

double relative() { return S[gateSlot.x] > 0.0lf ? sqrt(S[gateSlot.y]) / sqrt(S[gateSlot.x]) : 0.0lf; }

// Before the first iteration: go while ||r|| / ||b|| > tol (and b != 0).
void gateStart() {
  iterations = 0u;
  go = S[gateSlot.x] > 0.0lf && relative() > gateTol ? 1u : 0u;
}

// After an iteration: count it while going; go on while p.Ap > 0,
// ||r|| / ||b|| > tol and fewer than the limit are done (core/pcg.cpp's loop).
void gateCheck() {
  if (go == 0u) return;
  iterations += 1u;
  go = S[gateSlot.z] > 0.0lf && relative() > gateTol && iterations < uint(gateLimit) ? 1u : 0u;
}

// The true residual ||r|| / ||b||: the solve's verdict (<= tol, with
// core/pcg.cpp's 1e-4 slack) into the tally.
void gateFinish() {
  const double r = relative();
  const bool converged = r <= gateTol * 1.0001lf;
  solves += 1u;
  total += iterations;
  maxIterations = max(maxIterations, iterations);
  if (!converged) unconverged += 1u;
  lastIterations = iterations;
  lastConverged = converged ? 1u : 0u;
  maxResidual = max(maxResidual, r);
  lastResidual = r;
  go = 1u;  // dispatches outside a solve run
}

// Every slot's dispatch arguments: its groups while going, 0 after (the
// whole group calls it, after invocation 0 updated the state).
void writeGateArgs() {
  const uint lid = gl_LocalInvocationID.x;
  if (lid == 0u) gateGoing = go;
  barrier();
  for (int k = int(lid); k < gateCount; k += 256) {
    args[3 * k] = gateGoing != 0u ? base[3 * k] : 0u;
    args[3 * k + 1] = base[3 * k + 1];
    args[3 * k + 2] = 1u;
  }
}

// The test as the last pass of a kernel over the reduction's groups (its
// first group calls it): S[pq] and S[rr] summed from their partials, then
// the test and the arguments.
void checkAsLastPass(int pqSlot, int rrSlot) {
  const int groups = int(gl_NumWorkGroups.x);
  const double pq = finalSum(pqSlot, groups), rr = finalSum(rrSlot, groups);
  if (gl_LocalInvocationID.x == 0u) {
    S[pqSlot] = pq;
    S[rrSlot] = rr;
    gateCheck();
  }
  writeGateArgs();
}
