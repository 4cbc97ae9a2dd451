// The smoke stages of the fluid step (fluid/smoke.cpp; Fedkiw, Stam & Jensen
// 2001), one MODE each, the formulas from kernels/smoke_physics.inc. The MAC
// velocity is one buffer, component a at velOff[a] with dims cells + e_a;
// the cell-centred work vectors hold component c at c * n.
// MODE_EMIT        smoke += dRho c, T += dT c (c: the source's cover of the cell)
// MODE_INJECT      faces of axis a the source covers take its velocity (blended by cover)
// MODE_BUOYANCY    force_a = b up_a, b = -alpha rho + beta (T - T_amb)     (eq. 8)
// MODE_CENTRE      the velocity at the cell centres
// MODE_VORTICITY   omega = curl u and |omega| at the centres (one-sided at walls)
// MODE_CONFINE     force += epsilon h (N x omega), N = grad|omega| / |grad|omega||  (eq. 11)
// MODE_ADD_FACES   u_a += dt (force_a(lo) + force_a(hi)) / 2 on every face of axis a
// MODE_DECAY       smoke *= keepRho, T - T_amb *= keepT
layout(std430, binding = 0) buffer Vel { float vel[]; };
layout(std430, binding = 1) buffer Smoke { float smoke[]; };
layout(std430, binding = 2) buffer Temp { float temp[]; };
layout(std430, binding = 3) readonly buffer Cover { float cover[]; };
layout(std430, binding = 4) buffer Force { float force[]; };
layout(std430, binding = 5) buffer Centre { float centre[]; };
layout(std430, binding = 6) buffer Omega { float omega[]; };  // W components, then |omega|

uniform ivec3 cells, periodic, velOff;
uniform int axis, n;  // the component a (MODE_INJECT, MODE_ADD_FACES); samples the mode runs over
uniform REAL dRho, dT, value, alpha, beta, ambient, s, h, dt, keepRho, keepT;
uniform REAL3 up;

#define SMOKE_FN(name) REAL name
#define SMOKE_F(name) float name
#define SMOKE_REAL REAL
#define SMOKE_SQRT sqrt
#include "smoke_physics.inc"

ivec3 faceDims() { ivec3 d = cells; d[axis] += 1; return d; }

// Flat neighbours of cell k along a: wrapped on periodic axes, the cell
// itself past a wall; span: their distance in cells.
void neighbours(ivec3 k, int a, out int lo, out int hi, out int span) {
  ivec3 l = k, u = k;
  if (periodic[a] != 0) {
    l = stepWrapped(k, a, -1, cells);
    u = stepWrapped(k, a, 1, cells);
    span = 2;
  } else {
    span = 0;
    if (k[a] > 0) { l[a] -= 1; span += 1; }
    if (k[a] < cells[a] - 1) { u[a] += 1; span += 1; }
  }
  lo = indexOf(l, cells);
  hi = indexOf(u, cells);
}

// d (field at offset off) / d x_a at cell k.
REAL derivative(ivec3 k, int a, int which, int off) {
  int lo, hi, span;
  neighbours(k, a, lo, hi, span);
  if (span == 0) return REAL(0.0);
  const REAL flo = which == 0 ? REAL(centre[off + lo]) : REAL(omega[off + lo]);
  const REAL fhi = which == 0 ? REAL(centre[off + hi]) : REAL(omega[off + hi]);
  return smokeDifference(flo, fhi, REAL(span) * h);
}

