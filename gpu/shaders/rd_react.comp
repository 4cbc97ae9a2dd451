// The reaction of a model of NSPECIES species, double precision, one
// invocation a cell. MODE_IMPLICIT: Kim & Lin's implicit step (seed 001 eq.
// 6), the root of F(x) = x - x0 - dt R(x) by Newton with an Armijo line
// search, continuation in dt and deterministic restarts where it stalls, and
// the complementarity solution for species that must stay >= 0: rd/newton.h,
// step for step. MODE_RATES: r = R(x) (the explicit and semi-implicit
// integrators). The host prepends NSPECIES, modelRates and modelJacobian
// (gpu/gpu_models.h: kernels/models/, the CPU's own; the model's parameters
// in p[], uniform or a parameter map's value at the cell) and GATHER_PARAMETERS.
// `precise` throughout: no fused multiply-adds, so every operation rounds as
// the CPU's does and Newton takes the CPU's path near folds and multiple roots.
#define N NSPECIES
layout(std430, binding = 0) buffer Species { double v[]; } xs[N];
layout(std430, binding = 6) writeonly buffer Rates { double v[]; } rs[N];
layout(std430, binding = 12) buffer Stats { uint failures; uint maxIterations; };
layout(std430, binding = 13) readonly buffer Maps { double maps[]; };  // parameter maps, one after another

uniform int n;
uniform double dt;
uniform double uniformP[12];  // the parameters' uniform values
uniform int mapAt[12];        // where parameter k's map starts in maps[], -1: uniform
uniform uint clamped;         // bit s: species s stays >= 0

double p[NPARAMETERS];  // this cell's parameters

void rates(double x[N], out double r[N]) { modelRates(x, p, r); }
void jacobian(double x[N], out double J[N * N]) { modelJacobian(x, p, J); }

bool held(uint mask, int s) { return ((mask >> uint(s)) & 1u) != 0u; }

// max |F|; l2 = |F|^2
double residualOf(double y[N], double x0[N], double h, uint fixedMask, out double f[N], out double l2) {
  double r[N];
  rates(y, r);
  precise double m = 0.0lf, q = 0.0lf;
  for (int s = 0; s < N; ++s) {
    precise double fs = held(fixedMask, s) ? 0.0lf : y[s] - x0[s] - h * r[s];
    f[s] = fs;
    m = max(m, abs(fs));
    q += fs * fs;
  }
  l2 = q;
  return m;
}

// solveDense (partial pivoting); false if singular
bool solveDense(inout double A[N][N], inout double b[N]) {
  for (int c = 0; c < N; ++c) {
    int piv = c;
    for (int r = c + 1; r < N; ++r)
      if (abs(A[r][c]) > abs(A[piv][c])) piv = r;
    if (!(abs(A[piv][c]) > 1e-300lf)) return false;
    if (piv != c) {
      for (int k = 0; k < N; ++k) {
        const double t = A[c][k];
        A[c][k] = A[piv][k];
        A[piv][k] = t;
      }
      const double t = b[c];
      b[c] = b[piv];
      b[piv] = t;
    }
    for (int r = c + 1; r < N; ++r) {
      precise double f = A[r][c] / A[c][c];
      for (int k = c; k < N; ++k) {
        precise double a = A[r][k] - f * A[c][k];
        A[r][k] = a;
      }
      precise double br = b[r] - f * b[c];
      b[r] = br;
    }
  }
  for (int c = N - 1; c >= 0; --c) {
    precise double s = b[c];
    for (int k = c + 1; k < N; ++k) s -= A[c][k] * b[k];
    b[c] = s / A[c][c];
  }
  return true;
}

struct Result { bool converged; int iterations; double residual; };

double maxAbs(double a[N]) {
  double m = 0.0lf;
  for (int s = 0; s < N; ++s) m = max(m, abs(a[s]));
  return m;
}

