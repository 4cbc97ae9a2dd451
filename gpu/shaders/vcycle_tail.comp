// The V-cycle's coarsest levels (gpu/gpu_multigrid.h) in one work group and
// one dispatch: the levels packed one after another in each buffer (level k
// at offsetOf[k], the first at 0, so the finer level's transfers read and
// write it in place), each zeroed, smoothed, its residual restricted to the
// next, the last solved exactly by its dense inverse, then each prolonged
// back and smoothed, as GpuMultigrid::cycle does with a dispatch a pass. The
// arithmetic is that of laplace.comp (laplace_stencil.glsl) and multigrid.comp
// (grid_transfer.glsl), so the cycle is the same, bit for bit.
layout(std430, binding = 0) coherent buffer X { float xs[]; };
layout(std430, binding = 1) coherent buffer B { float bs[]; };
layout(std430, binding = 2) coherent buffer R { float rs[]; };
layout(std430, binding = 3) readonly buffer W0 { float w0[]; };
layout(std430, binding = 4) readonly buffer W1 { float w1[]; };
layout(std430, binding = 5) readonly buffer W2 { float w2[]; };
layout(std430, binding = 6) readonly buffer Diag { float diag[]; };
layout(std430, binding = 7) readonly buffer C { float cTerm[]; };
layout(std430, binding = 8) readonly buffer Dense { float dense[]; };

const int kMaxLevels = 8;
uniform int levels;  // packed levels; the last one is solved exactly
uniform ivec3 dimsOf[kMaxLevels];
uniform int offsetOf[kMaxLevels];
uniform double scaleOf[kMaxLevels];
uniform bvec3 periodic;
uniform int preSmooth, postSmooth;

#define STENCIL_REAL float
int lo = 0;  // the offset of the level the accessors read
int co = 0;  // the transfers' coarse level's offset
#define LX(i) xs[lo + (i)]
#define LW(a, i) ((a) == 0 ? w0[lo + (i)] : (a) == 1 ? w1[lo + (i)] : w2[lo + (i)])
#include "laplace_stencil.glsl"
#define FINE(i) rs[lo + (i)]
#define COARSE(i) xs[co + (i)]
#include "grid_transfer.glsl"

#define lid int(gl_LocalInvocationID.x)

void sync() {
  memoryBarrierBuffer();
  barrier();
}

int cells(int k) { return dimsOf[k].x * dimsOf[k].y * dimsOf[k].z; }

void zeroX(int k) {
  for (int i = lid; i < cells(k); i += 256) xs[offsetOf[k] + i] = 0.0;
  sync();
}

// One colour of a red-black Gauss-Seidel sweep (laplace.comp's MODE_SMOOTH).
void smoothColour(int k, int colour) {
  lo = offsetOf[k];
  const ivec3 d = dimsOf[k];
  for (int i = lid; i < cells(k); i += 256) {
    const ivec3 c = coordsOf(i, d);
    if (((c.x + c.y + c.z) & 1) != colour) continue;
    const float dg = diag[lo + i];
    if (dg <= 0.0) {
      xs[lo + i] = 0.0;
      continue;
    }
    xs[lo + i] = gaussSeidelAt(c, i, d, scaleOf[k], bs[lo + i], dg);
  }
  sync();
}

void sweeps(int k, int count, bool reverse) {
  for (int s = 0; s < count; ++s) {
    smoothColour(k, reverse ? 1 : 0);
    smoothColour(k, reverse ? 0 : 1);
  }
}

// r = b - A x (laplace.comp's MODE_RESIDUAL in float).
void residual(int k) {
  lo = offsetOf[k];
  const ivec3 d = dimsOf[k];
  for (int i = lid; i < cells(k); i += 256) {
    if (diag[lo + i] <= 0.0) {
      rs[lo + i] = 0.0;
      continue;
    }
    const ivec3 c = coordsOf(i, d);
    precise float ax = operatorTerm(c, i, d, scaleOf[k], cTerm[lo + i]);
    rs[lo + i] = bs[lo + i] - ax;
  }
  sync();
}

// b of level k + 1 from r of level k (multigrid.comp's MODE_RESTRICT).
void restrictTo(int k) {
  lo = offsetOf[k];
  co = offsetOf[k + 1];
  for (int i = lid; i < cells(k + 1); i += 256)
    bs[co + i] = diag[co + i] <= 0.0 ? 0.0 : restrictAt(i, dimsOf[k], dimsOf[k + 1], periodic);
  sync();
}

// x of level k += the interpolated x of level k + 1 (MODE_PROLONG).
void prolongFrom(int k) {
  lo = offsetOf[k];
  co = offsetOf[k + 1];
  for (int i = lid; i < cells(k); i += 256)
    if (diag[lo + i] > 0.0) xs[lo + i] += prolongAt(i, dimsOf[k], dimsOf[k + 1], periodic);
  sync();
}

// x = M b on the last level (MODE_DENSE).
void solveCoarsest(int k) {
  const int o = offsetOf[k], n = cells(k);
  for (int i = lid; i < n; i += 256) {
    float s = 0.0;
    for (int j = 0; j < n; ++j) s += dense[i * n + j] * bs[o + j];
    xs[o + i] = s;
  }
  sync();
}

void main() {
  for (int k = 0; k + 1 < levels; ++k) {
    zeroX(k);
    sweeps(k, preSmooth, false);
    residual(k);
    restrictTo(k);
  }
  solveCoarsest(levels - 1);
  for (int k = levels - 2; k >= 0; --k) {
    prolongFrom(k);
    sweeps(k, postSmooth, true);
  }
}