void main() {
  const int i = flatIndex();
  if (i >= n) return;
#if defined(MODE_EMIT)
  const float c = cover[i];
  if (c == 0.0) return;
  if (dRho != REAL(0.0)) smoke[i] = float(REAL(smoke[i]) + dRho * REAL(c));
  if (dT != REAL(0.0)) temp[i] = float(REAL(temp[i]) + dT * REAL(c));
#elif defined(MODE_INJECT)
  const ivec3 k = coordsOf(i, faceDims());
  ivec3 lo = k;
  lo[axis] -= 1;
  const REAL cl = lo[axis] >= 0 ? REAL(cover[indexOf(lo, cells)]) : REAL(0.0);
  const REAL ch = k[axis] < cells[axis] ? REAL(cover[indexOf(k, cells)]) : REAL(0.0);
  const REAL w = REAL(0.5) * (cl + ch);
  if (w > REAL(0.0)) vel[velOff[axis] + i] = float(coverBlend(REAL(vel[velOff[axis] + i]), w, value));
#elif defined(MODE_BUOYANCY)
  const REAL b = smokeBuoyancy(REAL(smoke[i]), REAL(temp[i]), alpha, beta, ambient);
  for (int a = 0; a < DIM; ++a) force[a * n + i] = float(b * up[a]);
#elif defined(MODE_CENTRE)
  const ivec3 k = coordsOf(i, cells);
  for (int a = 0; a < DIM; ++a) {
    ivec3 d = cells;
    d[a] += 1;
    ivec3 k1 = k;
    k1[a] += 1;
    centre[a * n + i] = faceMean(vel[velOff[a] + indexOf(k, d)], vel[velOff[a] + indexOf(k1, d)]);
  }
#elif defined(MODE_VORTICITY)
  const ivec3 k = coordsOf(i, cells);
#if DIM == 2
  const REAL o = derivative(k, 0, 0, n) - derivative(k, 1, 0, 0);
  omega[i] = float(o);
  omega[n + i] = float(abs(o));
#else
  const REAL o0 = derivative(k, 1, 0, 2 * n) - derivative(k, 2, 0, n);
  const REAL o1 = derivative(k, 2, 0, 0) - derivative(k, 0, 0, 2 * n);
  const REAL o2 = derivative(k, 0, 0, n) - derivative(k, 1, 0, 0);
  omega[i] = float(o0);
  omega[n + i] = float(o1);
  omega[2 * n + i] = float(o2);
  omega[3 * n + i] = float(vectorLength(o0, o1, o2));
#endif
#elif defined(MODE_CONFINE)
  const ivec3 k = coordsOf(i, cells);
  const int W = DIM == 2 ? 1 : 3;
  REAL eta[3] = REAL[3](REAL(0.0), REAL(0.0), REAL(0.0));
  REAL len2 = REAL(0.0);
  for (int a = 0; a < DIM; ++a) {
    eta[a] = derivative(k, a, 1, W * n);
    len2 += eta[a] * eta[a];
  }
  if (!(len2 > REAL_TINY)) return;
  const REAL inv = inverseLength(len2);
  const REAL N0 = eta[0] * inv, N1 = eta[1] * inv, N2 = eta[2] * inv;
#if DIM == 2
  const REAL w0 = REAL(omega[i]);
  force[i] = float(REAL(force[i]) + REAL(float(confinementTerm(s, N1, w0, REAL(0.0), REAL(0.0)))));
  force[n + i] = float(REAL(force[n + i]) + REAL(float(confinementTerm(s, REAL(0.0), REAL(0.0), N0, w0))));
#else
  const REAL w0 = REAL(omega[i]), w1 = REAL(omega[n + i]), w2 = REAL(omega[2 * n + i]);
  force[i] = float(REAL(force[i]) + REAL(float(confinementTerm(s, N1, w2, N2, w1))));
  force[n + i] = float(REAL(force[n + i]) + REAL(float(confinementTerm(s, N2, w0, N0, w2))));
  force[2 * n + i] = float(REAL(force[2 * n + i]) + REAL(float(confinementTerm(s, N0, w1, N1, w0))));
#endif
#elif defined(MODE_ADD_FACES)
  const ivec3 k = coordsOf(i, faceDims());
  const int nc = cells.x * cells.y * cells.z;
  ivec3 lo = k, hi = k;
  lo[axis] -= 1;
  if (lo[axis] < 0) lo[axis] = periodic[axis] != 0 ? cells[axis] - 1 : 0;
  if (hi[axis] >= cells[axis]) hi[axis] = periodic[axis] != 0 ? 0 : cells[axis] - 1;
  const float halfDt = float(REAL(0.5) * dt);
  const float fl = force[axis * nc + indexOf(lo, cells)], fh = force[axis * nc + indexOf(hi, cells)];
  vel[velOff[axis] + i] += faceForce(halfDt, fl, fh);
#elif defined(MODE_DECAY)
  if (keepRho != REAL(1.0)) smoke[i] = float(decayed(REAL(smoke[i]), keepRho, REAL(0.0)));
  if (keepT != REAL(1.0)) temp[i] = float(decayed(REAL(temp[i]), keepT, ambient));
#endif
}
