// The reaction of a model of NSPECIES species, in REAL (float or double),
// one invocation a cell. MODE_IMPLICIT: Kim & Lin's implicit step (seed 001 eq.
// 6), the root of F(x) = x - x0 - dt R(x) by Newton with an Armijo line
// search, continuation in dt and deterministic restarts where it stalls, and
// the complementarity solution for species that must stay >= 0: the CPU's
// own steps (kernels/newton.inc, included below). MODE_RATES: r = R(x) (the
// explicit and semi-implicit integrators). The host prepends NSPECIES, modelRates and modelJacobian
// (gpu/gpu_models.h: kernels/models/, the CPU's own; the model's parameters
// in p[], uniform or a parameter map's value at the cell) and GATHER_PARAMETERS.
// `precise` throughout: no fused multiply-adds, so every operation rounds as
// the CPU's does and Newton takes the CPU's path near folds and multiple roots.
#define N NSPECIES
layout(std430, binding = 0) buffer Species { REAL v[]; } xs[N];
layout(std430, binding = 6) writeonly buffer Rates { REAL v[]; } rs[N];
layout(std430, binding = 12) buffer Stats { uint failures; uint maxIterations; };
layout(std430, binding = 13) readonly buffer Maps { REAL maps[]; };  // parameter maps, one after another

uniform int n;
uniform REAL dt;
uniform REAL uniformP[12];  // the parameters' uniform values
uniform int mapAt[12];        // where parameter k's map starts in maps[], -1: uniform
uniform uint clamped;         // bit s: species s stays >= 0

REAL p[NPARAMETERS];  // this cell's parameters

void rates(REAL x[N], out REAL r[N]) { modelRates(x, p, r); }
void jacobian(REAL x[N], out REAL J[N * N]) { modelJacobian(x, p, J); }

// kernels/newton.inc in GLSL: the arrays of NSPECIES reals
struct NewtonResult { bool converged; int iterations; REAL residual; };
#define NS N
#define NT REAL
#define ARRAY_IN(name) REAL name[N]
#define ARRAY_OUT(name) out REAL name[N]
#define ARRAY_INOUT(name) inout REAL name[N]
#define MATRIX_INOUT(name) inout REAL name[N][N]
#define CONSTEXPR
#if defined(REAL_IS_DOUBLE)
#define NEWTON_TOLERANCE 1e-12lf
#else
#define NEWTON_TOLERANCE 1e-5
#endif
#define NEWTON_TINY REAL_TINY
#include "newton.inc"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
  GATHER_PARAMETERS  // p[k] = uniformP[k] or maps[mapAt[k] + i], for each of the model's k (constant indices)
  REAL x0[N];
  for (int s = 0; s < N; ++s) x0[s] = xs[s].v[i];
#if defined(MODE_IMPLICIT)
  REAL x[N];
  const NewtonResult r = implicitReaction(x0, dt, x, clamped);
  if (!r.converged) atomicAdd(failures, 1u);
  atomicMax(maxIterations, uint(r.iterations));
  // the model's projection
  for (int s = 0; s < N; ++s) xs[s].v[i] = held(clamped, s) && x[s] < REAL(0) ? REAL(0) : x[s];
#else
  REAL r[N];
  rates(x0, r);
  for (int s = 0; s < N; ++s) rs[s].v[i] = r[s];
#endif
}
