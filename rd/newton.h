// Newton-Raphson for one cell's implicit reaction step (Kim & Lin sec. 3.2,
// eq. 6):  F(x) = x - x0 - dt R(x) = 0,  J_F = I - dt dR/dx.
// Started from x0, with a backtracking line search on max|F| so it cannot run
// away on the stiff cubic kinetics (FitzHugh-Nagumo, Barkley) at large dt.
#pragma once

#include <algorithm>
#include <cmath>

namespace morphoflow {

// Solves the n x n system A y = b in place (partial pivoting); false if singular.
template <int N>
bool solveDense(double (&A)[N][N], double (&b)[N], int n) {
  if constexpr (N >= 2) {
    if (n == 2) {  // the loops below unrolled for two species: the same arithmetic
      if (std::abs(A[1][0]) > std::abs(A[0][0])) {
        std::swap(A[0][0], A[1][0]);
        std::swap(A[0][1], A[1][1]);
        std::swap(b[0], b[1]);
      }
      if (!(std::abs(A[0][0]) > 1e-300)) return false;
      const double f = A[1][0] / A[0][0];
      A[1][1] -= f * A[0][1];
      b[1] -= f * b[0];
      if (!(std::abs(A[1][1]) > 1e-300)) return false;
      b[1] = b[1] / A[1][1];
      b[0] = (b[0] - A[0][1] * b[1]) / A[0][0];
      return true;
    }
  }
  for (int c = 0; c < n; ++c) {
    int piv = c;
    for (int r = c + 1; r < n; ++r)
      if (std::abs(A[r][c]) > std::abs(A[piv][c])) piv = r;
    if (!(std::abs(A[piv][c]) > 1e-300)) return false;
    if (piv != c) {
      for (int k = 0; k < n; ++k) std::swap(A[c][k], A[piv][k]);
      std::swap(b[c], b[piv]);
    }
    for (int r = c + 1; r < n; ++r) {
      double f = A[r][c] / A[c][c];
      for (int k = c; k < n; ++k) A[r][k] -= f * A[c][k];
      b[r] -= f * b[c];
    }
  }
  for (int c = n - 1; c >= 0; --c) {
    double s = b[c];
    for (int k = c + 1; k < n; ++k) s -= A[c][k] * b[k];
    b[c] = s / A[c][c];
  }
  return true;
}

// Newton iterations per attempt (each start or continuation stage).
constexpr int kNewtonMaxIterations = 60;

struct NewtonResult {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;  // max |F| at the returned x
};

// Species whose bit is set in `fixed` keep their starting value x[s] (the
// row of F is dropped); the others start from x[s] too (callers set x).
// Solves x - x0 - tau dt R(x) = 0 by Newton with an Armijo line search on
// |F|_2^2 (the Newton step is always a descent direction for it).
template <int N, typename Rates, typename Jacobian>
NewtonResult newtonFrom(int n, const double* x0, double dt, double* x, Rates&& rates, Jacobian&& jacobian,
                        unsigned fixed, int maxIterations) {
  double r[N], J[N * N], F[N], xn[N], Fn[N];
  double scale = 1.0;
  for (int s = 0; s < n; ++s) scale = std::max({scale, std::abs(x0[s]), std::abs(x[s])});
  auto residual = [&](const double* y, double* f, double* l2) {
    rates(y, r);
    double m = 0.0, q = 0.0;
    for (int s = 0; s < n; ++s) {
      f[s] = (fixed >> s) & 1u ? 0.0 : y[s] - x0[s] - dt * r[s];
      m = std::max(m, std::abs(f[s]));
      q += f[s] * f[s];
    }
    *l2 = q;
    return m;
  };
  NewtonResult out;
  double q = 0.0, fnorm = residual(x, F, &q);
  for (;;) {
    double tol = 1e-12 * scale;
    if (!(fnorm > tol)) {  // also stops on NaN (reported as unconverged)
      out.converged = fnorm <= tol;
      break;
    }
    if (out.iterations >= maxIterations) break;
    ++out.iterations;
    jacobian(x, J);
    double A[N][N], d[N];
    for (int s = 0; s < n; ++s) {
      bool fx = (fixed >> s) & 1u;
      for (int t = 0; t < n; ++t) A[s][t] = (s == t ? 1.0 : 0.0) - (fx ? 0.0 : dt * J[s * n + t]);
      d[s] = -F[s];
    }
    if (!solveDense<N>(A, d, n))
      for (int s = 0; s < n; ++s) d[s] = -F[s];  // singular: a damped fixed-point step
    double lambda = 1.0, fn = 0.0, qn = 0.0;
    bool accepted = false;
    for (int tries = 0; tries < 40; ++tries, lambda *= 0.5) {
      for (int s = 0; s < n; ++s) xn[s] = x[s] + lambda * d[s];
      fn = residual(xn, Fn, &qn);
      if (qn <= (1.0 - 2e-4 * lambda) * q) {
        accepted = true;
        break;
      }
    }
    if (!accepted) break;  // stagnated in a local minimum of |F|: let the caller restart
    for (int s = 0; s < n; ++s) {
      x[s] = xn[s];
      F[s] = Fn[s];
      scale = std::max(scale, std::abs(x[s]));
    }
    fnorm = fn;
    q = qn;
  }
  out.residual = fnorm;
  return out;
}

// Newton from x0; if it stagnates (the stiff cubic kinetics at large dt have
// several roots and folds), follow the root from x0 by continuation in dt
// (tau = 1/2, 3/4, ...), then try a few deterministic restarts.
template <int N, typename Rates, typename Jacobian>
NewtonResult newtonImplicit(int n, const double* x0, double dt, double* x, Rates&& rates, Jacobian&& jacobian,
                            unsigned fixed = 0, int maxIterations = kNewtonMaxIterations) {
  double start[N];
  for (int s = 0; s < n; ++s) {
    if (!((fixed >> s) & 1u)) x[s] = x0[s];
    start[s] = x[s];
  }
  NewtonResult r = newtonFrom<N>(n, x0, dt, x, rates, jacobian, fixed, maxIterations);
  if (r.converged) return r;
  int total = r.iterations;
  // Continuation: solve for tau dt with tau doubling towards 1.
  for (int s = 0; s < n; ++s) x[s] = start[s];
  for (double tau : {1.0 / 64, 1.0 / 16, 1.0 / 4, 0.5, 0.75, 1.0}) {
    NewtonResult c = newtonFrom<N>(n, x0, tau * dt, x, rates, jacobian, fixed, maxIterations);
    total += c.iterations;
    if (!c.converged) break;
    if (tau == 1.0) {
      c.iterations = total;
      return c;
    }
  }
  // Deterministic restarts around x0: a Halton set of offsets in
  // (-1, 1) (1 + |x0|) per species.
  static constexpr int kPrimes[8] = {2, 3, 5, 7, 11, 13, 17, 19};
  for (int k = 1; k <= 32; ++k) {
    for (int s = 0; s < n; ++s) {
      double f = 0.0, base = 1.0 / kPrimes[s % 8];
      for (int i = k, b = kPrimes[s % 8]; i > 0; i /= b, base /= b) f += base * (i % b);
      x[s] = (fixed >> s) & 1u ? start[s] : x0[s] + (2.0 * f - 1.0) * (1.0 + std::abs(x0[s]));
    }
    NewtonResult c = newtonFrom<N>(n, x0, dt, x, rates, jacobian, fixed, maxIterations);
    total += c.iterations;
    if (c.converged) {
      c.iterations = total;
      return c;
    }
  }
  // Nothing converged: return the best effort from x0.
  for (int s = 0; s < n; ++s) x[s] = start[s];
  r = newtonFrom<N>(n, x0, dt, x, rates, jacobian, fixed, maxIterations);
  r.iterations += total;
  return r;
}

// The implicit reaction step of a model whose species in `clamped` (a bit
// mask) must stay >= 0: an unconstrained Newton solve first; if it has no
// admissible root (a clamped species ends below 0, or no root exists at all,
// as for Turing's decay term at large dt), the offending species are held at
// 0 and the rest solved again: the complementarity solution of
//   x = x0 + dt R(x),  x_c >= 0.
template <int N, typename Rates, typename Jacobian>
NewtonResult implicitReactionCell(int n, const double* x0, double dt, double* x, Rates&& rates,
                                  Jacobian&& jacobian, unsigned clamped) {
  NewtonResult r = newtonImplicit<N>(n, x0, dt, x, rates, jacobian);
  if (!clamped) return r;
  unsigned active = 0;
  for (int s = 0; s < n; ++s)
    if (((clamped >> s) & 1u) && (!r.converged ? true : x[s] < 0.0)) active |= 1u << s;
  if (!active) return r;
  for (int s = 0; s < n; ++s)
    if ((active >> s) & 1u) x[s] = 0.0;
  NewtonResult c = newtonImplicit<N>(n, x0, dt, x, rates, jacobian, active);
  // Held at 0 is right only where the free update pushes the species down;
  // otherwise there is a root with x_c >= 0 nearby: release and solve again.
  double rr[N];
  rates(x, rr);
  unsigned violated = 0;
  for (int s = 0; s < n; ++s)
    if (((active >> s) & 1u) && x[s] - x0[s] - dt * rr[s] < 0.0) violated |= 1u << s;
  const bool release = violated != 0;
  const unsigned held = active & ~violated;
  // Look for the admissible root from above: starts with the held species
  // at positive values from 2^-14 (1 + |x0|) up.
  for (int j = 0; release && j < 10; ++j) {
    double y[N];
    for (int s = 0; s < n; ++s)
      y[s] = (violated >> s) & 1u ? (std::abs(x0[s]) + 1.0) * std::ldexp(1.0, 2 * j - 14) : x[s];
    NewtonResult f = newtonFrom<N>(n, x0, dt, y, rates, jacobian, held, kNewtonMaxIterations);
    c.iterations += f.iterations;
    bool admissible = f.converged;
    for (int s = 0; s < n; ++s)
      if (((clamped >> s) & 1u) && y[s] < 0.0) admissible = false;
    if (admissible) {
      for (int s = 0; s < n; ++s) x[s] = y[s];
      f.iterations = c.iterations + r.iterations;
      return f;
    }
  }
  c.iterations += r.iterations;
  return c;
}

}  // namespace morphoflow