Result newtonFrom(double x0[N], double h, inout double x[N], uint fixedMask, int maxIterations) {
  double scale = max(1.0lf, max(maxAbs(x0), maxAbs(x)));
  double F[N], Fn[N], xn[N];
  double q, qn;
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
    double J[N * N];
    jacobian(x, J);
    double A[N][N], d[N];
    for (int s = 0; s < N; ++s) {
      const bool fx = held(fixedMask, s);
      for (int t = 0; t < N; ++t) {
        precise double a = (s == t ? 1.0lf : 0.0lf) - (fx ? 0.0lf : h * J[s * N + t]);
        A[s][t] = a;
      }
      d[s] = -F[s];
    }
    if (!solveDense(A, d))
      for (int s = 0; s < N; ++s) d[s] = -F[s];  // singular: a damped fixed-point step
    double lambda = 1.0lf, fn = 0.0lf;
    bool accepted = false;
    for (int tries = 0; tries < 40; ++tries, lambda *= 0.5lf) {
      for (int s = 0; s < N; ++s) {
        precise double y = x[s] + lambda * d[s];
        xn[s] = y;
      }
      fn = residualOf(xn, x0, h, fixedMask, Fn, qn);
      precise double bound = (1.0lf - 2e-4lf * lambda) * q;
      if (qn <= bound) {
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    for (int s = 0; s < N; ++s) {
      x[s] = xn[s];
      F[s] = Fn[s];
      scale = max(scale, abs(x[s]));
    }
    fnorm = fn;
    q = qn;
  }
  res.residual = fnorm;
  return res;
}

const int kMaxIterations = 60;

Result newtonImplicit(double x0[N], double h, inout double x[N], uint fixedMask) {
  double start[N];
  for (int s = 0; s < N; ++s) {
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
  const int primes[8] = int[8](2, 3, 5, 7, 11, 13, 17, 19);
  for (int k = 1; k <= 32; ++k) {
    for (int s = 0; s < N; ++s) {
      precise double f = 0.0lf, base = 1.0lf / double(primes[s % 8]);
      for (int i = k, b = primes[s % 8]; i > 0; i /= b, base /= double(b)) f += base * double(i % b);
      precise double y = x0[s] + (2.0lf * f - 1.0lf) * (1.0lf + abs(x0[s]));
      x[s] = held(fixedMask, s) ? start[s] : y;
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
Result implicitReaction(double x0[N], double h, out double x[N]) {
  x = x0;
  Result r = newtonImplicit(x0, h, x, 0u);
  if (clamped == 0u) return r;
  uint pinned = 0u;
  for (int s = 0; s < N; ++s)
    if (held(clamped, s) && (!r.converged ? true : x[s] < 0.0lf)) pinned |= 1u << uint(s);
  if (pinned == 0u) return r;
  for (int s = 0; s < N; ++s)
    if (held(pinned, s)) x[s] = 0.0lf;
  Result c = newtonImplicit(x0, h, x, pinned);
  double rr[N];
  rates(x, rr);
  uint violated = 0u;
  for (int s = 0; s < N; ++s) {
    precise double g = x[s] - x0[s] - h * rr[s];
    if (held(pinned, s) && g < 0.0lf) violated |= 1u << uint(s);
  }
  const uint keep = pinned & ~violated;
  for (int j = 0; violated != 0u && j < 10; ++j) {
    double y[N];
    for (int s = 0; s < N; ++s) y[s] = held(violated, s) ? (abs(x0[s]) + 1.0lf) * ldexp(1.0lf, 2 * j - 14) : x[s];
    Result f = newtonFrom(x0, h, y, keep, kMaxIterations);
    c.iterations += f.iterations;
    bool admissible = f.converged;
    for (int s = 0; s < N; ++s)
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
  double x0[N];
  for (int s = 0; s < N; ++s) x0[s] = xs[s].v[i];
#if defined(MODE_IMPLICIT)
  double x[N];
  const Result r = implicitReaction(x0, dt, x);
  if (!r.converged) atomicAdd(failures, 1u);
  atomicMax(maxIterations, uint(r.iterations));
  for (int s = 0; s < N; ++s) xs[s].v[i] = held(clamped, s) && x[s] < 0.0lf ? 0.0lf : x[s];  // the model's projection
#else
  double r[N];
  rates(x0, r);
  for (int s = 0; s < N; ++s) rs[s].v[i] = r[s];
#endif
}
