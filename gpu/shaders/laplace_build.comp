// A LaplaceSystem rebuilt on the GPU from coefficients written there (the
// cosine lobes, a shaped tensor): MODE_SHIFT makes the implicit system
// I + k A from A (AnisotropicSystem::shifted: w' = k w, c' = 1 + k c; with
// CROSS the mixed couplings times k instead); MODE_DIAG sets diag = c + the
// face weights (LaplaceSystem::finalize, in its order).
#if defined(CROSS)
layout(std430, binding = 0) readonly buffer Source { float v[]; } source[2 * (DIM == 3 ? 3 : 1)];
layout(std430, binding = 8) buffer Target { float v[]; } target[2 * (DIM == 3 ? 3 : 1)];
#else
layout(std430, binding = 0) buffer W0 { float w0[]; };
layout(std430, binding = 1) buffer W1 { float w1[]; };
layout(std430, binding = 2) buffer W2 { float w2[]; };
layout(std430, binding = 3) buffer C { float cTerm[]; };
layout(std430, binding = 4) buffer Diag { float diag[]; };
layout(std430, binding = 5) readonly buffer S0 { float s0[]; };
layout(std430, binding = 6) readonly buffer S1 { float s1[]; };
layout(std430, binding = 7) readonly buffer S2 { float s2[]; };
layout(std430, binding = 8) readonly buffer SC { float sc[]; };
#endif

uniform ivec3 dims;
uniform double k;

#if !defined(CROSS)
float weight(int a, int i) { return a == 0 ? w0[i] : a == 1 ? w1[i] : w2[i]; }
#endif

void main() {
  const int i = flatIndex();
  if (i >= dims.x * dims.y * dims.z) return;
#if defined(CROSS)
  for (int q = 0; q < 2 * (DIM == 3 ? 3 : 1); ++q) target[q].v[i] = float(double(source[q].v[i]) * k);
#elif defined(MODE_SHIFT)
  w0[i] = float(double(s0[i]) * k);
  w1[i] = float(double(s1[i]) * k);
  if (DIM == 3) w2[i] = float(double(s2[i]) * k);
  cTerm[i] = float(1.0lf + k * double(sc[i]));
#elif defined(MODE_DIAG)
  const ivec3 c = coordsOf(i, dims);
  float d = cTerm[i];
  for (int a = 0; a < DIM; ++a) d += weight(a, i) + weight(a, indexOf(stepWrapped(c, a, -1, dims), dims));
  diag[i] = d;
#endif
}
