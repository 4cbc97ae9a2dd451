// The second-order corrections of the velocity's advection (fluid/advection.cpp; the
// semi-Lagrangian passes are advect.comp's), one MODE each.
// MODE_MACCORMACK       phi = fwd + (src - back) / 2 where inside [lo, hi] (Selle et al. 2008)
// MODE_BFECC_CORRECT    dst = src + (src - back) / 2                    (Kim et al. 2005)
// MODE_BFECC_LIMIT      dst = back (first order) where dst leaves [lo, hi]
#include "fluid_faces.glsl"

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_MACCORMACK)  // f0 = fwd at dstOff, f1 = src at f1Off, f2 = back, f3 = lo, f4 = hi
  precise float v = f0[dstOff + i] + 0.5 * (f1[f1Off + i] - f2[i]);
  // revert to first order where the correction leaves the stencil's range
  if (v >= f3[i] && v <= f4[i]) f0[dstOff + i] = v;
#elif defined(MODE_BFECC_CORRECT)  // f0 = dst, f1 = src at f1Off, f2 = back
  precise float v = f1[f1Off + i] + 0.5 * (f1[f1Off + i] - f2[i]);
  f0[i] = v;
#elif defined(MODE_BFECC_LIMIT)  // f0 = dst at dstOff, f1 = first-order back, f2 = lo, f3 = hi
  const float v = f0[dstOff + i];
  if (v < f2[i] || v > f3[i]) f0[dstOff + i] = f1[i];
#endif
}
