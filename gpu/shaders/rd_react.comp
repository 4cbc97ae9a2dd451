// The reaction of a two-species model, double precision, one invocation a
// cell. MODE_IMPLICIT: Kim & Lin's implicit step (seed 001 eq. 6), the root of
// F(x) = x - x0 - dt R(x) by Newton with an Armijo line search, continuation
// in dt and deterministic restarts where it stalls, and the complementarity
// solution for species that must stay >= 0: rd/newton.h, step for step.
// MODE_RATES: r = R(x) (the explicit and semi-implicit integrators).
// The host prepends RATES(x, r) and JACOBIAN(x, J) (rd/models.h in GLSL, the
// model's parameters in p[]: uniform, or a parameter map's value at the cell).
layout(std430, binding = 0) buffer X0 { double xu[]; };
layout(std430, binding = 1) buffer X1 { double xv[]; };
layout(std430, binding = 2) writeonly buffer R0 { double ru[]; };
layout(std430, binding = 3) writeonly buffer R1 { double rv[]; };
layout(std430, binding = 4) buffer Stats { uint failures; uint maxIterations; };
layout(std430, binding = 5) readonly buffer Maps { double maps[]; };  // parameter maps, one after another

uniform int n;
uniform double dt;
uniform double uniformP[12];  // the parameters' uniform values
uniform int mapAt[12];        // where parameter k's map starts in maps[], -1: uniform
uniform uint clamped;         // bit s: species s stays >= 0

double p[12];  // this cell's parameters (RATES and JACOBIAN read p)

// `precise` throughout: no fused multiply-adds, so every operation rounds as
// the CPU's does and Newton takes the CPU's path near folds and multiple roots.
dvec2 rates(dvec2 x) {
  precise double r[2];
  RATES(x, r)
  return dvec2(r[0], r[1]);
}
void jacobian(dvec2 x, out double J[4]) {
  precise double K[4];
  JACOBIAN(x, K)
  J = K;
}

bool held(uint mask, int s) { return ((mask >> uint(s)) & 1u) != 0u; }

// max |F|; l2 = |F|^2
double residualOf(dvec2 y, dvec2 x0, double h, uint fixedMask, out dvec2 f, out double l2) {
  const dvec2 r = rates(y);
  precise double m = 0.0lf, q = 0.0lf;
  for (int s = 0; s < 2; ++s) {
    f[s] = held(fixedMask, s) ? 0.0lf : y[s] - x0[s] - h * r[s];
    m = max(m, abs(f[s]));
    q += f[s] * f[s];
  }
  l2 = q;
  return m;
}

// solveDense for n = 2 (partial pivoting); false if singular
bool solve2(inout double A[2][2], inout dvec2 b) {
  if (abs(A[1][0]) > abs(A[0][0])) {
    double t = A[0][0]; A[0][0] = A[1][0]; A[1][0] = t;
    t = A[0][1]; A[0][1] = A[1][1]; A[1][1] = t;
    b = b.yx;
  }
  if (!(abs(A[0][0]) > 1e-300lf)) return false;
  precise double f = A[1][0] / A[0][0];
  A[1][1] -= f * A[0][1];
  b[1] -= f * b[0];
  if (!(abs(A[1][1]) > 1e-300lf)) return false;
  b[1] = b[1] / A[1][1];
  b[0] = (b[0] - A[0][1] * b[1]) / A[0][0];
  return true;
}

struct Result { bool converged; int iterations; double residual; };

