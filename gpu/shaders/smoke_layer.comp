// The pattern on the smoke (coupling/smoke_layer.h) on the layer's NSPECIES
// species, one invocation a layer cell:
// MODE_BLEND  x_s = coverBlend(x_s, c, values_s), c the source's cover of the cell
// MODE_MASK   x_s = rest_s where the smoke, interpolated at the cell's centre
//             through the host's taps (interpolateStencil's order), is at most threshold
#define N NSPECIES
layout(std430, binding = 0) buffer Species { REAL v[]; } xs[N];
layout(std430, binding = 8) readonly buffer Cover { float cover[]; };
layout(std430, binding = 9) readonly buffer Smoke { float smoke[]; };
layout(std430, binding = 10) readonly buffer Taps { int taps[]; };  // axis a at tapOff[a]: i0, i1, bits of t per cell

uniform int n;
uniform ivec3 rdCells, cells, tapOff;
uniform REAL values[N];
uniform REAL threshold;

// kernels/multilinear.inc in float, `precise`: each operation rounded as the CPU's
#define ML_FN float
#define ML_T float
#define PRECISE precise
#include "multilinear.inc"
#define SMOKE_FN(name) REAL name
#define SMOKE_F(name) float name
#define SMOKE_REAL REAL
#define SMOKE_SQRT sqrt
#include "smoke_physics.inc"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_BLEND)
  const REAL c = REAL(cover[i]);
  for (int s = 0; s < N; ++s) {
    precise REAL x = coverBlend(xs[s].v[i], c, values[s]);
    xs[s].v[i] = x;
  }
#elif defined(MODE_MASK)
  const ivec3 k = coordsOf(i, rdCells);
  int lo[3] = int[3](0, 0, 0), hi[3] = int[3](0, 0, 0);
  float t[3] = float[3](0.0, 0.0, 0.0);
  for (int a = 0; a < DIM; ++a) {
    const int at = tapOff[a] + 3 * k[a];
    lo[a] = taps[at];
    hi[a] = taps[at + 1];
    t[a] = intBitsToFloat(taps[at + 2]);
  }
  float v[8];
  for (int c = 0; c < (1 << DIM); ++c)
    v[c] = smoke[indexOf(ivec3((c & 1) != 0 ? hi[0] : lo[0], (c & 2) != 0 ? hi[1] : lo[1],
                               (c & 4) != 0 ? hi[2] : lo[2]), cells)];
  const float r = DIM == 2 ? bilinear(v[0], v[1], v[2], v[3], t[0], t[1])
                           : trilinear(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], t[0], t[1], t[2]);
  if (REAL(r) > threshold) return;
  for (int s = 0; s < N; ++s) xs[s].v[i] = values[s];
#endif
}