Result newtonFrom(dvec2 x0, double h, inout dvec2 x, uint fixedMask, int maxIterations) {
  double scale = max(max(1.0lf, max(abs(x0[0]), abs(x0[1]))), max(abs(x[0]), abs(x[1])));
  precise dvec2 F, Fn, xn;
  precise double q, qn;
  double fnorm = residualOf(x, x0, h, fixedMask, F, q);
  Result res = Result(false, 0, 0.0lf);
  for (;;) {
    const double tol = 1e-12lf * scale;
    if (!(fnorm > tol)) {  // also stops on NaN (unconverged)
      res.converged = fnorm <= tol;
      break;
    }
    if (res.iterations >= maxIterations) break;
    ++res.iterations;
    double J[4];
    jacobian(x, J);
    precise double A[2][2];
    precise dvec2 d;
    for (int s = 0; s < 2; ++s) {
      const bool fx = held(fixedMask, s);
      for (int t = 0; t < 2; ++t) A[s][t] = (s == t ? 1.0lf : 0.0lf) - (fx ? 0.0lf : h * J[s * 2 + t]);
      d[s] = -F[s];
    }
    if (!solve2(A, d)) d = -F;  // singular: a damped fixed-point step
    double lambda = 1.0lf, fn = 0.0lf;
    bool accepted = false;
    for (int tries = 0; tries < 40; ++tries, lambda *= 0.5lf) {
      xn = x + lambda * d;
      fn = residualOf(xn, x0, h, fixedMask, Fn, qn);
      if (qn <= (1.0lf - 2e-4lf * lambda) * q) {
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    x = xn;
    F = Fn;
    scale = max(scale, max(abs(x[0]), abs(x[1])));
    fnorm = fn;
    q = qn;
  }
  res.residual = fnorm;
  return res;
}

const int kMaxIterations = 60;

Result newtonImplicit(dvec2 x0, double h, inout dvec2 x, uint fixedMask) {
  dvec2 start;
  for (int s = 0; s < 2; ++s) {
    if (!held(fixedMask, s)) x[s] = x0[s];
    start[s] = x[s];
  }
  Result r = newtonFrom(x0, h, x, fixedMask, kMaxIterations);
  if (r.converged) return r;
  int total = r.iterations;
  // continuation: tau dt with tau towards 1
  x = start;
  const double taus[6] = double[6](1.0lf / 64.0lf, 1.0lf / 16.0lf, 0.25lf, 0.5lf, 0.75lf, 1.0lf);
  for (int k = 0; k < 6; ++k) {
    Result c = newtonFrom(x0, taus[k] * h, x, fixedMask, kMaxIterations);
    total += c.iterations;
    if (!c.converged) break;
    if (k == 5) {
      c.iterations = total;
      return c;
    }
  }
  // deterministic restarts: Halton offsets in (-1, 1) (1 + |x0|)
  const int primes[2] = int[2](2, 3);
  for (int k = 1; k <= 32; ++k) {
    for (int s = 0; s < 2; ++s) {
      precise double f = 0.0lf, base = 1.0lf / double(primes[s]);
      for (int i = k, b = primes[s]; i > 0; i /= b, base /= double(b)) f += base * double(i % b);
      x[s] = held(fixedMask, s) ? start[s] : x0[s] + (2.0lf * f - 1.0lf) * (1.0lf + abs(x0[s]));
    }
    Result c = newtonFrom(x0, h, x, fixedMask, kMaxIterations);
    total += c.iterations;
    if (c.converged) {
      c.iterations = total;
      return c;
    }
  }
  x = start;
  r = newtonFrom(x0, h, x, fixedMask, kMaxIterations);
  r.iterations += total;
  return r;
}

// implicitReactionCell: the complementarity solution for the clamped species.
Result implicitReaction(dvec2 x0, double h, out dvec2 x) {
  x = x0;
  Result r = newtonImplicit(x0, h, x, 0u);
  if (clamped == 0u) return r;
  uint pinned = 0u;
  for (int s = 0; s < 2; ++s)
    if (held(clamped, s) && (!r.converged ? true : x[s] < 0.0lf)) pinned |= 1u << uint(s);
  if (pinned == 0u) return r;
  for (int s = 0; s < 2; ++s)
    if (held(pinned, s)) x[s] = 0.0lf;
  Result c = newtonImplicit(x0, h, x, pinned);
  const dvec2 rr = rates(x);
  uint violated = 0u;
  for (int s = 0; s < 2; ++s)
    if (held(pinned, s) && x[s] - x0[s] - h * rr[s] < 0.0lf) violated |= 1u << uint(s);
  const uint keep = pinned & ~violated;
  for (int j = 0; violated != 0u && j < 10; ++j) {
    dvec2 y;
    for (int s = 0; s < 2; ++s) y[s] = held(violated, s) ? (abs(x0[s]) + 1.0lf) * ldexp(1.0lf, 2 * j - 14) : x[s];
    Result f = newtonFrom(x0, h, y, keep, kMaxIterations);
    c.iterations += f.iterations;
    bool admissible = f.converged;
    for (int s = 0; s < 2; ++s)
      if (held(clamped, s) && y[s] < 0.0lf) admissible = false;
    if (admissible) {
      x = y;
      f.iterations = c.iterations + r.iterations;
      return f;
    }
  }
  c.iterations += r.iterations;
  return c;
}

void main() {
  const int i = flatIndex();
  if (i >= n) return;
  GATHER_PARAMETERS  // p[k] = uniformP[k] or maps[mapAt[k] + i], for each of the model's k (constant indices)
  const dvec2 x0 = dvec2(xu[i], xv[i]);
#if defined(MODE_IMPLICIT)
  dvec2 x;
  const Result r = implicitReaction(x0, dt, x);
  if (!r.converged) atomicAdd(failures, 1u);
  atomicMax(maxIterations, uint(r.iterations));
  for (int s = 0; s < 2; ++s)
    if (held(clamped, s) && x[s] < 0.0lf) x[s] = 0.0lf;  // the model's projection
  xu[i] = x[0];
  xv[i] = x[1];
#else
  const dvec2 r = rates(x0);
  ru[i] = r[0];
  rv[i] = r[1];
#endif
}
